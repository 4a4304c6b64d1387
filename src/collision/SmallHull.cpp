#include "collision/SmallHull.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>

#include "rubble/collision/ConvexDecomposition.hpp"

namespace rubble::detail {
namespace {

/// A hull triangle, counter-clockwise seen from outside.
struct Tri {
    std::uint32_t v[3];
    Vec3 area; // the cross product of its edges: outward, twice its area long
    Vec3 normal;
    double offset = 0;
    bool alive = true;
    double distance(const Vec3& p) const { return dot(normal, p) - offset; }
};

/// Incremental hull of a few points; every step that could go wrong declines instead.
class Builder {
public:
    explicit Builder(const std::vector<Vec3>& points)
        : p_(points), n_(points.size()), edge_(n_ * n_, -1), next_(n_, -1), seen_(n_, 0) {
        tris_.reserve(4 * n_);
        visibleMark_.reserve(4 * n_);
    }

    std::optional<ConvexPolytope> run() {
        Aabb box;
        double reach = 0;
        for (const Vec3& p : p_) {
            if (!isFinite(p))
                return std::nullopt;
            box.extend(p);
            reach = std::max({reach, std::abs(p.x), std::abs(p.y), std::abs(p.z)});
        }
        eps_ = 1e-12 * (reach + box.diagonal());
        if (!simplex())
            return std::nullopt;
        for (std::uint32_t i : order_)
            if (!insert(i))
                return std::nullopt;
        return faces();
    }

private:
    const std::vector<Vec3>& p_;
    std::size_t n_;
    double eps_ = 0;
    std::vector<Tri> tris_;
    std::vector<std::int32_t> edge_; // edge_[a * n + b]: the live triangle with directed edge a → b
    std::vector<std::int32_t> next_; // scratch: a loop's next vertex
    std::vector<std::uint32_t> seen_;
    std::uint32_t stamp_ = 0;
    std::vector<std::uint32_t> order_; // the points left after the first four, farthest first
    std::vector<std::uint32_t> visibleMark_;
    std::vector<std::int32_t> stack_, visible_; // scratch of insert
    std::vector<std::pair<std::uint32_t, std::uint32_t>> horizon_;

    std::int32_t& edge(std::uint32_t a, std::uint32_t b) { return edge_[a * n_ + b]; }

    bool addTri(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
        Tri t{{a, b, c}, cross(p_[b] - p_[a], p_[c] - p_[a]), {}, 0, true};
        const double len = length(t.area);
        if (!(len > 0))
            return false;
        t.normal = t.area / len;
        t.offset = (dot(t.normal, p_[a]) + dot(t.normal, p_[b]) + dot(t.normal, p_[c])) / 3;
        const auto id = static_cast<std::int32_t>(tris_.size());
        for (int k = 0; k < 3; ++k) {
            std::int32_t& e = edge(t.v[k], t.v[(k + 1) % 3]);
            if (e >= 0)
                return false;
            e = id;
        }
        tris_.push_back(t);
        visibleMark_.push_back(0);
        return true;
    }

    bool simplex() {
        std::uint32_t i0 = 0;
        for (std::uint32_t i = 1; i < n_; ++i)
            if (p_[i].x < p_[i0].x)
                i0 = i;
        auto farthest = [&](auto&& measure) {
            std::uint32_t best = i0;
            double bestValue = -1;
            for (std::uint32_t i = 0; i < n_; ++i)
                if (const double v = measure(p_[i] - p_[i0]); v > bestValue) {
                    bestValue = v;
                    best = i;
                }
            return std::pair{best, bestValue};
        };
        const double big = 1000 * eps_;
        const auto first = farthest([](const Vec3& d) { return length(d); });
        const std::uint32_t i1 = first.first;
        const double d1 = first.second;
        if (!(d1 > big))
            return false;
        const Vec3 u = p_[i1] - p_[i0];
        const auto second = farthest([&](const Vec3& d) { return length(cross(u, d)) / d1; });
        const std::uint32_t i2 = second.first;
        if (!(second.second > big))
            return false;
        const Vec3 w = normalized(cross(u, p_[i2] - p_[i0]));
        const auto third = farthest([&](const Vec3& d) { return std::abs(dot(w, d)); });
        const std::uint32_t i3 = third.first;
        if (!(third.second > big))
            return false;
        std::uint32_t a = i0, b = i1, c = i2;
        if (dot(w, p_[i3] - p_[i0]) < 0)
            std::swap(b, c);
        if (!addTri(a, c, b) || !addTri(a, b, i3) || !addTri(b, c, i3) || !addTri(c, a, i3))
            return false;
        std::vector<std::pair<double, std::uint32_t>> rest;
        for (std::uint32_t i = 0; i < n_; ++i) {
            if (i == i0 || i == i1 || i == i2 || i == i3)
                continue;
            double d = -1e300;
            for (const Tri& t : tris_)
                d = std::max(d, t.distance(p_[i]));
            if (d > eps_)
                rest.emplace_back(-d, i);
        }
        std::sort(rest.begin(), rest.end());
        for (const auto& r : rest)
            order_.push_back(r.second);
        return true;
    }

    // Replaces the triangles point i sees by a fan from i to their horizon; false where that cannot close.
    bool insert(std::uint32_t i) {
        const Vec3& p = p_[i];
        std::int32_t best = -1;
        double bestDistance = eps_;
        for (std::size_t f = 0; f < tris_.size(); ++f)
            if (tris_[f].alive)
                if (const double d = tris_[f].distance(p); d > bestDistance) {
                    bestDistance = d;
                    best = static_cast<std::int32_t>(f);
                }
        if (best < 0)
            return true; // inside, within rounding
        ++stamp_;
        std::vector<std::int32_t>& stack = stack_;
        std::vector<std::int32_t>& visible = visible_;
        std::vector<std::pair<std::uint32_t, std::uint32_t>>& horizon = horizon_;
        stack.assign(1, best);
        visible.clear();
        horizon.clear();
        visibleMark_[static_cast<std::size_t>(best)] = stamp_;
        while (!stack.empty()) {
            const std::int32_t f = stack.back();
            stack.pop_back();
            visible.push_back(f);
            const Tri& t = tris_[static_cast<std::size_t>(f)];
            for (int k = 0; k < 3; ++k) {
                const std::uint32_t a = t.v[k], b = t.v[(k + 1) % 3];
                const std::int32_t g = edge(b, a);
                if (g < 0)
                    return false;
                const auto gs = static_cast<std::size_t>(g);
                if (visibleMark_[gs] == stamp_)
                    continue;
                if (tris_[gs].distance(p) > eps_) {
                    visibleMark_[gs] = stamp_;
                    stack.push_back(g);
                } else {
                    horizon.emplace_back(a, b);
                }
            }
        }
        const bool loop = oneLoop(horizon);
        clearLoop(horizon);
        if (!loop)
            return false;
        for (std::int32_t f : visible) {
            Tri& t = tris_[static_cast<std::size_t>(f)];
            t.alive = false;
            for (int k = 0; k < 3; ++k)
                edge(t.v[k], t.v[(k + 1) % 3]) = -1;
        }
        for (const auto& [a, b] : horizon)
            if (!addTri(a, b, i))
                return false;
        return true;
    }

    // True when the directed edges form one simple loop; each edge's end stays in next_ until clearLoop.
    bool oneLoop(const std::vector<std::pair<std::uint32_t, std::uint32_t>>& edges) {
        bool ok = edges.size() >= 3;
        for (const auto& [a, b] : edges) {
            ok = ok && next_[a] < 0;
            next_[a] = static_cast<std::int32_t>(b);
        }
        if (!ok)
            return false;
        ++stamp_;
        const std::uint32_t start = edges.front().first;
        std::uint32_t v = start;
        for (std::size_t k = 0; k < edges.size() && ok; ++k) {
            ok = next_[v] >= 0 && seen_[v] != stamp_;
            seen_[v] = stamp_;
            if (ok)
                v = static_cast<std::uint32_t>(next_[v]);
        }
        return ok && v == start;
    }

    // Empties next_ at the edges' starts.
    void clearLoop(const std::vector<std::pair<std::uint32_t, std::uint32_t>>& edges) {
        for (const auto& e : edges)
            next_[e.first] = -1;
    }

    // The polytope of the live triangles, those in one plane merged into one face (docs/collision.md).
    std::optional<ConvexPolytope> faces() {
        std::vector<std::uint32_t> root(tris_.size());
        std::iota(root.begin(), root.end(), 0u);
        auto find = [&](std::uint32_t f) {
            while (root[f] != f)
                f = root[f] = root[root[f]];
            return f;
        };
        auto far = [](const Tri& t, std::uint32_t a, std::uint32_t b) {
            for (std::uint32_t v : t.v)
                if (v != a && v != b)
                    return v;
            return t.v[0];
        };
        for (std::uint32_t f = 0; f < tris_.size(); ++f) {
            const Tri& t = tris_[f];
            if (!t.alive)
                continue;
            for (int k = 0; k < 3; ++k) {
                const std::uint32_t a = t.v[k], b = t.v[(k + 1) % 3];
                const std::int32_t twin = edge(b, a);
                if (twin < 0)
                    return std::nullopt;
                const auto g = static_cast<std::uint32_t>(twin);
                if (g <= f)
                    continue;
                const Tri& u = tris_[g];
                if (dot(t.normal, u.normal) > 0 && u.distance(p_[far(t, a, b)]) > -eps_ &&
                    t.distance(p_[far(u, b, a)]) > -eps_) {
                    const std::uint32_t rf = find(f), rg = find(g);
                    root[std::max(rf, rg)] = std::min(rf, rg);
                }
            }
        }
        // Each face: its plane and its boundary loop.
        struct Face {
            std::uint32_t root;
            Plane plane;
            std::vector<std::uint32_t> tris, loop;
        };
        std::vector<Face> out;
        std::vector<std::int32_t> faceOf(tris_.size(), -1);
        for (std::uint32_t f = 0; f < tris_.size(); ++f)
            if (tris_[f].alive) {
                const std::uint32_t r = find(f);
                if (faceOf[r] < 0) {
                    faceOf[r] = static_cast<std::int32_t>(out.size());
                    out.push_back({r, Plane{Vec3{}, 0}, {}, {}});
                }
                Face& face = out[static_cast<std::size_t>(faceOf[r])];
                face.plane.normal += tris_[f].area;
                face.tris.push_back(f);
                faceOf[f] = faceOf[r];
            }
        std::vector<std::pair<std::uint32_t, std::uint32_t>> boundary;
        std::vector<std::uint32_t> facesAt(n_, 0);
        for (std::size_t i = 0; i < out.size(); ++i) {
            Face& face = out[i];
            face.plane.normal = normalized(face.plane.normal);
            boundary.clear();
            for (std::uint32_t f : face.tris) {
                const Tri& t = tris_[f];
                for (int k = 0; k < 3; ++k) {
                    const std::uint32_t a = t.v[k], b = t.v[(k + 1) % 3];
                    const std::int32_t twin = edge(b, a);
                    if (twin < 0)
                        return std::nullopt;
                    if (faceOf[static_cast<std::size_t>(twin)] != static_cast<std::int32_t>(i))
                        boundary.emplace_back(a, b);
                }
            }
            if (!oneLoop(boundary)) {
                clearLoop(boundary);
                return std::nullopt;
            }
            const std::uint32_t first = std::min_element(boundary.begin(), boundary.end())->first;
            std::uint32_t v = first;
            double lo = 1e300, hi = -1e300;
            do {
                face.loop.push_back(v);
                ++facesAt[v];
                const double d = dot(face.plane.normal, p_[v]);
                lo = std::min(lo, d);
                hi = std::max(hi, d);
                v = static_cast<std::uint32_t>(next_[v]);
            } while (v != first);
            clearLoop(boundary);
            if (!(hi - lo <= 4 * eps_))
                return std::nullopt;
            face.plane.offset = hi;
        }
        std::vector<PolytopeFace> faces;
        faces.reserve(out.size());
        std::size_t corners = 0, vertices = 0;
        for (std::uint32_t v = 0; v < n_; ++v)
            vertices += facesAt[v] >= 3;
        for (const Face& face : out) {
            PolytopeFace pf;
            pf.plane = face.plane;
            for (std::uint32_t v : face.loop)
                if (facesAt[v] >= 3)
                    pf.corners.push_back(p_[v]);
            if (pf.corners.size() < 3)
                return std::nullopt;
            corners += pf.corners.size();
            faces.push_back(std::move(pf));
        }
        if (corners % 2 != 0 || vertices + faces.size() != corners / 2 + 2) // Euler: V - E + F = 2
            return std::nullopt;
        for (const PolytopeFace& f : faces)
            for (const Vec3& p : p_)
                if (f.plane.signedDistance(p) > 4 * eps_)
                    return std::nullopt;
        return ConvexPolytope::fromFaces(std::move(faces));
    }
};

} // namespace

std::optional<ConvexPolytope> smallHull(const std::vector<Vec3>& points) {
    if (points.size() < 4 || points.size() > kSmallHullPoints)
        return std::nullopt;
    return Builder(points).run();
}

Result<ConvexPolytope> hullOfFew(const std::vector<Vec3>& points) {
    if (auto small = smallHull(points); small && small->volume() > 0)
        return std::move(*small);
    return convexHull(points);
}

} // namespace rubble::detail
