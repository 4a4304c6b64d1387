#pragma once
// A rotation check for placements given from outside (the runtime's objects, the C API's structure bodies).

#include <cmath>

#include "rubble/core/Vec3.hpp"

namespace rubble::detail {

// True when r is a rotation: orthonormal columns (to 1e-6) and determinant 1.
inline bool isRotation(const Mat3& r) {
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            double d = 0;
            for (int k = 0; k < 3; ++k)
                d += r.m[k][i] * r.m[k][j];
            if (!(std::abs(d - (i == j ? 1.0 : 0.0)) < 1e-6))
                return false;
        }
    const double det = r.m[0][0] * (r.m[1][1] * r.m[2][2] - r.m[1][2] * r.m[2][1]) -
                       r.m[0][1] * (r.m[1][0] * r.m[2][2] - r.m[1][2] * r.m[2][0]) +
                       r.m[0][2] * (r.m[1][0] * r.m[2][1] - r.m[1][1] * r.m[2][0]);
    return det > 0;
}

} // namespace rubble::detail
