#include "collision/MeshRegion.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <tuple>
#include <unordered_map>

#include "geometry/PointBits.hpp"
#include "rubble/collision/ConvexDecomposition.hpp"

namespace rubble::detail {

namespace {

// How far a part reaches out of one hull plane, as of one round of keepInsideHull.
struct PlaneReach {
    double reach = 0;        // the farthest corner's signed distance (an upper bound in later rounds)
    std::uint32_t plane = 0; // index into the hull's planes
    Vec3 corner;             // the least corner (lexicographically) that reaches that far
    std::size_t round = 0;   // the round whose corners gave it
    bool operator<(const PlaneReach& o) const { return reach < o.reach; }
};

// The farthest corner out of plane (beyond margin), the least one of those that reach that far.
PlaneReach farthest(const std::vector<Vec3>& corners, const Plane& plane, double margin) {
    PlaneReach r;
    r.reach = margin;
    bool found = false;
    for (const Vec3& c : corners)
        if (const double d = plane.signedDistance(c);
            d > r.reach || (found && d == r.reach && lexLess(c, r.corner))) {
            r.reach = d;
            r.corner = c;
            found = true;
        }
    return r;
}

} // namespace

void keepInsideHull(std::vector<ConvexPolytope>& parts, const ConvexPolytope& hull, double margin) {
    std::vector<Plane> planes;
    planes.reserve(hull.faces().size());
    for (const PolytopeFaceView& h : hull.faces())
        planes.push_back(h.plane);
    std::vector<ConvexPolytope> kept;
    kept.reserve(parts.size());
    std::vector<PlaneReach> heap, measured;
    for (ConvexPolytope& part : parts) {
        // Clipped by the plane it reaches farthest out of, one at a time; earlier reaches are upper bounds
        // (docs/collision.md, "The hull clip measured lazily").
        heap.clear();
        const std::vector<Vec3>* corners = &part.corners();
        // A plane that the part's box does not reach out of (with room for rounding) is not measured.
        const Aabb box = part.bounds();
        const Vec3 mid = box.center(), half = box.size() * 0.5;
        const double room =
            1e-12 * (std::abs(mid.x) + std::abs(mid.y) + std::abs(mid.z) + half.x + half.y + half.z);
        for (std::uint32_t i = 0; i < planes.size(); ++i) {
            const Vec3& n = planes[i].normal;
            const double boxReach = planes[i].signedDistance(mid) + std::abs(n.x) * half.x +
                                    std::abs(n.y) * half.y + std::abs(n.z) * half.z;
            if (boxReach + room * (1 + std::abs(planes[i].offset)) <= margin)
                continue;
            if (PlaneReach r = farthest(*corners, planes[i], margin); r.reach > margin) {
                r.plane = i;
                heap.push_back(r);
            }
        }
        std::make_heap(heap.begin(), heap.end());
        for (std::size_t round = 0; round < kMaxHullClips && !part.empty(); ++round) {
            if (round > 0)
                corners = &part.corners();
            std::optional<PlaneReach> worst;
            measured.clear();
            while (!heap.empty() && (!worst || heap.front().reach >= worst->reach)) {
                std::pop_heap(heap.begin(), heap.end());
                PlaneReach r = heap.back();
                heap.pop_back();
                if (r.round != round) { // measured before the last clip: measure it again
                    const std::uint32_t plane = r.plane;
                    r = farthest(*corners, planes[plane], margin);
                    r.plane = plane;
                    r.round = round;
                    if (r.reach > margin) {
                        heap.push_back(r);
                        std::push_heap(heap.begin(), heap.end());
                    }
                    continue;
                }
                if (!worst || r.reach > worst->reach ||
                    (r.reach == worst->reach && (lexLess(r.corner, worst->corner) ||
                                                 (r.corner == worst->corner && r.plane < worst->plane))))
                    worst = r;
                measured.push_back(r);
            }
            if (!worst)
                break;
            for (const PlaneReach& r : measured) { // still bounds for the next round
                heap.push_back(r);
                std::push_heap(heap.begin(), heap.end());
            }
            part = part.clipped(planes[worst->plane]);
        }
        if (!part.empty())
            kept.push_back(std::move(part));
    }
    parts = std::move(kept);
}

void splitPolygon(const Polygon& poly, const Plane& plane, Polygon& inside, Polygon& outside) {
    inside.clear();
    outside.clear();
    const std::size_t n = poly.size();
    double dist[64];
    std::vector<double> big;
    double* d = dist;
    if (n > 64) {
        big.resize(n);
        d = big.data();
    }
    bool anyIn = false, anyOut = false;
    for (std::size_t i = 0; i < n; ++i) {
        d[i] = plane.signedDistance(poly[i]);
        anyIn |= d[i] < 0;
        anyOut |= d[i] > 0;
    }
    if (!anyOut) {
        inside = poly;
        return;
    }
    if (!anyIn) {
        outside = poly;
        return;
    }
    for (std::size_t i = 0; i < n; ++i) {
        const std::size_t j = (i + 1) % n;
        if (d[i] <= 0)
            inside.push_back(poly[i]);
        if (d[i] >= 0)
            outside.push_back(poly[i]);
        if ((d[i] < 0 && d[j] > 0) || (d[i] > 0 && d[j] < 0)) {
            const double t = d[i] / (d[i] - d[j]);
            const Vec3 x = poly[i] + (poly[j] - poly[i]) * t;
            inside.push_back(x);
            outside.push_back(x);
        }
    }
}

std::vector<Polygon> clipTrianglesToRegion(const Mesh& mesh, const ConvexPolytope& region) {
    std::vector<Polygon> out;
    const Aabb rb = region.bounds();
    Polygon in, outside;
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
        const auto c = mesh.corners(t);
        Aabb tb;
        tb.extend(c[0]);
        tb.extend(c[1]);
        tb.extend(c[2]);
        if (!tb.overlaps(rb))
            continue;
        Polygon poly{c[0], c[1], c[2]};
        for (const PolytopeFaceView& f : region.faces()) {
            splitPolygon(poly, f.plane, in, outside);
            poly.swap(in);
            if (poly.size() < 3)
                break;
        }
        if (poly.size() >= 3)
            out.push_back(std::move(poly));
    }
    return out;
}

Mesh clusteredProxy(const Mesh& mesh, int cellsPerAxis) {
    const Aabb box = mesh.bounds();
    const double floor = 1e-9 * box.diagonal() + 1e-300;
    const Vec3 size = box.size();
    const double n = std::max(cellsPerAxis, 1);
    const Vec3 h{std::max(size.x, floor) / n, std::max(size.y, floor) / n, std::max(size.z, floor) / n};
    std::unordered_map<std::uint64_t, std::uint32_t> cluster; // cell key -> proxy vertex
    std::vector<Vec3> sum;
    std::vector<double> count;
    std::vector<std::uint32_t> of(mesh.positions.size());
    for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
        const Vec3 d = mesh.positions[v] - box.lo;
        const Vec3 q{d.x / h.x, d.y / h.y, d.z / h.z};
        const auto cell = [](double x) { return static_cast<std::uint64_t>(std::max(0.0, std::floor(x))); };
        const std::uint64_t key = (cell(q.x) << 42) | (cell(q.y) << 21) | cell(q.z);
        auto [it, fresh] = cluster.try_emplace(key, static_cast<std::uint32_t>(sum.size()));
        if (fresh) {
            sum.emplace_back();
            count.push_back(0);
        }
        sum[it->second] += mesh.positions[v];
        count[it->second] += 1;
        of[v] = it->second;
    }
    Mesh proxy;
    proxy.positions.reserve(sum.size());
    for (std::size_t i = 0; i < sum.size(); ++i)
        proxy.positions.push_back(sum[i] / count[i]);
    // Net count of each triangle (rotated to start at its smallest vertex) against its reverse.
    std::map<std::array<std::uint32_t, 3>, int> net;
    std::vector<std::array<std::uint32_t, 3>> order; // first appearance, so the output is deterministic
    const auto canonical = [](std::uint32_t a, std::uint32_t b,
                              std::uint32_t c) -> std::array<std::uint32_t, 3> {
        if (a < b && a < c)
            return {a, b, c};
        if (b < c)
            return {b, c, a};
        return {c, a, b};
    };
    for (const Triangle& t : mesh.triangles) {
        const std::uint32_t a = of[t[0]], b = of[t[1]], c = of[t[2]];
        if (a == b || b == c || a == c)
            continue;
        auto reverse = net.find(canonical(a, c, b));
        if (reverse != net.end() && reverse->second > 0) {
            --reverse->second;
            continue;
        }
        auto [it, fresh] = net.try_emplace(canonical(a, b, c), 0);
        if (fresh)
            order.push_back(it->first);
        ++it->second;
    }
    for (const auto& key : order)
        for (int k = net[key]; k > 0; --k)
            proxy.triangles.push_back({key[0], key[1], key[2]});
    proxy.removeUnreferencedVertices();
    return proxy;
}

Result<ConvexPolytope> hullOfPolygons(const std::vector<Polygon>& polys, const std::vector<Vec3>& extra) {
    std::vector<Vec3> pts = extra;
    for (const Polygon& p : polys)
        pts.insert(pts.end(), p.begin(), p.end());
    std::sort(pts.begin(), pts.end(),
              [](const Vec3& a, const Vec3& b) { return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z); });
    pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
    return convexHull(pts);
}

Result<ConvexPolytope> hullOfMeshInRegion(const Mesh& mesh, const ConvexPolytope& region) {
    const std::vector<Polygon> polys = clipTrianglesToRegion(mesh, region);
    std::vector<Vec3> extra;
    for (const Vec3& v : region.vertices())
        if (insideMesh(mesh, v))
            extra.push_back(v);
    return hullOfPolygons(polys, extra);
}

} // namespace rubble::detail
