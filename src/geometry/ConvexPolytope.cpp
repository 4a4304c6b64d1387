#include "rubble/geometry/ConvexPolytope.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <map>

#include "geometry/PointBits.hpp"
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

using detail::lexLess;
using detail::pointBits;
} // namespace

ConvexPolytope ConvexPolytope::fromAabb(const Aabb& box) {
    const Vec3 l = box.lo, h = box.hi;
    ConvexPolytope p;
    p.corners_ = {{l.x, l.y, l.z}, {h.x, l.y, l.z}, {h.x, h.y, l.z}, {l.x, h.y, l.z},
                  {l.x, l.y, h.z}, {h.x, l.y, h.z}, {h.x, h.y, h.z}, {l.x, h.y, h.z}};
    p.index_ = {0, 4, 7, 3, 1, 2, 6, 5, 0, 1, 5, 4, 3, 7, 6, 2, 0, 3, 2, 1, 4, 5, 6, 7};
    p.faces_ = {{{{-1, 0, 0}, -l.x}, 0, -1}, {{{1, 0, 0}, h.x}, 4, -1},    {{{0, -1, 0}, -l.y}, 8, -1},
                {{{0, 1, 0}, h.y}, 12, -1},  {{{0, 0, -1}, -l.z}, 16, -1}, {{{0, 0, 1}, h.z}, 20, -1}};
    return p;
}

ConvexPolytope ConvexPolytope::fromFaces(std::vector<PolytopeFace> faces) {
    // corners shared where their bits are equal, so that every face keeps its corners exactly
    struct Ref {
        std::array<std::uint64_t, 3> bits;
        std::uint32_t at;
    };
    std::vector<Ref> refs;
    for (const PolytopeFace& f : faces)
        for (const Vec3& c : f.corners)
            refs.push_back({pointBits(c), static_cast<std::uint32_t>(refs.size())});
    std::sort(refs.begin(), refs.end(), [](const Ref& a, const Ref& b) { return a.bits < b.bits; });
    ConvexPolytope p;
    p.index_.resize(refs.size());
    std::vector<Vec3> flat;
    flat.reserve(refs.size());
    for (const PolytopeFace& f : faces)
        flat.insert(flat.end(), f.corners.begin(), f.corners.end());
    for (std::size_t i = 0; i < refs.size(); ++i) {
        if (i == 0 || refs[i].bits != refs[i - 1].bits)
            p.corners_.push_back(flat[refs[i].at]);
        p.index_[refs[i].at] = static_cast<std::uint32_t>(p.corners_.size() - 1);
    }
    p.corners_.shrink_to_fit();
    p.faces_.reserve(faces.size());
    std::uint32_t first = 0;
    for (const PolytopeFace& f : faces) {
        p.faces_.push_back({f.plane, first, f.tag});
        first += static_cast<std::uint32_t>(f.corners.size());
    }
    return p;
}

std::vector<PolytopeFace> ConvexPolytope::faceList() const {
    std::vector<PolytopeFace> out;
    out.reserve(faces_.size());
    for (const PolytopeFaceView& f : faces())
        out.push_back({f.plane, std::vector<Vec3>(f.corners.begin(), f.corners.end()), f.tag});
    return out;
}

std::vector<Vec3> ConvexPolytope::vertices() const {
    std::vector<Vec3> out = corners_;
    std::sort(out.begin(), out.end(), lexLess);
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
}

std::size_t ConvexPolytope::heapBytes() const {
    return faces_.capacity() * sizeof(Face) + corners_.capacity() * sizeof(Vec3) +
           index_.capacity() * sizeof(std::uint32_t);
}

Aabb ConvexPolytope::bounds() const {
    Aabb b;
    for (const Vec3& c : corners_)
        b.extend(c);
    return b;
}

double ConvexPolytope::volume() const {
    if (empty())
        return 0;
    const Vec3 r = corners_[index_[0]];
    double v = 0;
    for (const PolytopeFaceView& f : faces())
        for (std::size_t i = 1; i + 1 < f.corners.size(); ++i)
            v += dot(f.corners[0] - r, cross(f.corners[i] - r, f.corners[i + 1] - r));
    return v / 6.0;
}

Vec3 ConvexPolytope::centroid() const {
    if (empty())
        return {};
    const Vec3 r = corners_[index_[0]];
    double v = 0;
    Vec3 c;
    for (const PolytopeFaceView& f : faces())
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
    for (const Face& f : faces_)
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
    constexpr std::uint32_t kNone = ~0u;
    // This thread's work arrays (clipping runs often: no allocation but the result's).
    struct Crossing {
        std::uint32_t a, c; // the edge's old corners, a < c
        Vec3 p;
        std::uint32_t at; // its index in the result, or kNone until a face uses it
    };
    thread_local struct {
        ConvexPolytope out;
        std::vector<double> dist;
        std::vector<std::uint32_t> kept, pending, cap;
        std::vector<Crossing> crossings;
        std::vector<std::pair<Vec3, std::uint32_t>> capPoints;
        std::vector<std::pair<double, std::uint32_t>> ordered;
    } work;
    // signed distance of each corner, snapped to 0 within tol
    std::vector<double>& dist = work.dist;
    dist.resize(corners_.size());
    bool anyOut = false, anyIn = false;
    for (std::size_t i = 0; i < corners_.size(); ++i) {
        const double d = plane.signedDistance(corners_[i]);
        anyOut |= d > tol;
        anyIn |= d < -tol;
        dist[i] = std::abs(d) <= tol ? 0 : d;
    }
    if (!anyOut)
        return *this;
    if (!anyIn)
        return {};

    // A new corner is a kept corner (its old index) or a point where an edge crosses the plane; both are
    // added to out.corners_ only when a face or the cap uses them.
    std::vector<std::uint32_t>& kept = work.kept;
    kept.assign(corners_.size(), kNone);
    std::vector<Crossing>& crossings = work.crossings;
    crossings.clear();
    ConvexPolytope& out = work.out; // returned as an exact-size copy
    out.faces_.clear();
    out.corners_.clear();
    out.index_.clear();
    auto keep = [&](std::uint32_t old) {
        if (kept[old] == kNone) {
            kept[old] = static_cast<std::uint32_t>(out.corners_.size());
            out.corners_.push_back(corners_[old]);
        }
        return kept[old];
    };
    auto place = [&](Crossing& x) {
        if (x.at == kNone) {
            x.at = static_cast<std::uint32_t>(out.corners_.size());
            out.corners_.push_back(x.p);
        }
        return x.at;
    };
    // a face's corners until it is known to keep three: an old index, or kCrossing | a crossing
    constexpr std::uint32_t kCrossing = 1u << 31;
    std::vector<std::uint32_t>& pending = work.pending;
    std::vector<std::uint32_t>& cap = work.cap; // the same encoding, the points on the plane
    cap.clear();
    for (std::size_t fi = 0; fi < faces_.size(); ++fi) {
        const std::uint32_t first = faces_[fi].first;
        const std::uint32_t end =
            fi + 1 < faces_.size() ? faces_[fi + 1].first : static_cast<std::uint32_t>(index_.size());
        const std::uint32_t n = end - first;
        pending.clear();
        for (std::uint32_t i = 0; i < n; ++i) {
            const std::uint32_t ia = index_[first + i], ic = index_[first + (i + 1) % n];
            const double da = dist[ia], dc = dist[ic];
            if (da <= 0) {
                pending.push_back(ia);
                if (da == 0)
                    cap.push_back(ia);
            }
            if ((da < 0 && dc > 0) || (da > 0 && dc < 0)) {
                const Vec3 x = edgePlanePoint(corners_[ia], corners_[ic], da, dc);
                const std::uint32_t lo = std::min(ia, ic), hi = std::max(ia, ic);
                std::size_t k = 0;
                while (k < crossings.size() && !(crossings[k].a == lo && crossings[k].c == hi &&
                                                 pointBits(crossings[k].p) == pointBits(x)))
                    ++k;
                if (k == crossings.size())
                    crossings.push_back({lo, hi, x, kNone});
                pending.push_back(kCrossing | static_cast<std::uint32_t>(k));
                cap.push_back(kCrossing | static_cast<std::uint32_t>(k));
            }
        }
        if (pending.size() < 3)
            continue;
        out.faces_.push_back(
            {faces_[fi].plane, static_cast<std::uint32_t>(out.index_.size()), faces_[fi].tag});
        for (std::uint32_t e : pending)
            out.index_.push_back((e & kCrossing) ? place(crossings[e & ~kCrossing]) : keep(e));
    }
    auto pointOf = [&](std::uint32_t e) {
        return (e & kCrossing) ? crossings[e & ~kCrossing].p : corners_[e];
    };
    // Cap face: the points on the plane, ordered counter-clockwise around the outward normal.
    std::vector<std::pair<Vec3, std::uint32_t>>& capPoints = work.capPoints;
    capPoints.clear();
    for (std::uint32_t e : cap)
        capPoints.emplace_back(pointOf(e), e);
    std::sort(capPoints.begin(), capPoints.end(),
              [](const auto& x, const auto& y) { return lexLess(x.first, y.first); });
    capPoints.erase(std::unique(capPoints.begin(), capPoints.end(),
                                [](const auto& x, const auto& y) { return x.first == y.first; }),
                    capPoints.end());
    if (capPoints.size() >= 3) {
        Vec3 center;
        for (const auto& [p, e] : capPoints)
            center += p;
        center = center / static_cast<double>(capPoints.size());
        const Vec3 n = plane.normal;
        const Vec3 u = normalized(std::abs(n.x) < 0.9 ? cross(n, Vec3{1, 0, 0}) : cross(n, Vec3{0, 1, 0}));
        const Vec3 v = cross(n, u);
        std::vector<std::pair<double, std::uint32_t>>& ordered = work.ordered;
        ordered.clear();
        for (const auto& [p, e] : capPoints)
            ordered.emplace_back(detail::pseudoAngle(dot(p - center, u), dot(p - center, v)), e);
        std::sort(ordered.begin(), ordered.end(),
                  [](const auto& x, const auto& y) { return x.first < y.first; });
        out.faces_.push_back({plane, static_cast<std::uint32_t>(out.index_.size()), tag});
        for (const auto& [angle, e] : ordered)
            out.index_.push_back((e & kCrossing) ? place(crossings[e & ~kCrossing]) : keep(e));
    }
    if (out.faces_.size() < 4 || out.volume() <= 0)
        return {};
    return ConvexPolytope(out);
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
    for (const Face& f : faces_)
        tagged |= f.tag >= 0;
    for (const PolytopeFaceView& f : faces()) {
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
