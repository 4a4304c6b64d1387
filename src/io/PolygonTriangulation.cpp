#include "io/PolygonTriangulation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace rubble::io {

namespace {
constexpr std::size_t kMaxEarClipCorners = 1024;

double cross2(double ax, double ay, double bx, double by) {
    return ax * by - ay * bx;
}

} // namespace

std::vector<std::array<std::size_t, 3>> triangulatePolygon(const std::vector<Vec3>& pts) {
    const std::size_t n = pts.size();
    std::vector<std::array<std::size_t, 3>> out;
    auto fanFrom = [&](std::size_t s) {
        for (std::size_t i = 1; i + 1 < n; ++i)
            out.push_back({s, (s + i) % n, (s + i + 1) % n});
    };
    bool finite = true;
    for (const Vec3& p : pts)
        finite = finite && isFinite(p);
    Vec3 normal; // Newell's method
    for (std::size_t i = 0; i < n && finite; ++i) {
        const Vec3& a = pts[i];
        const Vec3& b = pts[(i + 1) % n];
        normal += Vec3{(a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y)};
    }
    if (!finite || !(lengthSquared(normal) > 0) || !isFinite(normal)) {
        fanFrom(0);
        return out;
    }
    const Vec3 nz = normalized(normal);
    const Vec3 ux = normalized(std::abs(nz.x) < 0.9 ? cross(Vec3{1, 0, 0}, nz) : cross(Vec3{0, 1, 0}, nz));
    const Vec3 vy = cross(nz, ux);
    std::vector<std::array<double, 2>> p(n);
    for (std::size_t i = 0; i < n; ++i)
        p[i] = {dot(pts[i] - pts[0], ux), dot(pts[i] - pts[0], vy)};
    auto turn = [&](std::size_t a, std::size_t b, std::size_t c) {
        return cross2(p[b][0] - p[a][0], p[b][1] - p[a][1], p[c][0] - p[b][0], p[c][1] - p[b][1]);
    };
    bool convex = true;
    std::size_t best = 0;
    double bestTurn = -std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < n; ++i) {
        const double t = turn((i + n - 1) % n, i, (i + 1) % n);
        convex = convex && t >= 0;
        if (t > bestTurn) {
            bestTurn = t;
            best = i;
        }
    }
    if (convex || n > kMaxEarClipCorners) {
        fanFrom(best);
        return out;
    }
    // Ear clipping. Points within a relative tolerance of a candidate ear count as inside it, so that
    // rounding in the projection cannot produce zero-area triangles.
    double extent = 0;
    for (const auto& q : p)
        extent = std::max({extent, std::abs(q[0]), std::abs(q[1])});
    const double eps = 1e-12 * extent * extent;
    std::vector<std::size_t> ring(n);
    for (std::size_t i = 0; i < n; ++i)
        ring[i] = i;
    auto inside = [&](std::size_t q, std::size_t a, std::size_t b, std::size_t c) {
        const double d1 = cross2(p[b][0] - p[a][0], p[b][1] - p[a][1], p[q][0] - p[a][0], p[q][1] - p[a][1]);
        const double d2 = cross2(p[c][0] - p[b][0], p[c][1] - p[b][1], p[q][0] - p[b][0], p[q][1] - p[b][1]);
        const double d3 = cross2(p[a][0] - p[c][0], p[a][1] - p[c][1], p[q][0] - p[c][0], p[q][1] - p[c][1]);
        return d1 >= -eps && d2 >= -eps && d3 >= -eps;
    };
    std::size_t k = 0;
    while (ring.size() > 3) {
        const std::size_t m = ring.size();
        bool clipped = false;
        for (std::size_t tries = 0; tries < m; ++tries, k = (k + 1) % m) {
            const std::size_t a = ring[(k + m - 1) % m], b = ring[k], c = ring[(k + 1) % m];
            if (turn(a, b, c) <= eps)
                continue;
            bool ear = true;
            for (std::size_t q : ring) {
                if (q == a || q == b || q == c || p[q] == p[a] || p[q] == p[b] || p[q] == p[c])
                    continue;
                if (inside(q, a, b, c)) {
                    ear = false;
                    break;
                }
            }
            if (!ear)
                continue;
            out.push_back({a, b, c});
            ring.erase(ring.begin() + static_cast<std::ptrdiff_t>(k));
            k = k % ring.size();
            clipped = true;
            break;
        }
        if (!clipped) { // self-intersecting or degenerate remainder: fan what is left
            for (std::size_t i = 1; i + 1 < ring.size(); ++i)
                out.push_back({ring[0], ring[i], ring[i + 1]});
            return out;
        }
    }
    out.push_back({ring[0], ring[1], ring[2]});
    return out;
}

} // namespace rubble::io
