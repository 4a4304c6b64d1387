#pragma once
// Private helper of the collision module: the convex hull of a few points without Qhull (docs/collision.md).

#include <cstddef>
#include <optional>
#include <vector>

#include "rubble/core/Result.hpp"
#include "rubble/geometry/ConvexPolytope.hpp"

namespace rubble::detail {

/// The most points smallHull takes.
inline constexpr std::size_t kSmallHullPoints = 96;

/// The convex hull of 4 to kSmallHullPoints points, or nothing where it declines (docs/collision.md).
std::optional<ConvexPolytope> smallHull(const std::vector<Vec3>& points);

/// smallHull where it does not decline, else convexHull (Qhull).
Result<ConvexPolytope> hullOfFew(const std::vector<Vec3>& points);

} // namespace rubble::detail
