// withinGap (separating axes of two convex polytopes) and ConvexPolytope::transformed.
#include <gtest/gtest.h>

#include <cmath>

#include "rubble/core/Random.hpp"
#include "rubble/geometry/ConvexPolytope.hpp"

namespace rubble {
namespace {

ConvexPolytope box(const Vec3& lo, const Vec3& hi) {
    return ConvexPolytope::fromAabb(Aabb{lo, hi});
}

// A rotation of angle a about the unit axis u.
Mat3 rotation(const Vec3& u, double a) {
    const double c = std::cos(a), s = std::sin(a), t = 1 - c;
    Mat3 r;
    r.m[0][0] = t * u.x * u.x + c;
    r.m[0][1] = t * u.x * u.y - s * u.z;
    r.m[0][2] = t * u.x * u.z + s * u.y;
    r.m[1][0] = t * u.x * u.y + s * u.z;
    r.m[1][1] = t * u.y * u.y + c;
    r.m[1][2] = t * u.y * u.z - s * u.x;
    r.m[2][0] = t * u.x * u.z - s * u.y;
    r.m[2][1] = t * u.y * u.z + s * u.x;
    r.m[2][2] = t * u.z * u.z + c;
    return r;
}

TEST(ConvexContact, BoxesTouchFaceToFaceAndSeparateBeyondTheGap) {
    const ConvexPolytope a = box({0, 0, 0}, {1, 1, 1});
    EXPECT_TRUE(withinGap(a, box({1, 0, 0}, {2, 1, 1}), 0)) << "a shared face";
    EXPECT_TRUE(withinGap(a, box({0.5, 0.5, 0.5}, {3, 3, 3}), 0)) << "overlapping";
    EXPECT_TRUE(withinGap(a, box({1.01, 0, 0}, {2, 1, 1}), 0.02));
    EXPECT_FALSE(withinGap(a, box({1.03, 0, 0}, {2, 1, 1}), 0.02));
    EXPECT_FALSE(withinGap(a, ConvexPolytope{}, 1)) << "an empty polytope touches nothing";
}

// Two cubes turned 45° about perpendicular axes, one above the other: the upper one's lowest edge crosses the
// lower one's highest edge. Only an edge × edge axis separates them; every face normal still sees an overlap
// (and so do the bounding boxes, once the pair is turned away from the coordinate axes).
TEST(ConvexContact, SkewEdgesNeedTheEdgeCrossAxes) {
    const ConvexPolytope cube = box({-1, -1, -1}, {1, 1, 1});
    const double pi = 3.14159265358979;
    const Frame tilt{rotation(normalized(Vec3{1, 2, 3}), 0.7), {}};
    const ConvexPolytope lower = cube.transformed(tilt * Frame{rotation({0, 0, 1}, pi / 4), {}});
    auto upper = [&](double y) {
        return cube.transformed(tilt * Frame{rotation({1, 0, 0}, pi / 4), {0, y, 0}});
    };
    ASSERT_TRUE(lower.bounds().overlaps(upper(2.9).bounds()));
    // the edges are 2.9 − 2·√2 = 0.0716 apart
    EXPECT_FALSE(withinGap(lower, upper(2.9), 0.05));
    EXPECT_TRUE(withinGap(lower, upper(2.9), 0.08));
    EXPECT_TRUE(withinGap(lower, upper(2.8), 0)) << "the edges cross";
}

TEST(ConvexContact, TransformedKeepsVolumeAndMovesTheCentroid) {
    Rng rng(4);
    const ConvexPolytope p = box({-1, -0.5, -0.25}, {1, 0.5, 0.25});
    const Frame f{rng.rotation(), {3, -2, 7}};
    const ConvexPolytope q = p.transformed(f);
    EXPECT_NEAR(q.volume(), p.volume(), 1e-12);
    const Vec3 c = q.centroid();
    EXPECT_NEAR(c.x, 3, 1e-12);
    EXPECT_NEAR(c.y, -2, 1e-12);
    EXPECT_NEAR(c.z, 7, 1e-12);
    for (const PolytopeFaceView& face : q.faces())
        for (const Vec3& corner : face.corners)
            EXPECT_NEAR(dot(face.plane.normal, corner), face.plane.offset, 1e-12);
    const ConvexPolytope back = q.transformed(f.inverse());
    EXPECT_NEAR(back.bounds().lo.x, -1, 1e-12);
    EXPECT_NEAR(back.bounds().hi.z, 0.25, 1e-12);
}

} // namespace
} // namespace rubble
