#pragma once
// Private to the core: inside/outside of a point by the parity of ray crossings (used by islands, repair and
// the convex-cell clipper to place cavities and untouched regions).

#include <cstddef>

#include "rubble/geometry/Mesh.hpp"

namespace rubble::detail {

/// True when the fixed, slightly irrational ray from p crosses triangle t of m (Möller–Trumbore, forward
/// only).
inline bool rayCrossesTriangle(const Mesh& m, std::size_t t, const Vec3& p) {
    static const Vec3 d = normalized(Vec3{0.5773502691896258, 0.5772502691896258, 0.5774502691896258});
    const auto c = m.corners(t);
    const Vec3 e1 = c[1] - c[0], e2 = c[2] - c[0];
    const Vec3 h = cross(d, e2);
    const double a = dot(e1, h);
    if (a == 0)
        return false;
    const double f = 1.0 / a;
    const Vec3 s = p - c[0];
    const double u = f * dot(s, h);
    if (u < 0 || u > 1)
        return false;
    const Vec3 q = cross(s, e1);
    const double v = f * dot(d, q);
    if (v < 0 || u + v > 1)
        return false;
    return f * dot(e2, q) > 0;
}

/// Parity of crossings of that ray with the triangles listed (all of m's when tris is null): true = inside a
/// closed shell.
template <class TriangleRange>
bool insideByRayParity(const Mesh& m, const TriangleRange& tris, const Vec3& p) {
    int crossings = 0;
    for (const auto t : tris)
        crossings += rayCrossesTriangle(m, static_cast<std::size_t>(t), p) ? 1 : 0;
    return crossings % 2 == 1;
}

} // namespace rubble::detail
