#pragma once
// Private helper of the io module: splitting a planar-ish polygon into triangles.

#include <array>
#include <cstddef>
#include <vector>

#include "rubble/core/Vec3.hpp"

namespace rubble::io {

/// Splits a polygon (corner positions in order) into triangles given as corner indices, keeping the polygon's
/// winding. Convex polygons are fanned from their most convex corner; concave ones (up to 1024 corners) are
/// ear-clipped in their best-fit (Newell) plane; degenerate or non-finite polygons are fanned from corner 0.
std::vector<std::array<std::size_t, 3>> triangulatePolygon(const std::vector<Vec3>& pts);

} // namespace rubble::io
