#pragma once
/// \file Aabb.hpp
/// Axis-aligned bounding box.

#include <limits>

#include "rubble/core/Export.hpp"
#include "rubble/core/Vec3.hpp"

namespace rubble {

/// An axis-aligned bounding box; an empty box has lo > hi.
struct RUBBLE_API Aabb {
    Vec3 lo{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
            std::numeric_limits<double>::infinity()}; ///< minimum corner
    Vec3 hi{-std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
            -std::numeric_limits<double>::infinity()}; ///< maximum corner

    /// True when the box contains no point.
    bool empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
    /// Grow the box to contain p.
    void extend(const Vec3& p) {
        lo = min(lo, p);
        hi = max(hi, p);
    }
    /// Grow the box to contain another box.
    void extend(const Aabb& b) {
        lo = min(lo, b.lo);
        hi = max(hi, b.hi);
    }
    /// Centre of the box.
    Vec3 center() const { return (lo + hi) * 0.5; }
    /// Edge lengths of the box.
    Vec3 size() const { return hi - lo; }
    /// Length of the diagonal (0 for an empty box).
    double diagonal() const { return empty() ? 0.0 : length(hi - lo); }
    /// True when p lies inside the box grown by eps.
    bool contains(const Vec3& p, double eps = 0) const {
        return p.x >= lo.x - eps && p.x <= hi.x + eps && p.y >= lo.y - eps && p.y <= hi.y + eps &&
               p.z >= lo.z - eps && p.z <= hi.z + eps;
    }
    /// True when the two boxes overlap (touching counts), each grown by eps.
    bool overlaps(const Aabb& b, double eps = 0) const {
        return lo.x <= b.hi.x + eps && b.lo.x <= hi.x + eps && lo.y <= b.hi.y + eps && b.lo.y <= hi.y + eps &&
               lo.z <= b.hi.z + eps && b.lo.z <= hi.z + eps;
    }
};

} // namespace rubble
