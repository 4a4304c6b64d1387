#pragma once
/// \file MeshRepair.hpp
/// Repairs the common defects of triangle meshes in place: duplicate vertices, degenerate and duplicate
/// triangles, inconsistent or inward orientation, triangles touching non-finite vertices.

#include <cstddef>
#include <string>
#include <vector>

#include "rubble/core/Export.hpp"
#include "rubble/geometry/Mesh.hpp"
#include "rubble/geometry/MeshCheck.hpp"

namespace rubble {

/// What repairMesh does.
struct RUBBLE_API RepairOptions {
    /// Vertices closer than weldTolerance × (bounding-box diagonal) are merged; 0 merges exact duplicates
    /// only.
    double weldTolerance = 1e-9;
    /// Orient every edge-connected shell consistently and outward (cavities inward).
    bool orient = true;
    /// Run the self-intersection test in the final check (see CheckOptions::selfIntersections).
    bool checkSelfIntersections = true;
    /// Close holes whose boundary is one simple loop, planar or nearly so (needs orient).
    bool fillHoles = true;
};

/// What repairMesh changed and what it could not fix.
struct RUBBLE_API RepairReport {
    std::size_t removedBadIndexTriangles = 0;  ///< triangles referring to vertices that do not exist
    std::size_t removedNonFiniteTriangles = 0; ///< triangles touching a vertex with a NaN/infinite coordinate
    std::size_t weldedVertices = 0;    ///< vertices merged into an earlier vertex within the tolerance
    std::size_t removedDegenerate = 0; ///< triangles with a repeated vertex or zero area
    std::size_t removedDuplicates = 0; ///< triangles with the same three vertices as an earlier one
    std::size_t removedUnreferencedVertices = 0; ///< vertices no triangle uses any more
    std::size_t flippedTriangles = 0;            ///< triangles reversed to agree with their neighbours
    std::size_t invertedShells = 0;      ///< whole shells reversed to face outward (or inward for cavities)
    std::size_t nonOrientableShells = 0; ///< shells that cannot be oriented consistently (e.g. Möbius)
    std::size_t filledHoles = 0;         ///< holes closed (RepairOptions::fillHoles)
    std::size_t openHoles = 0;           ///< holes left open: not simple, not planar, or crossing themselves

    std::vector<std::string> fixed; ///< one sentence per kind of fix applied
    std::vector<std::string>
        unrepaired;   ///< problems that remain (holes, non-manifold edges, self-intersections)
    MeshReport after; ///< checkMesh of the repaired mesh

    /// True when the repair changed the mesh.
    bool changed() const { return !fixed.empty(); }
    /// True when the repaired mesh is a valid solid.
    bool valid() const { return after.valid(); }
};

/// Repairs mesh in place and reports what was fixed and what could not be repaired. Attributes (normals, uvs,
/// materials) stay consistent with the triangles: removed triangles lose theirs, reversed triangles have
/// their corners swapped and normals that point against the new face negated. A hole whose boundary is one
/// simple loop bending out of its plane by at most 5% of its width is closed by a triangulation in that
/// plane; other holes, non-manifold edges and self-intersections are not repaired, only reported (unrepaired
/// says what the user can do). Never fails and never throws.
RUBBLE_API RepairReport repairMesh(Mesh& mesh, const RepairOptions& options = {});

} // namespace rubble
