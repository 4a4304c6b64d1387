#pragma once
/// \file Math.hpp
/// Small single-precision vector and matrix types for rendering (column-major like OpenGL).

#include <cmath>

namespace demo {

/// A 3D float vector.
struct V3 {
    float x = 0; ///< x
    float y = 0; ///< y
    float z = 0; ///< z
    /// Sum.
    V3 operator+(const V3& o) const { return {x + o.x, y + o.y, z + o.z}; }
    /// Difference.
    V3 operator-(const V3& o) const { return {x - o.x, y - o.y, z - o.z}; }
    /// Scaling.
    V3 operator*(float s) const { return {x * s, y * s, z * s}; }
    /// Negation.
    V3 operator-() const { return {-x, -y, -z}; }
    /// In-place sum.
    V3& operator+=(const V3& o) { return *this = *this + o; }
};

/// Dot product.
inline float dot(const V3& a, const V3& b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
/// Cross product.
inline V3 cross(const V3& a, const V3& b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
/// Length.
inline float len(const V3& v) {
    return std::sqrt(dot(v, v));
}
/// Unit vector (zero stays zero).
inline V3 norm(const V3& v) {
    const float l = len(v);
    return l > 0 ? v * (1.0f / l) : V3{};
}
/// Linear interpolation.
inline V3 lerp(const V3& a, const V3& b, float t) {
    return a + (b - a) * t;
}

/// A 4x4 column-major matrix: m[col*4 + row].
struct M4 {
    float m[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}; ///< elements, column-major

    /// Matrix product.
    M4 operator*(const M4& o) const {
        M4 r;
        for (int c = 0; c < 4; ++c)
            for (int rr = 0; rr < 4; ++rr) {
                float s = 0;
                for (int k = 0; k < 4; ++k)
                    s += m[k * 4 + rr] * o.m[c * 4 + k];
                r.m[c * 4 + rr] = s;
            }
        return r;
    }
    /// Transforms a point (w = 1).
    V3 point(const V3& p) const {
        return {m[0] * p.x + m[4] * p.y + m[8] * p.z + m[12], m[1] * p.x + m[5] * p.y + m[9] * p.z + m[13],
                m[2] * p.x + m[6] * p.y + m[10] * p.z + m[14]};
    }
};

/// Perspective projection (fovy in radians).
inline M4 perspective(float fovy, float aspect, float zn, float zf) {
    M4 r;
    const float f = 1.0f / std::tan(fovy * 0.5f);
    for (float& v : r.m)
        v = 0;
    r.m[0] = f / aspect;
    r.m[5] = f;
    r.m[10] = (zf + zn) / (zn - zf);
    r.m[11] = -1;
    r.m[14] = 2 * zf * zn / (zn - zf);
    return r;
}

/// Orthographic projection.
inline M4 ortho(float l, float r, float b, float t, float n, float f) {
    M4 o;
    o.m[0] = 2 / (r - l);
    o.m[5] = 2 / (t - b);
    o.m[10] = -2 / (f - n);
    o.m[12] = -(r + l) / (r - l);
    o.m[13] = -(t + b) / (t - b);
    o.m[14] = -(f + n) / (f - n);
    return o;
}

/// View matrix looking from eye at target.
inline M4 lookAt(const V3& eye, const V3& target, const V3& up) {
    const V3 f = norm(target - eye);
    const V3 s = norm(cross(f, up));
    const V3 u = cross(s, f);
    M4 r;
    r.m[0] = s.x;
    r.m[4] = s.y;
    r.m[8] = s.z;
    r.m[1] = u.x;
    r.m[5] = u.y;
    r.m[9] = u.z;
    r.m[2] = -f.x;
    r.m[6] = -f.y;
    r.m[10] = -f.z;
    r.m[12] = -dot(s, eye);
    r.m[13] = -dot(u, eye);
    r.m[14] = dot(f, eye);
    return r;
}

/// Translation and non-uniform scale.
inline M4 translateScale(const V3& t, const V3& s) {
    M4 r;
    r.m[0] = s.x;
    r.m[5] = s.y;
    r.m[10] = s.z;
    r.m[12] = t.x;
    r.m[13] = t.y;
    r.m[14] = t.z;
    return r;
}

} // namespace demo
