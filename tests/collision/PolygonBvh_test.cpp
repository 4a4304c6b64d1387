// PolygonBvh::winding: the signed ray crossings that decompose() uses as its inside test.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>

#include "collision/PolygonBvh.hpp"
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

} // namespace
} // namespace rubble
