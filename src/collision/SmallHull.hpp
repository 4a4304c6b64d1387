#pragma once
// Private helper of the collision module: the convex hull of a few points without Qhull's set-up
// (docs/collision.md, "Small hulls").

#include <cstddef>
#include <optional>
#include <vector>

#include "rubble/core/Result.hpp"
#include "rubble/geometry/ConvexPolytope.hpp"

namespace rubble::detail {

/// The most points smallHull takes.
inline constexpr std::size_t kSmallHullPoints = 96;

/// The convex hull of 4 to kSmallHullPoints points: inserted one by one with a tolerance of rounding, the
/// triangles that lie in one plane within it merged into one face. Nothing when it declines (too many points,
/// flat or degenerate input, a horizon that is not one loop, a face it cannot close): Qhull decides those.
std::optional<ConvexPolytope> smallHull(const std::vector<Vec3>& points);

/// smallHull where it does not decline, else convexHull (Qhull): for the hulls of parts' corners that a
/// fracture's merges ask for.
Result<ConvexPolytope> hullOfFew(const std::vector<Vec3>& points);

} // namespace rubble::detail
