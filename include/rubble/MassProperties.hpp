#pragma once
/// \file MassProperties.hpp
/// Exact mass properties of a closed triangle mesh of uniform density.

#include "rubble/Mesh.hpp"
#include "rubble/Vec3.hpp"

namespace rubble {

/// Mass properties for density 1 (multiply inertia by density for a real body; mass = density · volume).
struct MassProperties {
    double volume = 0;     ///< signed volume (negative for an inward-oriented mesh)
    Vec3 centerOfMass;     ///< centroid of the solid
    Mat3 inertia;          ///< inertia tensor about the centre of mass, density 1
    Vec3 principalMoments; ///< eigenvalues of inertia, ascending
    Mat3 principalAxes;    ///< columns are unit principal axes matching principalMoments; a proper rotation
};

/// Computes volume, centre of mass and inertia by the divergence theorem over the triangles.
/// Exact for closed meshes; numerically stable far from the origin (computed about the bounding-box centre).
MassProperties computeMassProperties(const Mesh& mesh);

/// Signed volume only (cheaper than computeMassProperties).
double signedVolume(const Mesh& mesh);

} // namespace rubble
