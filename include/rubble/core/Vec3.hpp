#pragma once
/// \file Vec3.hpp
/// Small vector types used across Rubble's public API (double; float for mesh attributes).

#include <cmath>

#include "rubble/core/Export.hpp"

namespace rubble {

/// A 3D vector or point in double precision.
struct RUBBLE_API Vec3 {
    double x = 0; ///< x coordinate
    double y = 0; ///< y coordinate
    double z = 0; ///< z coordinate

    /// Component access by index 0..2.
    constexpr double operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
    /// Mutable component access by index 0..2.
    constexpr double& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
    /// Component-wise sum.
    constexpr Vec3 operator+(const Vec3& o) const { return {x + o.x, y + o.y, z + o.z}; }
    /// Component-wise difference.
    constexpr Vec3 operator-(const Vec3& o) const { return {x - o.x, y - o.y, z - o.z}; }
    /// Negation.
    constexpr Vec3 operator-() const { return {-x, -y, -z}; }
    /// Scaling by a scalar.
    constexpr Vec3 operator*(double s) const { return {x * s, y * s, z * s}; }
    /// Division by a scalar.
    constexpr Vec3 operator/(double s) const { return {x / s, y / s, z / s}; }
    /// In-place sum.
    constexpr Vec3& operator+=(const Vec3& o) { return *this = *this + o; }
    /// In-place difference.
    constexpr Vec3& operator-=(const Vec3& o) { return *this = *this - o; }
    /// In-place scaling.
    constexpr Vec3& operator*=(double s) { return *this = *this * s; }
    /// Exact component-wise equality.
    constexpr bool operator==(const Vec3&) const = default;
};

/// Scalar times vector.
constexpr Vec3 operator*(double s, const Vec3& v) {
    return v * s;
}
/// Dot product.
constexpr double dot(const Vec3& a, const Vec3& b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
/// Cross product.
constexpr Vec3 cross(const Vec3& a, const Vec3& b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
/// Squared Euclidean length.
constexpr double lengthSquared(const Vec3& v) {
    return dot(v, v);
}
/// Euclidean length.
inline double length(const Vec3& v) {
    return std::sqrt(dot(v, v));
}
/// Unit vector in the direction of v, or the zero vector when v has zero length.
inline Vec3 normalized(const Vec3& v) {
    const double l = length(v);
    return l > 0 ? v / l : Vec3{};
}
/// Component-wise minimum.
constexpr Vec3 min(const Vec3& a, const Vec3& b) {
    return {a.x < b.x ? a.x : b.x, a.y < b.y ? a.y : b.y, a.z < b.z ? a.z : b.z};
}
/// Component-wise maximum.
constexpr Vec3 max(const Vec3& a, const Vec3& b) {
    return {a.x > b.x ? a.x : b.x, a.y > b.y ? a.y : b.y, a.z > b.z ? a.z : b.z};
}
/// True when every component is finite (no NaN, no infinity).
inline bool isFinite(const Vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

/// A 2D vector (texture coordinates widened from Vec2f, plane geometry).
struct RUBBLE_API Vec2 {
    double x = 0; ///< u / x
    double y = 0; ///< v / y
    /// Exact component-wise equality.
    constexpr bool operator==(const Vec2&) const = default;
};

/// Per-corner normals in float: widen to Vec3 implicitly, are rounded from one explicitly.
struct RUBBLE_API Vec3f {
    float x = 0, y = 0, z = 0;   ///< components
    constexpr Vec3f() = default; ///< the zero vector
    constexpr Vec3f(double a, double b, double c) : x(float(a)), y(float(b)), z(float(c)) {} ///< rounded
    constexpr explicit Vec3f(const Vec3& v) : Vec3f(v.x, v.y, v.z) {}                        ///< rounded
    constexpr operator Vec3() const { return {x, y, z}; }    ///< widened exactly
    constexpr bool operator==(const Vec3f&) const = default; ///< exact equality
};
/// Texture coordinates in float: widen to Vec2 implicitly, are rounded from one explicitly.
struct RUBBLE_API Vec2f {
    float x = 0, y = 0;                                               ///< u, v
    constexpr Vec2f() = default;                                      ///< (0, 0)
    constexpr Vec2f(double u, double v) : x(float(u)), y(float(v)) {} ///< rounded
    constexpr explicit Vec2f(const Vec2& v) : Vec2f(v.x, v.y) {}      ///< rounded
    constexpr operator Vec2() const { return {x, y}; }                ///< widened exactly
    constexpr bool operator==(const Vec2f&) const = default;          ///< exact equality
};

/// A row-major 3x3 matrix (inertia tensors, rotations).
struct RUBBLE_API Mat3 {
    double m[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}}; ///< m[row][column]

    /// The identity matrix.
    static constexpr Mat3 identity() {
        Mat3 r;
        r.m[0][0] = r.m[1][1] = r.m[2][2] = 1;
        return r;
    }
    /// Matrix times vector.
    constexpr Vec3 operator*(const Vec3& v) const {
        return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z, m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
                m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
    }
    /// Matrix product.
    constexpr Mat3 operator*(const Mat3& o) const {
        Mat3 r;
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j)
                r.m[i][j] = m[i][0] * o.m[0][j] + m[i][1] * o.m[1][j] + m[i][2] * o.m[2][j];
        return r;
    }
    /// Transpose.
    constexpr Mat3 transposed() const {
        Mat3 r;
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j)
                r.m[i][j] = m[j][i];
        return r;
    }
    /// Column j as a vector.
    constexpr Vec3 column(int j) const { return {m[0][j], m[1][j], m[2][j]}; }
};

} // namespace rubble
