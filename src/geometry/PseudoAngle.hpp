#pragma once
// An angle substitute for sorting a polygon's corners around its centre without atan2.

#include <cmath>

namespace rubble::detail {

/// A number increasing with atan2(y, x) over (−π, π], in (−2, 2]: the corners sort as by angle, without
/// atan2.
inline double pseudoAngle(double x, double y) {
    if (y == 0 && x <= 0)
        return x == 0 ? 0 : (std::signbit(y) ? -2 : 2); // atan2 gives −π for −0 and π for +0
    const double d = y / (std::abs(x) + std::abs(y)); // in [−1, 1], increasing with the angle on each side
    return x >= 0 ? d : (y > 0 ? 2 - d : -2 - d);
}

} // namespace rubble::detail
