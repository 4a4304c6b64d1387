// The hull of a few points without Qhull: the same solid as Qhull's, closed and convex, its corners input
// points, coplanar triangles one face; flat input left to Qhull's error.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "collision/SmallHull.hpp"
#include "geometry/PointBits.hpp"
#include "rubble/collision/ConvexDecomposition.hpp"

using namespace rubble;

namespace {

/// Qhull's hull of the points: repeated past kSmallHullPoints, which smallHull does not take.
ConvexPolytope qhullOf(const std::vector<Vec3>& points) {
    std::vector<Vec3> many;
    while (many.size() <= detail::kSmallHullPoints)
        many.insert(many.end(), points.begin(), points.end());
    return convexHull(many).value();
}

/// Corners of two boxes, each clipped by a few random planes: what a merge of two parts asks for.
std::vector<Vec3> twoClippedBoxes(std::mt19937_64& rng, double scale, const Vec3& at) {
    std::uniform_real_distribution<double> u(-1, 1);
    std::vector<Vec3> points;
    for (int part = 0; part < 2; ++part) {
        const Vec3 c{u(rng), u(rng), u(rng)};
        ConvexPolytope p = ConvexPolytope::fromAabb({c - Vec3{0.5, 0.5, 0.5}, c + Vec3{0.5, 0.5, 0.5}});
        const int cuts = static_cast<int>(rng() % 6);
        for (int k = 0; k < cuts; ++k) {
            const Vec3 n = normalized(Vec3{u(rng), u(rng), u(rng)});
            if (ConvexPolytope q = p.clipped(Plane{n, dot(n, c) + 0.3 * u(rng)}); !q.empty())
                p = std::move(q);
        }
        for (const Vec3& v : p.vertices())
            points.push_back(v * scale + at);
    }
    return points;
}

void expectHullOf(const ConvexPolytope& hull, const std::vector<Vec3>& points, const std::string& what) {
    ASSERT_GE(hull.faces().size(), 4u) << what;
    Aabb box;
    for (const Vec3& p : points)
        box.extend(p);
    const double tol = 1e-10 * (box.diagonal() + length(box.hi) + length(box.lo));
    for (const PolytopeFaceView& f : hull.faces()) {
        ASSERT_GE(f.corners.size(), 3u) << what;
        for (const Vec3& p : points)
            EXPECT_LE(f.plane.signedDistance(p), tol) << what;
    }
    for (const Vec3& c : hull.corners())
        EXPECT_TRUE(std::any_of(points.begin(), points.end(),
                                [&](const Vec3& p) { return detail::pointBits(p) == detail::pointBits(c); }))
            << what << ": a corner that is no input point";
    const double q = qhullOf(points).volume();
    EXPECT_NEAR(hull.volume(), q, 1e-9 * q) << what;
}

} // namespace

TEST(SmallHull, MatchesQhullOnRandomAndClippedSets) {
    std::mt19937_64 rng(20261129);
    std::uniform_real_distribution<double> u(-1, 1);
    int declined = 0, sets = 0;
    for (int i = 0; i < 300; ++i) {
        std::vector<Vec3> points;
        if (i % 3 == 0) {
            const int n = 4 + static_cast<int>(rng() % 80);
            for (int k = 0; k < n; ++k)
                points.push_back({u(rng), u(rng), u(rng)});
        } else {
            points = i % 3 == 1 ? twoClippedBoxes(rng, 1, {}) : twoClippedBoxes(rng, 0.01, {150, -40, 75});
        }
        if (points.size() > detail::kSmallHullPoints)
            continue;
        ++sets;
        const std::optional<ConvexPolytope> hull = detail::smallHull(points);
        if (!hull) {
            ++declined;
            continue;
        }
        expectHullOf(*hull, points, "set " + std::to_string(i));
    }
    EXPECT_GE(sets, 250);
    EXPECT_EQ(declined, 0);
}

TEST(SmallHull, CoplanarTrianglesAreOneFaceAndCornersInsideAnEdgeGo) {
    std::vector<Vec3> lattice;
    for (int x = 0; x < 3; ++x)
        for (int y = 0; y < 3; ++y)
            for (int z = 0; z < 3; ++z)
                lattice.push_back({x * 0.5, y * 0.25, z * 0.125});
    std::shuffle(lattice.begin(), lattice.end(), std::mt19937_64(3));
    const std::optional<ConvexPolytope> box = detail::smallHull(lattice);
    ASSERT_TRUE(box);
    EXPECT_EQ(box->faces().size(), 6u);
    EXPECT_EQ(box->corners().size(), 8u);
    for (const PolytopeFaceView& f : box->faces())
        EXPECT_EQ(f.corners.size(), 4u);
    expectHullOf(*box, lattice, "lattice");
}

TEST(SmallHull, FlatInputIsLeftToQhullsError) {
    std::vector<Vec3> flat;
    for (int k = 0; k < 12; ++k)
        flat.push_back({std::cos(k * 0.5), std::sin(k * 0.5), 2.0});
    EXPECT_FALSE(detail::smallHull(flat));
    const Result<ConvexPolytope> hull = detail::hullOfFew(flat);
    ASSERT_FALSE(hull);
    EXPECT_EQ(hull.error().code, ErrorCode::InvalidInput);
    EXPECT_NE(hull.error().message.find("coplanar"), std::string::npos) << hull.error().message;
}
