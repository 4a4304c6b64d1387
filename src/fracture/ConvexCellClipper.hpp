#pragma once
// Fast split of a closed triangle mesh by one convex cell, or by several convex cells with disjoint interiors
// (a shatter pattern), touching only the triangles near the cells.
//
// Exactness model: decisions are made with floating-point signed distances, but every point is computed once
// from a canonical key (the mesh edge it lies on, or the triangle and cell edge it lies on) and shared by all
// faces that use it, so the outputs are closed by construction. Several cells are split in one pass as a
// complex: their welded vertices and the faces two cells share are stored once, a point on a shared face or
// on an edge where cells meet is the same keyed point for every cell around it, and a cap on a shared face
// goes to both cells (one reversed), so neighbouring pieces match exactly. Any near-degenerate configuration
// (a vertex within tolerance of a cell plane, an ill-conditioned intersection, an inconsistent boundary) is
// reported as an error, and the caller falls back to an exact CGAL backend. Outputs are verified (closedness
// of all new faces, volume conservation) before they are returned.

#include "geometry/TopologyEdit.hpp"
#include "rubble/core/Result.hpp"
#include "rubble/geometry/ConvexPolytope.hpp"
#include "rubble/geometry/MassProperties.hpp"
#include "rubble/geometry/Mesh.hpp"

#include <optional>
#include <vector>

namespace rubble::detail {

/// The two sides of a mesh split by one convex cell.
struct CellSplit {
    Mesh outside; ///< mesh − cell
    Mesh inside;  ///< mesh ∩ cell
};

/// Splits a closed, consistently oriented mesh by a convex cell. Cut faces get kInteriorMaterial.
/// Returns ErrorCode::GeometryFailure for configurations it does not handle robustly (use an exact backend).
Result<CellSplit> clipByConvexCell(const Mesh& mesh, const ConvexPolytope& cell);

/// The parts of a mesh split by several convex cells.
struct MultiCellSplit {
    Mesh outside;             ///< mesh − ∪ cells
    std::vector<Mesh> inside; ///< mesh ∩ cell k, in the order of the cells
    /// With the input's integrals given: outside's, as the input's minus the triangles it lost plus those
    /// it gained (about the same reference).
    std::optional<VolumeIntegrals> outsideIntegrals;
};

/// Splits a closed, consistently oriented mesh by non-empty convex cells with disjoint interiors whose shared
/// faces have the same (bit-identical) corners, e.g. welded Voronoi cells. Cut faces get kInteriorMaterial.
/// Returns ErrorCode::GeometryFailure when the cells overlap, do not form a complex, or for configurations it
/// does not handle robustly (use an exact backend). With meshIntegrals (the mesh's volume integrals), the
/// verification and outsideIntegrals cost what the cut touched instead of two passes over the mesh.
Result<MultiCellSplit> clipByConvexCells(const Mesh& mesh, const std::vector<ConvexPolytope>& cells,
                                         const VolumeIntegrals* meshIntegrals = nullptr);

/// The rest of a split as an edit of the input mesh (detail::replaceTriangles applies it).
struct RemainderEdit {
    std::vector<std::uint32_t> removed; ///< input triangles the rest loses, sorted
    std::vector<Vec3> newPositions;     ///< points it gains, vertex ids from the input's vertex count on
    TriangleBatch added;                ///< triangles it gains, with their attributes
};

/// A split whose rest is an edit of the input.
struct MultiCellEdit {
    RemainderEdit outside;               ///< mesh − ∪ cells, as an edit of mesh
    std::vector<Mesh> inside;            ///< mesh ∩ cell k, in the order of the cells
    std::vector<std::size_t> insideKept; ///< per cell: inside's first triangles, input triangles kept whole;
                                         ///< the rest are new
    VolumeIntegrals outsideIntegrals;    ///< of mesh − ∪ cells, by difference
};

/// clipByConvexCells with the rest as an edit of mesh (not assembled: no pass over the untouched triangles
/// but the scan of their bounds). The edit's closedness is checked when it is applied.
Result<MultiCellEdit> clipByConvexCellsAsEdit(const Mesh& mesh, const std::vector<ConvexPolytope>& cells,
                                              const VolumeIntegrals& meshIntegrals);

} // namespace rubble::detail
