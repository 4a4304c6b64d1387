#pragma once
/// \file MeshSimplify.hpp
/// Lossless simplification of the flat parts of a closed mesh: what repeated fracture leaves behind.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "rubble/core/Aabb.hpp"
#include "rubble/core/Export.hpp"
#include "rubble/geometry/MassProperties.hpp"
#include "rubble/geometry/Mesh.hpp"

namespace rubble {

/// Tolerances of simplifyPlanarRegions.
struct RUBBLE_API PlanarSimplifyParams {
    /// Largest distance of a vertex from its region's plane (and of a removed boundary vertex from the
    /// straight edge that replaces it), relative to the mesh's bounding-box diagonal.
    double planeTolerance = 1e-9;
    /// Largest deviation of a region's texture coordinates from one affine map of the plane, in texture units
    /// relative to max(1, the region's texture-coordinate extent).
    double uvTolerance = 1e-5;
    /// Only vertices inside this box may be removed (e.g. the cells of the fracture that made the mesh, so
    /// the cost follows what changed); an empty box means everywhere.
    Aabb focus;
    /// Reference point of PlanarSimplifyReport::integralsChange.
    Vec3 integralsReference;
};

/// What simplifyPlanarRegions did.
struct RUBBLE_API PlanarSimplifyReport {
    std::size_t trianglesBefore = 0;            ///< triangles of the input
    std::size_t trianglesAfter = 0;             ///< triangles of the output
    std::size_t verticesRemoved = 0;            ///< vertices that no longer exist
    std::vector<std::uint32_t> removedVertices; ///< which: the input's indices, ascending (the others keep
                                                ///< their order)
    std::size_t regionsRetriangulated = 0;      ///< flat regions that were triangulated anew
    std::size_t regionsKept = 0; ///< flat regions left as they were because re-triangulating failed
    bool unchanged = false;      ///< the input was returned as it was (not closed, or nothing to do)
    /// The volume integrals of the new triangles minus those of the triangles they replaced, about
    /// params.integralsReference: the output's integrals are the input's plus this.
    VolumeIntegrals integralsChange;
};

/// Removes the vertices that carry no shape: those inside a flat region of the surface and those in the
/// middle of a straight edge between two flat regions, and triangulates the affected regions anew
/// (constrained Delaunay). A flat region is a connected set of triangles in one plane with one material, one
/// per-corner normal and texture coordinates that follow one affine map, so the rendered surface, the
/// enclosed volume and the outline of every region stay the same. Each fracture cuts the triangles it crosses
/// into smaller ones; this keeps a piece's triangle count proportional to its shape's features instead of its
/// history. Every re-triangulated patch is checked to close up exactly with its surroundings and to cover the
/// same area without changing the enclosed volume; a patch that fails keeps its vertices. Vertices on open
/// boundaries, where the surface touches itself, or next to a repeated edge stay where they are.
/// Deterministic.
RUBBLE_API Mesh simplifyPlanarRegions(const Mesh& mesh, const PlanarSimplifyParams& params = {},
                                      PlanarSimplifyReport* report = nullptr);
/// As above; a mesh left as it is is moved into the result, not copied.
RUBBLE_API Mesh simplifyPlanarRegions(Mesh&& mesh, const PlanarSimplifyParams& params = {},
                                      PlanarSimplifyReport* report = nullptr);

} // namespace rubble
