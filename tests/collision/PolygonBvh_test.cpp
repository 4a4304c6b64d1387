// PolygonBvh::winding: the signed ray crossings that decompose() uses as its inside test; HullPlaneTree: the
// hull planes its pocket rays leave through.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <optional>

#include "collision/HullPlaneTree.hpp"
#include "collision/PolygonBvh.hpp"
#include "rubble/collision/ConvexDecomposition.hpp"
#include "rubble/core/Random.hpp"

namespace rubble {
namespace {

const Vec3 kRay = normalized(Vec3{0.3141592653589793, 0.5772156649015329, 0.7071067811865476});

/// Over random points in and around mesh: the crossings equal the winding number's sum, rounded, wherever
/// they answer; they answer for most points.
void expectSameAsWindingNumber(const Mesh& mesh, std::uint64_t seed) {
    const detail::PolygonBvh tree(mesh);
    Aabb box = mesh.bounds();
    const Vec3 pad = box.size() * 0.2;
    box.lo -= pad;
    box.hi += pad;
    Rng rng(seed);
    int answered = 0, inside = 0;
    for (int i = 0; i < 400; ++i) {
        const Vec3 p = rng.inBox(box.lo, box.hi);
        const std::optional<int> w = tree.winding(p, kRay, 1e-9 * box.diagonal());
        if (!w)
            continue;
        ++answered;
        inside += *w > 0;
        EXPECT_EQ(*w, static_cast<int>(std::lround(windingNumber(mesh, p))))
            << p.x << " " << p.y << " " << p.z;
    }
    EXPECT_GT(answered, 390);
    EXPECT_GT(inside, 20);
}

TEST(PolygonBvh, WindingCrossingsMatchTheWindingNumber) {
    expectSameAsWindingNumber(makeTorus({0, 0, 0}, 2, 0.5, 32, 12), 1);
    expectSameAsWindingNumber(makeSubdividedBox({-1, -1, -1}, {1, 2, 3}, 4), 2);
    expectSameAsWindingNumber(makeSphere({0.5, 0, 0}, 1, 24, 12), 3);
}

TEST(PolygonBvh, WindingDeclinesOnTheSurfaceAndThroughEdges) {
    const Mesh box = makeBox({0, 0, 0}, {1, 1, 1});
    const detail::PolygonBvh tree(box);
    // A point on a face, on an edge and at a corner: the ray starts on the surface.
    for (const Vec3& p : {Vec3{0.5, 0.5, 0}, Vec3{0.5, 0, 0}, Vec3{0, 0, 0}})
        EXPECT_FALSE(tree.winding(p, kRay, 1e-9)) << p.x << " " << p.y << " " << p.z;
    // A ray from inside through the box's corner (1, 1, 1) leaves through an edge of both triangles there.
    EXPECT_FALSE(tree.winding({0.5, 0.5, 0.5}, normalized(Vec3{1, 1, 1}), 1e-9));
    // Inside and outside, clear of every edge.
    EXPECT_EQ(tree.winding({0.3, 0.4, 0.2}, kRay, 1e-9), 1);
    EXPECT_EQ(tree.winding({-0.3, 0.4, 0.2}, kRay, 1e-9), 0);
    // A box turned inside out winds -1.
    Mesh flipped = box;
    for (Triangle& t : flipped.triangles)
        std::swap(t[1], t[2]);
    EXPECT_EQ(detail::PolygonBvh(flipped).winding({0.3, 0.4, 0.2}, kRay, 1e-9), -1);
}

// The plane-by-plane scan that HullPlaneTree::exitBefore replaces.
double scanExit(const std::vector<Plane>& planes, const Vec3& o, const Vec3& dir, double reach) {
    double t = std::numeric_limits<double>::infinity();
    for (const Plane& plane : planes)
        if (const double nd = dot(plane.normal, dir); nd > 1e-12)
            if (const double a = plane.offset - dot(plane.normal, o); a <= reach * nd)
                t = std::min(t, a / nd);
    return t;
}

TEST(HullPlaneTree, FindsTheSameExitAsAScanOfEveryPlane) {
    // A lumpy hull of many faces, far from the origin; rays from just inside its faces (as pocket rays
    // start), from deep inside and from outside, with reaches from zero to past the far side.
    Rng rng(7);
    std::vector<Vec3> points;
    const Vec3 centre{40, -25, 10};
    for (int i = 0; i < 3000; ++i) {
        const Vec3 u = rng.unitVector();
        points.push_back(centre + Vec3{3 * u.x, 1.5 * u.y, u.z} * (1 + 0.05 * std::sin(7 * u.x + 5 * u.y)));
    }
    const ConvexPolytope hull = convexHull(points).value();
    ASSERT_GT(hull.faces().size(), 1000u);
    std::vector<Plane> planes;
    for (const PolytopeFaceView& f : hull.faces())
        planes.push_back(f.plane);
    const detail::HullPlaneTree tree(hull.faces(), planes);
    int exits = 0, none = 0;
    for (int i = 0; i < 4000; ++i) {
        const PolytopeFaceView& f = hull.faces()[rng.below(hull.faces().size())];
        Vec3 o;
        Vec3 dir = -f.plane.normal;
        switch (i % 3) {
        case 0: // just inside a face, inward
            for (const Vec3& c : f.corners)
                o += c;
            o = o / static_cast<double>(f.corners.size()) - f.plane.normal * 1e-9;
            break;
        case 1: // anywhere in the hull's box, any direction
            o = rng.inBox(hull.bounds().lo, hull.bounds().hi);
            dir = rng.unitVector();
            break;
        default: // outside, towards the hull
            o = centre + rng.unitVector() * 5;
            dir = normalized(centre - o + rng.unitVector());
        }
        const double reach = rng.uniform(0.0, 7.0) * (i % 7 == 0 ? 1e-6 : 1.0);
        const double expected = scanExit(planes, o, dir, reach);
        EXPECT_EQ(tree.exitBefore(o, dir, reach), expected) << i;
        (std::isfinite(expected) ? exits : none)++;
    }
    EXPECT_GT(exits, 500);
    EXPECT_GT(none, 500);
}

} // namespace
} // namespace rubble
