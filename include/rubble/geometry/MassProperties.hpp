#pragma once
/// \file MassProperties.hpp
/// Exact mass properties of a closed triangle mesh of uniform density.

#include "rubble/core/Export.hpp"
#include "rubble/core/Vec3.hpp"
#include "rubble/geometry/Mesh.hpp"

namespace rubble {

/// Mass properties for density 1 (multiply inertia by density for a real body; mass = density · volume).
struct RUBBLE_API MassProperties {
    double volume = 0;     ///< signed volume (negative for an inward-oriented mesh)
    Vec3 centerOfMass;     ///< centroid of the solid
    Mat3 inertia;          ///< inertia tensor about the centre of mass, density 1
    Vec3 principalMoments; ///< eigenvalues of inertia, ascending
    Mat3 principalAxes;    ///< columns are unit principal axes matching principalMoments; a proper rotation
};

/// The volume integrals of a closed mesh about a reference point: sums over its triangles of the tetrahedra
/// they form with the point. They are additive, so the integrals of a mesh that changed in a few triangles
/// are its old ones minus the removed triangles' terms plus the added ones' (docs/megamesh.md).
struct RUBBLE_API VolumeIntegrals {
    Vec3 reference;        ///< apex of the tetrahedra
    double volume = 0;     ///< ∫ dV
    Vec3 first;            ///< ∫ (x − reference) dV
    double cov[3][3] = {}; ///< ∫ (x − reference)(x − reference)ᵀ dV, upper triangle (i <= j)

    /// Adds the tetrahedron of the triangle (a, b, c) (mesh coordinates) and the reference.
    void add(const Vec3& a, const Vec3& b, const Vec3& c) {
        addRelative(a - reference, b - reference, c - reference);
    }
    /// Adds sign (±1) times the terms of the triangle (a, b, c) given relative to the reference.
    void addRelative(const Vec3& a, const Vec3& b, const Vec3& c, double sign = 1.0);
    /// Adds triangle t of mesh.
    void add(const Mesh& mesh, std::size_t t) {
        const Triangle& tri = mesh.triangles[t];
        add(mesh.positions[tri[0]], mesh.positions[tri[1]], mesh.positions[tri[2]]);
    }
    /// Subtracts triangle t of mesh (its terms negated exactly).
    void remove(const Mesh& mesh, std::size_t t) {
        const Triangle& tri = mesh.triangles[t];
        addRelative(mesh.positions[tri[0]] - reference, mesh.positions[tri[1]] - reference,
                    mesh.positions[tri[2]] - reference, -1.0);
    }
    /// Adds (sign +1) or subtracts (sign −1) integrals about the same reference.
    void accumulate(const VolumeIntegrals& o, double sign);
};

/// The volume integrals of all triangles of mesh about reference.
RUBBLE_API VolumeIntegrals volumeIntegrals(const Mesh& mesh, const Vec3& reference);
/// About the centre of the mesh's bounds (what computeMassProperties sums).
RUBBLE_API VolumeIntegrals volumeIntegrals(const Mesh& mesh);

/// Mass properties from volume integrals (computeMassProperties(m) is massProperties(volumeIntegrals(m))).
RUBBLE_API MassProperties massProperties(const VolumeIntegrals& integrals);

/// Computes volume, centre of mass and inertia by the divergence theorem over the triangles.
/// Exact for closed meshes; numerically stable far from the origin (computed about the bounding-box centre).
RUBBLE_API MassProperties computeMassProperties(const Mesh& mesh);

/// Signed volume only (cheaper than computeMassProperties).
RUBBLE_API double signedVolume(const Mesh& mesh);

} // namespace rubble
