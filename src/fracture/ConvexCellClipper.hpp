#pragma once
// Fast split of a closed triangle mesh by ONE convex cell, touching only the triangles near the cell.
//
// Exactness model: decisions are made with floating-point signed distances, but every point is computed once
// from a canonical key (the mesh edge it lies on, or the triangle and cell edge it lies on) and shared by all
// faces that use it, so the outputs are closed by construction. Any near-degenerate configuration (a vertex
// within tolerance of a cell plane, an ill-conditioned intersection, an inconsistent boundary) is reported as
// an error, and the caller falls back to an exact CGAL backend. Outputs are verified (closedness of all new
// faces, volume conservation) before they are returned.

#include "rubble/ConvexPolytope.hpp"
#include "rubble/Mesh.hpp"
#include "rubble/Result.hpp"

namespace rubble::detail {

/// The two sides of a mesh split by one convex cell.
struct CellSplit {
    Mesh outside; ///< mesh − cell
    Mesh inside;  ///< mesh ∩ cell
};

/// Splits a closed, consistently oriented mesh by a convex cell. Cut faces get kInteriorMaterial.
/// Returns ErrorCode::GeometryFailure for configurations it does not handle robustly (use an exact backend).
Result<CellSplit> clipByConvexCell(const Mesh& mesh, const ConvexPolytope& cell);

} // namespace rubble::detail
