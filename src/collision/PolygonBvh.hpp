#pragma once
// A bounding-volume hierarchy over planar convex polygons (fanned into triangles), for the nearest ray hit.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

#include "collision/MeshRegion.hpp"
#include "rubble/core/Aabb.hpp"

namespace rubble::detail {

/// Möller–Trumbore: the ray parameter of the hit of o + t·d with triangle abc, or −1 for a miss.
inline double rayTriangle(const Vec3& o, const Vec3& d, const Vec3& a, const Vec3& b, const Vec3& c) {
    const Vec3 e1 = b - a, e2 = c - a;
    const Vec3 p = cross(d, e2);
    const double det = dot(e1, p);
    if (std::abs(det) < 1e-300)
        return -1;
    const double inv = 1.0 / det;
    const Vec3 s = o - a;
    const double u = dot(s, p) * inv;
    if (u < 0 || u > 1)
        return -1;
    const Vec3 q = cross(s, e1);
    const double v = dot(d, q) * inv;
    if (v < 0 || u + v > 1)
        return -1;
    return dot(e2, q) * inv;
}

/// The fan triangles of polygons in a median-split tree of boxes (padded, so a hit is never culled).
class PolygonBvh {
public:
    explicit PolygonBvh(const std::vector<Polygon>& polygons) {
        for (const Polygon& poly : polygons)
            for (std::size_t k = 1; k + 1 < poly.size(); ++k)
                tris_.push_back({poly[0], poly[k], poly[k + 1]});
        index();
    }
    /// The triangles of a mesh, in their orientation.
    explicit PolygonBvh(const Mesh& mesh) {
        tris_.reserve(mesh.triangles.size());
        for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
            const auto c = mesh.corners(t);
            tris_.push_back({c[0], c[1], c[2]});
        }
        index();
    }

    /// The winding number of closed triangles around o, counted as signed crossings of the ray o + t·d
    /// (t > 0; +1 where it leaves through a triangle's front); nullopt when the ray passes within about
    /// 1e-9 of an edge, grazes a triangle's plane or o lies within epsilon of a triangle it crosses.
    std::optional<int> winding(const Vec3& o, const Vec3& d, double epsilon) const {
        if (nodes_.empty())
            return 0;
        constexpr double kEdge = 1e-9;
        int w = 0;
        const Vec3 inv{1 / d.x, 1 / d.y, 1 / d.z};
        const double far = std::numeric_limits<double>::infinity();
        std::uint32_t stack[128];
        int top = 0;
        stack[top++] = 0;
        while (top > 0) {
            const Node& n = nodes_[stack[--top]];
            if (!hitsBox(n.box, o, d, inv, far))
                continue;
            if (n.count == 0) {
                stack[top++] = n.first;
                stack[top++] = n.second;
                continue;
            }
            for (std::uint32_t i = n.first; i < n.first + n.count; ++i) {
                const Tri& tri = tris_[order_[i]];
                const Vec3 e1 = tri[1] - tri[0], e2 = tri[2] - tri[0];
                const Vec3 p = cross(d, e2);
                const double det = dot(e1, p);
                const Vec3 s = o - tri[0];
                if (std::abs(det) <= kEdge * length(e1) * length(e2)) {
                    // Parallel to the plane: harmless unless the ray runs in it.
                    if (std::abs(dot(s, cross(e1, e2))) <= epsilon * length(cross(e1, e2)))
                        return std::nullopt;
                    continue;
                }
                const double inv_det = 1.0 / det;
                const double u = dot(s, p) * inv_det;
                const Vec3 q = cross(s, e1);
                const double v = dot(d, q) * inv_det;
                if (u < -kEdge || v < -kEdge || u + v > 1 + kEdge)
                    continue;
                const double t = dot(e2, q) * inv_det;
                if (std::abs(t) <= epsilon)
                    return std::nullopt; // o on the triangle
                if (t < 0)
                    continue;
                if (u <= kEdge || v <= kEdge || u + v >= 1 - kEdge)
                    return std::nullopt; // through an edge or a corner
                w += det < 0 ? 1 : -1;
            }
        }
        return w;
    }

private:
    void index() {
        order_.resize(tris_.size());
        for (std::size_t i = 0; i < order_.size(); ++i)
            order_[i] = static_cast<std::uint32_t>(i);
        Aabb all;
        for (const Tri& t : tris_)
            for (const Vec3& p : t)
                all.extend(p);
        pad_ = 1e-9 * (all.diagonal() + 1);
        centres_.reserve(tris_.size());
        for (const Tri& t : tris_)
            centres_.push_back(centroid(t));
        if (!tris_.empty())
            build(0, static_cast<std::uint32_t>(tris_.size()));
        centres_ = {};
    }

public:
    /// The smallest t in [0, tMax) where the ray o + t·d hits a triangle (tMax when none); the search stops
    /// early once t <= stopBelow.
    double nearest(const Vec3& o, const Vec3& d, double tMax, double stopBelow) const {
        if (nodes_.empty())
            return tMax;
        double t = tMax;
        const Vec3 inv{1 / d.x, 1 / d.y, 1 / d.z};
        std::uint32_t stack[128]; // median splits keep the depth near log2 of the count
        int top = 0;
        stack[top++] = 0;
        while (top > 0) {
            const Node& n = nodes_[stack[--top]];
            if (!hitsBox(n.box, o, d, inv, t))
                continue;
            if (n.count > 0) {
                for (std::uint32_t i = n.first; i < n.first + n.count; ++i) {
                    const Tri& tri = tris_[order_[i]];
                    const double h = rayTriangle(o, d, tri[0], tri[1], tri[2]);
                    if (h >= 0 && h < t)
                        t = h;
                }
                if (t <= stopBelow)
                    return t;
            } else {
                stack[top++] = n.first;
                stack[top++] = n.second;
            }
        }
        return t;
    }

private:
    using Tri = std::array<Vec3, 3>;
    struct Node {
        Aabb box;
        std::uint32_t first = 0;  // leaf: first index in order_; inner: index of the left child
        std::uint32_t second = 0; // inner: index of the right child
        std::uint32_t count = 0;  // triangles of a leaf, 0 for an inner node
    };
    static constexpr std::uint32_t kLeafSize = 4;

    static Vec3 centroid(const Tri& t) { return (t[0] + t[1] + t[2]) / 3.0; }

    // Builds the node of order_[begin, end) at the back of nodes_ and returns its index.
    std::uint32_t build(std::uint32_t begin, std::uint32_t end) {
        const auto index = static_cast<std::uint32_t>(nodes_.size());
        nodes_.emplace_back();
        Aabb box, centers;
        for (std::uint32_t i = begin; i < end; ++i) {
            for (const Vec3& p : tris_[order_[i]])
                box.extend(p);
            centers.extend(centres_[order_[i]]);
        }
        box.lo -= Vec3{pad_, pad_, pad_};
        box.hi += Vec3{pad_, pad_, pad_};
        nodes_[index].box = box;
        if (end - begin <= kLeafSize) {
            nodes_[index].first = begin;
            nodes_[index].count = end - begin;
            return index;
        }
        const Vec3 extent = centers.size();
        const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
        const std::uint32_t mid = begin + (end - begin) / 2;
        std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
                         [&](std::uint32_t a, std::uint32_t b) {
                             const double ca = centres_[a][axis], cb = centres_[b][axis];
                             return ca < cb || (ca == cb && a < b);
                         });
        const std::uint32_t left = build(begin, mid);
        const std::uint32_t right = build(mid, end);
        nodes_[index].first = left;
        nodes_[index].second = right;
        return index;
    }

    static bool hitsBox(const Aabb& b, const Vec3& o, const Vec3& d, const Vec3& inv, double tMax) {
        double t0 = 0, t1 = tMax;
        for (int a = 0; a < 3; ++a) {
            if (d[a] == 0) {
                if (o[a] < b.lo[a] || o[a] > b.hi[a])
                    return false;
                continue;
            }
            double n = (b.lo[a] - o[a]) * inv[a], f = (b.hi[a] - o[a]) * inv[a];
            if (n > f)
                std::swap(n, f);
            t0 = std::max(t0, n);
            t1 = std::min(t1, f);
            if (t0 > t1)
                return false;
        }
        return true;
    }

    std::vector<Tri> tris_;
    std::vector<Vec3> centres_; // the triangles' centroids, while building
    std::vector<std::uint32_t> order_;
    std::vector<Node> nodes_;
    double pad_ = 0;
};

} // namespace rubble::detail
