#pragma once
// A solid of one convex part, the axis-aligned box between two corners: the structure tests' building block.

#include <vector>

#include "rubble/geometry/ConvexPolytope.hpp"

namespace rubble::test {

/// The box from lo to hi as a solid (one convex part).
inline std::vector<ConvexPolytope> boxSolid(const Vec3& lo, const Vec3& hi) {
    Aabb b;
    b.extend(lo);
    b.extend(hi);
    return {ConvexPolytope::fromAabb(b)};
}

} // namespace rubble::test
