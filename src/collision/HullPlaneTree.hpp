#pragma once
// A tree over a convex hull's face planes, for the first plane a ray from inside leaves through before a
// given distance, without testing every plane.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "rubble/geometry/ConvexPolytope.hpp"

namespace rubble::detail {

/// Planes grouped by their faces' centres (median splits); each group bounds how far a point can lie beyond
/// any of its planes and how much any of its normals can face a direction.
class HullPlaneTree {
public:
    /// faces: the hull's faces (their centres place the planes); planes[i] is faces[i]'s plane.
    HullPlaneTree(const PolytopeFaces& faces, const std::vector<Plane>& planes) : planes_(planes) {
        centres_.reserve(faces.size());
        double scale = 0;
        for (const PolytopeFaceView& f : faces) {
            Vec3 c;
            for (const Vec3& p : f.corners)
                c += p;
            c = f.corners.empty() ? c : c / static_cast<double>(f.corners.size());
            centres_.push_back(c);
            scale = std::max({scale, std::abs(c.x), std::abs(c.y), std::abs(c.z), std::abs(f.plane.offset)});
        }
        scale_ = scale;
        order_.resize(planes_.size());
        for (std::size_t i = 0; i < order_.size(); ++i)
            order_[i] = static_cast<std::uint32_t>(i);
        if (!order_.empty())
            build(0, static_cast<std::uint32_t>(order_.size()));
    }

    /// min over planes with cosine nd = n·dir > 1e-12 and a = offset − n·o ≤ reach·nd of a / nd (infinity
    /// when none), computed plane by plane as a scan of all of them computes it.
    double exitBefore(const Vec3& o, const Vec3& dir, double reach) const {
        double t = std::numeric_limits<double>::infinity();
        if (nodes_.empty())
            return t;
        const Vec3 e = o + dir * reach;
        // Room for the rounding of the plane-by-plane test, far above it.
        const double slack = 1e-9 * (scale_ + std::abs(o.x) + std::abs(o.y) + std::abs(o.z) + reach) + 1e-300;
        std::uint32_t stack[128];
        int top = 0;
        stack[top++] = 0;
        while (top > 0) {
            const Node& n = nodes_[stack[--top]];
            // Every normal of the node is within spread of its axis.
            if (dot(n.axis, dir) + n.spread < 0.5e-12)
                continue;
            const Vec3 r = e - n.centre;
            if (dot(n.axis, r) + n.spread * length(r) + n.beyond < -slack)
                continue;
            if (n.count == 0) {
                stack[top++] = n.first;
                stack[top++] = n.second;
                continue;
            }
            for (std::uint32_t k = n.first; k < n.first + n.count; ++k) {
                const Plane& plane = planes_[order_[k]];
                const double nd = dot(plane.normal, dir);
                if (!(nd > 1e-12))
                    continue;
                if (const double a = plane.offset - dot(plane.normal, o); a <= reach * nd)
                    t = std::min(t, a / nd);
            }
        }
        return t;
    }

private:
    struct Node {
        Vec3 centre;       // any point; beyond bounds the planes' signed distances from it
        Vec3 axis;         // mean normal
        double spread = 0; // max |normal − axis|
        double beyond = 0; // max signed distance of centre beyond a plane
        std::uint32_t first = 0, second = 0, count = 0; // as PolygonBvh's nodes
    };
    static constexpr std::uint32_t kLeafSize = 8;

    std::uint32_t build(std::uint32_t begin, std::uint32_t end) {
        const auto index = static_cast<std::uint32_t>(nodes_.size());
        nodes_.emplace_back();
        Aabb box;
        Vec3 centre, axis;
        for (std::uint32_t k = begin; k < end; ++k) {
            box.extend(centres_[order_[k]]);
            centre += centres_[order_[k]];
            axis += planes_[order_[k]].normal;
        }
        centre = centre / static_cast<double>(end - begin);
        axis = axis / static_cast<double>(end - begin);
        double spread = 0, beyond = -std::numeric_limits<double>::infinity();
        for (std::uint32_t k = begin; k < end; ++k) {
            const Plane& p = planes_[order_[k]];
            spread = std::max(spread, length(p.normal - axis));
            beyond = std::max(beyond, dot(p.normal, centre) - p.offset);
        }
        Node& n = nodes_[index];
        n.centre = centre;
        n.axis = axis;
        n.spread = spread * (1 + 1e-12) + 1e-15;
        n.beyond = beyond;
        if (end - begin <= kLeafSize) {
            n.first = begin;
            n.count = end - begin;
            return index;
        }
        const Vec3 extent = box.size();
        const int a = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
        const std::uint32_t mid = begin + (end - begin) / 2;
        std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
                         [&](std::uint32_t x, std::uint32_t y) {
                             const double cx = centres_[x][a], cy = centres_[y][a];
                             return cx < cy || (cx == cy && x < y);
                         });
        const std::uint32_t left = build(begin, mid);
        const std::uint32_t right = build(mid, end);
        nodes_[index].first = left;
        nodes_[index].second = right;
        return index;
    }

    const std::vector<Plane>& planes_;
    std::vector<Vec3> centres_;
    std::vector<std::uint32_t> order_;
    std::vector<Node> nodes_;
    double scale_ = 0;
};

} // namespace rubble::detail
