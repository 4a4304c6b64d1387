#include <gtest/gtest.h>

#include <cmath>

#include "BoxSolid.hpp"
#include "rubble/structure/BondGraph.hpp"

using namespace rubble;

namespace {

using test::boxSolid;
} // namespace

TEST(BondGraph, BoxOnBoxSharesTheOverlapRectangle) {
    // A 2 x 1 x 2 box on a 1 x 1 x 3 box, offset: overlap x in [0.5, 1], z in [0, 2].
    const auto lower = boxSolid({0, 0, 0}, {1, 1, 3});
    const auto upper = boxSolid({0.5, 1, -1}, {2.5, 2, 2});
    const BondInterface s = bondInterface(lower, upper, {});
    EXPECT_NEAR(s.area, 0.5 * 2, 1e-12);
    EXPECT_NEAR(s.sectionArea, s.area, 1e-12);
    EXPECT_NEAR(s.centroid.x, 0.75, 1e-12);
    EXPECT_NEAR(s.centroid.y, 1, 1e-12);
    EXPECT_NEAR(s.centroid.z, 1, 1e-12);
    EXPECT_NEAR(s.normal.y, 1, 1e-12);
    // Second moments of a 0.5 x 2 rectangle about its centroid: b h^3 / 12 about both in-plane axes.
    const double ix = 0.5 * 8.0 / 12, iz = 2 * 0.125 / 12;
    EXPECT_NEAR(s.iuu + s.ivv, ix + iz, 1e-12);
    EXPECT_NEAR(std::max(s.iuu, s.ivv), ix, 1e-12);
    EXPECT_NEAR(std::min(s.iuu, s.ivv), iz, 1e-12);
    EXPECT_NEAR(s.iuv, 0, 1e-12);
    // Reversed, the normal flips and the area stays.
    const BondInterface r = bondInterface(upper, lower, {});
    EXPECT_NEAR(r.area, 1, 1e-12);
    EXPECT_NEAR(r.normal.y, -1, 1e-12);
}

TEST(BondGraph, GapAndAngleDecideTouching) {
    const auto lower = boxSolid({0, 0, 0}, {1, 1, 1});
    EXPECT_NEAR(bondInterface(lower, boxSolid({0, 1.0005, 0}, {1, 2, 1}), {}).area, 1, 1e-12);
    EXPECT_EQ(bondInterface(lower, boxSolid({0, 1.01, 0}, {1, 2, 1}), {}).area, 0);
    // Edge-to-edge: boxes meeting only along a line share no area.
    EXPECT_EQ(bondInterface(lower, boxSolid({1, 1, 0}, {2, 2, 1}), {}).area, 0);
    // A box tilted 5 degrees about z resting on a corner: not coplanar.
    const double a = 5 * 3.14159265358979 / 180;
    Frame f;
    f.rotation = Mat3{{{std::cos(a), -std::sin(a), 0}, {std::sin(a), std::cos(a), 0}, {0, 0, 1}}};
    f.translation = {0.5, 1.5, 0.5};
    const auto tilted =
        std::vector<ConvexPolytope>{boxSolid({-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5})[0].transformed(f)};
    EXPECT_EQ(bondInterface(lower, tilted, {}).area, 0);
}

TEST(BondGraph, SlabOnColumnsAndAWallMakesOneBondPerContact) {
    // Ground, two columns, a slab spanning them, and a box floating apart.
    const std::vector<std::vector<ConvexPolytope>> solids = {
        boxSolid({-5, -1, -5}, {5, 0, 5}),       // 0 ground
        boxSolid({-2, 0, -0.2}, {-1.6, 3, 0.2}), // 1 column
        boxSolid({1.6, 0, -0.2}, {2, 3, 0.2}),   // 2 column
        boxSolid({-2.5, 3, -1}, {2.5, 3.3, 1}),  // 3 slab
        boxSolid({10, 0, 10}, {11, 1, 11}),      // 4 apart
    };
    const std::vector<Bond> bonds = buildBonds(solids, {});
    ASSERT_EQ(bonds.size(), 4u);
    EXPECT_EQ(bonds[0].a, 0u);
    EXPECT_EQ(bonds[0].b, 1u);
    EXPECT_EQ(bonds[1].a, 0u);
    EXPECT_EQ(bonds[1].b, 2u);
    EXPECT_EQ(bonds[2].a, 1u);
    EXPECT_EQ(bonds[2].b, 3u);
    EXPECT_EQ(bonds[3].a, 2u);
    EXPECT_EQ(bonds[3].b, 3u);
    for (const Bond& b : bonds)
        EXPECT_NEAR(b.section.area, 0.4 * 0.4, 1e-12);
    EXPECT_NEAR(bonds[2].section.centroid.y, 3, 1e-12);
    EXPECT_NEAR(bonds[2].section.normal.y, 1, 1e-12);
}

TEST(BondGraph, MultiPartSolidsSumTheirPatches) {
    // An L-shaped solid of two parts standing on a plate: both feet touch.
    auto l = boxSolid({0, 0, 0}, {1, 2, 1});
    l.push_back(boxSolid({1, 0, 0}, {3, 1, 1})[0]);
    const auto plate = boxSolid({-1, -0.5, -1}, {4, 0, 2});
    const BondInterface s = bondInterface(plate, l, {});
    EXPECT_NEAR(s.area, 3, 1e-12);
    EXPECT_NEAR(s.centroid.x, 1.5, 1e-12);
    EXPECT_NEAR(s.centroid.z, 0.5, 1e-12);
    EXPECT_EQ(s.corners.size(), 8u);
}

TEST(BondGraph, AnInterfaceAroundACornerCountsEveryPatch) {
    // A unit cube nested in the corner of an L of three boxes: three faces touch, the section is their
    // projection on the mean normal (1, 1, 1) / sqrt 3.
    const auto cube = boxSolid({0, 0, 0}, {1, 1, 1});
    auto corner = boxSolid({-1, -1, -1}, {0, 1, 1});
    corner.push_back(boxSolid({0, -1, -1}, {1, 0, 1})[0]);
    corner.push_back(boxSolid({0, 0, -1}, {1, 1, 0})[0]);
    const BondInterface s = bondInterface(corner, cube, {});
    EXPECT_NEAR(s.area, 3, 1e-12);
    EXPECT_NEAR(s.normal.x, 1 / std::sqrt(3.0), 1e-12);
    EXPECT_NEAR(s.normal.y, 1 / std::sqrt(3.0), 1e-12);
    EXPECT_NEAR(s.sectionArea, 3 / std::sqrt(3.0), 1e-12);
}
