#include "rubble/geometry/ConvexPolytope.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include "geometry/PseudoAngle.hpp"

namespace rubble {

namespace {
// Intersection of segment ab with the plane, computed from the lexicographically smaller endpoint so that
// the two faces sharing an edge produce bit-identical points.
Vec3 edgePlanePoint(Vec3 a, Vec3 b, double da, double db) {
    if (std::tie(b.x, b.y, b.z) < std::tie(a.x, a.y, a.z)) {
        std::swap(a, b);
        std::swap(da, db);
    }
    const double t = da / (da - db);
    return a + (b - a) * t;
}

bool lexLess(const Vec3& a, const Vec3& b) {
    return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z);
}
} // namespace

ConvexPolytope ConvexPolytope::fromAabb(const Aabb& box) {
    const Vec3 l = box.lo, h = box.hi;
    const Vec3 v[8] = {{l.x, l.y, l.z}, {h.x, l.y, l.z}, {h.x, h.y, l.z}, {l.x, h.y, l.z},
                       {l.x, l.y, h.z}, {h.x, l.y, h.z}, {h.x, h.y, h.z}, {l.x, h.y, h.z}};
    auto face = [&](Vec3 n, double off, std::initializer_list<int> ids) {
        PolytopeFace f;
        f.plane = {n, off};
        for (int i : ids)
            f.corners.push_back(v[i]);
        return f;
    };
    ConvexPolytope p;
    p.faces_ = {face({-1, 0, 0}, -l.x, {0, 4, 7, 3}), face({1, 0, 0}, h.x, {1, 2, 6, 5}),
                face({0, -1, 0}, -l.y, {0, 1, 5, 4}), face({0, 1, 0}, h.y, {3, 7, 6, 2}),
                face({0, 0, -1}, -l.z, {0, 3, 2, 1}), face({0, 0, 1}, h.z, {4, 5, 6, 7})};
    return p;
}

ConvexPolytope ConvexPolytope::fromFaces(std::vector<PolytopeFace> faces) {
    ConvexPolytope p;
    p.faces_ = std::move(faces);
    return p;
}

std::vector<Vec3> ConvexPolytope::vertices() const {
    std::vector<Vec3> out;
    for (const auto& f : faces_)
        out.insert(out.end(), f.corners.begin(), f.corners.end());
    std::sort(out.begin(), out.end(), lexLess);
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
}

Aabb ConvexPolytope::bounds() const {
    Aabb b;
    for (const auto& f : faces_)
        for (const Vec3& c : f.corners)
            b.extend(c);
    return b;
}

double ConvexPolytope::volume() const {
    if (empty())
        return 0;
    const Vec3 r = faces_[0].corners[0];
    double v = 0;
    for (const auto& f : faces_)
        for (std::size_t i = 1; i + 1 < f.corners.size(); ++i)
            v += dot(f.corners[0] - r, cross(f.corners[i] - r, f.corners[i + 1] - r));
    return v / 6.0;
}

Vec3 ConvexPolytope::centroid() const {
    if (empty())
        return {};
    const Vec3 r = faces_[0].corners[0];
    double v = 0;
    Vec3 c;
    for (const auto& f : faces_)
        for (std::size_t i = 1; i + 1 < f.corners.size(); ++i) {
            const Vec3 a = f.corners[0] - r, b = f.corners[i] - r, d = f.corners[i + 1] - r;
            const double w = dot(a, cross(b, d));
            v += w;
            c += (a + b + d) * w;
        }
    return v != 0 ? r + c / (4.0 * v) : r;
}

bool ConvexPolytope::contains(const Vec3& p, double eps) const {
    if (empty())
        return false;
    for (const auto& f : faces_)
        if (f.plane.signedDistance(p) > eps)
            return false;
    return true;
}

ConvexPolytope ConvexPolytope::clipped(const Plane& plane, std::int32_t tag, double eps) const {
    if (empty())
        return {};
    // Scale the tolerance with the size of the polytope.
    const Aabb b = bounds();
    const double tol = eps * std::max(1.0, std::max({std::abs(b.lo.x), std::abs(b.lo.y), std::abs(b.lo.z),
                                                     std::abs(b.hi.x), std::abs(b.hi.y), std::abs(b.hi.z)}));
    bool anyOut = false, anyIn = false;
    for (const auto& f : faces_)
        for (const Vec3& c : f.corners) {
            const double d = plane.signedDistance(c);
            anyOut |= d > tol;
            anyIn |= d < -tol;
        }
    if (!anyOut)
        return *this;
    if (!anyIn)
        return {};

    ConvexPolytope out;
    out.faces_.reserve(faces_.size() + 1);
    std::vector<Vec3> capPoints;
    for (const auto& f : faces_) {
        PolytopeFace nf;
        nf.plane = f.plane;
        nf.tag = f.tag;
        const std::size_t n = f.corners.size();
        nf.corners.reserve(n + 1);
        for (std::size_t i = 0; i < n; ++i) {
            const Vec3& a = f.corners[i];
            const Vec3& c = f.corners[(i + 1) % n];
            double da = plane.signedDistance(a), dc = plane.signedDistance(c);
            if (std::abs(da) <= tol)
                da = 0;
            if (std::abs(dc) <= tol)
                dc = 0;
            if (da <= 0) {
                nf.corners.push_back(a);
                if (da == 0)
                    capPoints.push_back(a);
            }
            if ((da < 0 && dc > 0) || (da > 0 && dc < 0)) {
                const Vec3 x = edgePlanePoint(a, c, da, dc);
                nf.corners.push_back(x);
                capPoints.push_back(x);
            }
        }
        if (nf.corners.size() >= 3)
            out.faces_.push_back(std::move(nf));
    }
    // Cap face: the points on the plane, ordered counter-clockwise around the outward normal.
    std::sort(capPoints.begin(), capPoints.end(), lexLess);
    capPoints.erase(std::unique(capPoints.begin(), capPoints.end()), capPoints.end());
    if (capPoints.size() >= 3) {
        Vec3 center;
        for (const Vec3& p : capPoints)
            center += p;
        center = center / static_cast<double>(capPoints.size());
        const Vec3 n = plane.normal;
        const Vec3 u = normalized(std::abs(n.x) < 0.9 ? cross(n, Vec3{1, 0, 0}) : cross(n, Vec3{0, 1, 0}));
        const Vec3 v = cross(n, u);
        std::vector<std::pair<double, Vec3>> ordered;
        ordered.reserve(capPoints.size());
        for (const Vec3& p : capPoints)
            ordered.emplace_back(detail::pseudoAngle(dot(p - center, u), dot(p - center, v)), p);
        std::sort(ordered.begin(), ordered.end(),
                  [](const auto& x, const auto& y) { return x.first < y.first; });
        PolytopeFace cap;
        cap.plane = plane;
        cap.tag = tag;
        cap.corners.reserve(ordered.size());
        for (const auto& [angle, p] : ordered)
            cap.corners.push_back(p);
        out.faces_.push_back(std::move(cap));
    }
    if (out.faces_.size() < 4 || out.volume() <= 0)
        return {};
    return out;
}

Mesh ConvexPolytope::toMesh() const {
    Mesh m;
    std::map<std::tuple<double, double, double>, std::uint32_t> index;
    auto id = [&](const Vec3& p) {
        auto [it, inserted] =
            index.emplace(std::make_tuple(p.x, p.y, p.z), static_cast<std::uint32_t>(m.positions.size()));
        if (inserted)
            m.positions.push_back(p);
        return it->second;
    };
    bool tagged = false;
    for (const auto& f : faces_)
        tagged |= f.tag >= 0;
    for (const auto& f : faces_) {
        std::vector<std::uint32_t> ids;
        for (const Vec3& c : f.corners) {
            const std::uint32_t i = id(c);
            if (ids.empty() || ids.back() != i)
                ids.push_back(i);
        }
        while (ids.size() > 1 && ids.front() == ids.back())
            ids.pop_back();
        for (std::size_t i = 1; i + 1 < ids.size(); ++i) {
            m.triangles.push_back({ids[0], ids[i], ids[i + 1]});
            if (tagged)
                m.materials.push_back(f.tag >= 0 ? static_cast<std::uint32_t>(f.tag) : 0u);
        }
    }
    return m;
}

} // namespace rubble
