#pragma once
/// \file Plane.hpp
/// Oriented plane n·x = d; the normal points to the outside (positive side).

#include "rubble/core/Export.hpp"
#include "rubble/core/Vec3.hpp"

namespace rubble {

/// An oriented plane {x : dot(normal, x) = offset}. Points with signedDistance > 0 are outside.
struct RUBBLE_API Plane {
    Vec3 normal{0, 0, 1}; ///< unit outward normal
    double offset = 0;    ///< dot(normal, p) for any point p on the plane

    /// The plane through point p with outward normal n (normalised here).
    static Plane fromPointNormal(const Vec3& p, const Vec3& n) {
        const Vec3 u = normalized(n);
        return {u, dot(u, p)};
    }
    /// Signed distance of p (positive outside).
    double signedDistance(const Vec3& p) const { return dot(normal, p) - offset; }
    /// The same plane facing the other way.
    Plane flipped() const { return {-normal, -offset}; }
};

} // namespace rubble
