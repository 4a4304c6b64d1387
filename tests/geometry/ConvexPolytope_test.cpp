#include <gtest/gtest.h>

#include <cmath>

#include "TestSupport.hpp"
#include "rubble/core/Random.hpp"
#include "rubble/geometry/ConvexPolytope.hpp"
#include "rubble/geometry/MassProperties.hpp"
#include "rubble/geometry/MeshCheck.hpp"

using namespace rubble;

namespace {
// A random plane through a point inside the box lo..hi.
Plane randomPlane(Rng& rng, const Vec3& lo, const Vec3& hi) {
    return Plane::fromPointNormal(rng.inBox(lo, hi), rng.unitVector());
}
} // namespace

TEST(ConvexPolytope, BoxHasExactVolumeCentroidAndMesh) {
    const auto p = ConvexPolytope::fromAabb({{-1, 0, 2}, {3, 1, 5}});
    EXPECT_FALSE(p.empty());
    EXPECT_NEAR(p.volume(), 4 * 1 * 3, 1e-12);
    const Vec3 c = p.centroid();
    EXPECT_NEAR(c.x, 1, 1e-12);
    EXPECT_NEAR(c.y, 0.5, 1e-12);
    EXPECT_NEAR(c.z, 3.5, 1e-12);
    EXPECT_EQ(p.vertices().size(), 8u);
    EXPECT_TRUE(p.contains({0, 0.5, 3}));
    EXPECT_FALSE(p.contains({0, 1.5, 3}));
    const Mesh m = p.toMesh();
    const MeshReport r = checkMesh(m);
    EXPECT_TRUE(r.valid()) << test::joinLines(r.problems);
    EXPECT_NEAR(r.volume, 12, 1e-12);
}

TEST(ConvexPolytope, ClippingByRandomPlanesConservesVolume) {
    Rng rng(2024);
    const Vec3 lo{-1, -2, -0.5}, hi{2, 1, 1.5};
    const auto box = ConvexPolytope::fromAabb({lo, hi});
    const double whole = box.volume();
    for (int i = 0; i < 300; ++i) {
        const Plane plane = randomPlane(rng, lo, hi);
        const ConvexPolytope in = box.clipped(plane, 7);
        const ConvexPolytope out = box.clippedOutside(plane, 8);
        EXPECT_NEAR(in.volume() + out.volume(), whole, 1e-9 * whole) << "plane " << i;
        for (const ConvexPolytope* part : {&in, &out}) {
            if (part->empty())
                continue;
            const Mesh m = part->toMesh();
            const MeshReport r = checkMesh(m);
            EXPECT_TRUE(r.closed) << "plane " << i << "\n" << test::joinLines(r.problems);
            EXPECT_TRUE(r.oriented) << "plane " << i << "\n" << test::joinLines(r.problems);
            EXPECT_TRUE(r.outward) << "plane " << i;
            EXPECT_NEAR(r.volume, part->volume(), 1e-9 * whole) << "plane " << i;
        }
        // The cap face carries the tag of the plane that made it.
        bool tagged = false;
        for (const auto& f : in.faces())
            tagged = tagged || f.tag == 7;
        EXPECT_TRUE(in.empty() || tagged);
    }
}

TEST(ConvexPolytope, RepeatedClippingMakesClosedCellsThatTileTheBox) {
    // Split a box by several random planes into all sign combinations; the cells tile the box.
    Rng rng(99);
    const Vec3 lo{0, 0, 0}, hi{1, 1, 1};
    std::vector<ConvexPolytope> cells{ConvexPolytope::fromAabb({lo, hi})};
    for (int k = 0; k < 5; ++k) {
        const Plane plane = randomPlane(rng, lo, hi);
        std::vector<ConvexPolytope> next;
        for (const auto& c : cells) {
            for (const ConvexPolytope& part : {c.clipped(plane, k), c.clippedOutside(plane, k)})
                if (!part.empty())
                    next.push_back(part);
        }
        cells = std::move(next);
    }
    double total = 0;
    for (const auto& c : cells) {
        total += c.volume();
        const MeshReport r = checkMesh(c.toMesh());
        EXPECT_TRUE(r.closed && r.oriented && r.outward) << test::joinLines(r.problems);
        EXPECT_EQ(r.nonManifoldEdges, 0u);
    }
    EXPECT_GT(cells.size(), 5u);
    EXPECT_NEAR(total, 1.0, 1e-9);
}

TEST(ConvexPolytope, PlanesMissingTheBoxKeepOrEmptyIt) {
    const auto box = ConvexPolytope::fromAabb({{0, 0, 0}, {1, 1, 1}});
    const Plane far = Plane::fromPointNormal({5, 0, 0}, {1, 0, 0}); // box entirely on the inner side
    EXPECT_NEAR(box.clipped(far).volume(), 1.0, 1e-12);
    EXPECT_TRUE(box.clippedOutside(far).empty());
    const Plane face = Plane::fromPointNormal({1, 0, 0}, {1, 0, 0}); // coincides with a face
    EXPECT_NEAR(box.clipped(face).volume(), 1.0, 1e-12);
    EXPECT_TRUE(box.clippedOutside(face).empty());
}

TEST(ConvexPolytope, MassPropertiesOfClippedMeshMatchThePolytope) {
    Rng rng(5);
    const auto box = ConvexPolytope::fromAabb({{-2, -2, -2}, {2, 2, 2}});
    for (int i = 0; i < 50; ++i) {
        const ConvexPolytope part = box.clipped(randomPlane(rng, {-1, -1, -1}, {1, 1, 1}));
        if (part.empty())
            continue;
        const MassProperties mp = computeMassProperties(part.toMesh());
        const Vec3 c = part.centroid();
        EXPECT_NEAR(mp.volume, part.volume(), 1e-9);
        EXPECT_NEAR(mp.centerOfMass.x, c.x, 1e-9);
        EXPECT_NEAR(mp.centerOfMass.y, c.y, 1e-9);
        EXPECT_NEAR(mp.centerOfMass.z, c.z, 1e-9);
    }
}
