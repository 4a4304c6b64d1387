// Rigid motion of convex polytopes and the test whether two of them touch.
#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>

#include "rubble/geometry/ConvexPolytope.hpp"

namespace rubble {
namespace {

struct Interval {
    double lo = std::numeric_limits<double>::infinity();
    double hi = -std::numeric_limits<double>::infinity();
};

Interval project(const std::vector<Vec3>& points, const Vec3& axis) {
    Interval r;
    for (const Vec3& p : points) {
        const double d = dot(p, axis);
        r.lo = std::min(r.lo, d);
        r.hi = std::max(r.hi, d);
    }
    return r;
}

// Gap between the two point sets along a unit axis (negative: they overlap along it).
double gapAlong(const std::vector<Vec3>& a, const std::vector<Vec3>& b, const Vec3& axis) {
    const Interval ia = project(a, axis), ib = project(b, axis);
    return std::max(ib.lo - ia.hi, ia.lo - ib.hi);
}

std::vector<Vec3> edgeDirections(const ConvexPolytope& p) {
    std::vector<Vec3> out;
    for (const PolytopeFaceView& f : p.faces())
        for (std::size_t i = 0; i < f.corners.size(); ++i) {
            const Vec3 &from = f.corners[i], &to = f.corners[(i + 1) % f.corners.size()];
            if (std::tie(from.x, from.y, from.z) > std::tie(to.x, to.y, to.z))
                continue; // each edge once (its twin runs the other way)
            const Vec3 d = to - from;
            const double len = length(d);
            if (len > 0)
                out.push_back(d / len);
        }
    return out;
}

} // namespace

ConvexPolytope ConvexPolytope::transformed(const Frame& f) const {
    ConvexPolytope out = *this;
    for (Vec3& c : out.corners_)
        c = f.apply(c);
    for (std::size_t i = 0; i < out.faces_.size(); ++i) {
        const Vec3 n = f.rotation * faces_[i].plane.normal;
        const std::size_t end = i + 1 < faces_.size() ? faces_[i + 1].first : index_.size();
        out.faces_[i].plane = end > faces_[i].first
                                  ? Plane::fromPointNormal(out.corners_[index_[faces_[i].first]], n)
                                  : Plane{n, 0};
    }
    return out;
}

bool withinGap(const ConvexPolytope& a, const ConvexPolytope& b, double gap) {
    if (a.empty() || b.empty())
        return false;
    Aabb ba = a.bounds(), bb = b.bounds();
    for (int k = 0; k < 3; ++k)
        if (ba.lo[k] - bb.hi[k] > gap || bb.lo[k] - ba.hi[k] > gap)
            return false;
    const std::vector<Vec3> va = a.vertices(), vb = b.vertices();
    for (const ConvexPolytope* p : {&a, &b})
        for (const PolytopeFaceView& f : p->faces())
            if (gapAlong(va, vb, f.plane.normal) > gap)
                return false;
    const std::vector<Vec3> ea = edgeDirections(a), eb = edgeDirections(b);
    for (const Vec3& da : ea)
        for (const Vec3& db : eb) {
            const Vec3 c = cross(da, db);
            const double len = length(c);
            if (len < 1e-6)
                continue;
            if (gapAlong(va, vb, c / len) > gap)
                return false;
        }
    return true;
}

} // namespace rubble
