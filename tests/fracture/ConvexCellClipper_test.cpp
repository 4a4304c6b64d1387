#include <gtest/gtest.h>

#include <map>

#include "fracture/ConvexCellClipper.hpp"
#include "rubble/MassProperties.hpp"
#include "rubble/Random.hpp"

using namespace rubble;

namespace {

// Closed and consistently oriented: every directed edge appears once and its reverse once.
::testing::AssertionResult closedAndOriented(const Mesh& m) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
    for (const Triangle& t : m.triangles)
        for (int c = 0; c < 3; ++c)
            ++directed[{t[c], t[(c + 1) % 3]}];
    for (const auto& [e, count] : directed) {
        if (count != 1)
            return ::testing::AssertionFailure()
                   << "edge " << e.first << "-" << e.second << " used " << count;
        if (!directed.count({e.second, e.first}))
            return ::testing::AssertionFailure() << "open edge " << e.first << "-" << e.second;
    }
    return ::testing::AssertionSuccess();
}

// A random convex cell around c: a large box clipped by random planes through points near c (the box's own,
// axis-aligned faces are almost always cut away, so cells are in general position like Voronoi cells).
ConvexPolytope randomCell(Rng& rng, const Vec3& c, double size) {
    const Vec3 r{3 * size, 3 * size, 3 * size};
    ConvexPolytope p = ConvexPolytope::fromAabb({c - r, c + r});
    const int planes = 12 + static_cast<int>(rng.below(10));
    for (int i = 0; i < planes; ++i) {
        const Vec3 n = rng.unitVector();
        const Vec3 through = c + n * (size * rng.uniform(0.3, 0.9));
        ConvexPolytope q = p.clipped(Plane::fromPointNormal(through, n), i);
        if (!q.empty())
            p = q;
    }
    return p;
}

struct Stats {
    int runs = 0;
    int declined = 0;
};

void checkSplit(const Mesh& mesh, const ConvexPolytope& cell, Stats& stats) {
    ++stats.runs;
    auto r = detail::clipByConvexCell(mesh, cell);
    if (!r) {
        ++stats.declined;
        if (stats.declined <= 5)
            std::printf("declined: %s\n", r.error().message.c_str());
        EXPECT_EQ(r.error().code, ErrorCode::GeometryFailure);
        return;
    }
    const double v = signedVolume(mesh);
    const double vi = r->inside.empty() ? 0.0 : signedVolume(r->inside);
    const double vo = r->outside.empty() ? 0.0 : signedVolume(r->outside);
    EXPECT_NEAR(vi + vo, v, 1e-9 * v);
    EXPECT_TRUE(closedAndOriented(r->inside));
    EXPECT_TRUE(closedAndOriented(r->outside));
    EXPECT_TRUE(r->inside.validate().isOk());
    EXPECT_TRUE(r->outside.validate().isOk());
    // mesh ∩ cell cannot be larger than the cell.
    EXPECT_LE(vi, cell.volume() * (1 + 1e-9));
    EXPECT_EQ(r->inside.materials.size(), r->inside.triangles.size());
}

} // namespace

TEST(ConvexCellClipper, ConvexMeshMatchesPolytopeClipping) {
    // For a convex mesh, mesh ∩ cell is the mesh's polytope clipped by every cell plane: an exact reference.
    Rng rng(42);
    const ConvexPolytope cubePolytope = ConvexPolytope::fromAabb({{-1, -1, -1}, {1, 1, 1}});
    for (int n : {1, 7}) {
        const Mesh cube = makeSubdividedBox({-1, -1, -1}, {1, 1, 1}, n);
        for (int i = 0; i < 40; ++i) {
            const Vec3 c{rng.uniform(-1.2, 1.2), rng.uniform(-1.2, 1.2), rng.uniform() < 0.5 ? 1.0 : -1.0};
            const ConvexPolytope cell = randomCell(rng, c, rng.uniform(0.2, 0.8));
            ConvexPolytope expected = cubePolytope;
            for (const PolytopeFace& f : cell.faces())
                expected = expected.clipped(f.plane);
            auto r = detail::clipByConvexCell(cube, cell);
            ASSERT_TRUE(r) << r.error().message;
            const double vi = r->inside.empty() ? 0.0 : signedVolume(r->inside);
            EXPECT_NEAR(vi, expected.volume(), 1e-12);
            EXPECT_TRUE(closedAndOriented(r->inside));
            EXPECT_TRUE(closedAndOriented(r->outside));
            // Cut faces are interior material and lie on cell planes.
            for (std::size_t t = 0; t < r->inside.triangleCount(); ++t) {
                if (r->inside.materials[t] != kInteriorMaterial)
                    continue;
                const Vec3 centroid =
                    (r->inside.corners(t)[0] + r->inside.corners(t)[1] + r->inside.corners(t)[2]) / 3;
                EXPECT_TRUE(cell.contains(centroid, 1e-9));
            }
        }
    }
}

TEST(ConvexCellClipper, CellStrictlyInsideAFaceTriangle) {
    // A small cell poking into one big face of a 12-triangle cube: the cut polygon lies inside one triangle.
    const Mesh cube = makeBox({-1, -1, -1}, {1, 1, 1});
    Rng rng(5);
    Stats stats;
    for (int i = 0; i < 50; ++i)
        checkSplit(cube, randomCell(rng, {1.0, 0.31, -0.42}, 0.2), stats);
    EXPECT_LT(stats.declined, stats.runs / 10);
}

TEST(ConvexCellClipper, CellInsideMeshMakesACavity) {
    const Mesh cube = makeBox({-1, -1, -1}, {1, 1, 1});
    Rng rng(9);
    const ConvexPolytope cell = randomCell(rng, {0.1, 0.05, -0.02}, 0.3);
    auto r = detail::clipByConvexCell(cube, cell);
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_NEAR(signedVolume(r->inside), cell.volume(), 1e-12);
    EXPECT_NEAR(signedVolume(r->outside), 8 - cell.volume(), 1e-12);
}

TEST(ConvexCellClipper, CellOutsideMeshLeavesItWhole) {
    const Mesh cube = makeBox({-1, -1, -1}, {1, 1, 1});
    Rng rng(2);
    auto r = detail::clipByConvexCell(cube, randomCell(rng, {3, 0, 0}, 0.5));
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_TRUE(r->inside.empty());
    EXPECT_NEAR(signedVolume(r->outside), 8.0, 1e-12);
}

TEST(ConvexCellClipper, RandomCellsOnManyShapesKeepInvariants) {
    Rng rng(1234);
    const std::vector<Mesh> shapes = {
        makeSubdividedBox({-1, -1, -1}, {1, 1, 1}, 7), makeSubdividedBox({-1, -1, -1}, {1, 1, 1}, 29),
        makeSphere({0.1, 0, 0}, 1.0, 24, 12), makeTorus({0, 0, 0}, 1.0, 0.35, 32, 16),
        makeBox({-3, -0.05, -2}, {3, 0.05, 2})};
    Stats stats;
    for (const Mesh& shape : shapes) {
        const Aabb b = shape.bounds();
        for (int i = 0; i < 60; ++i) {
            // Centre near the surface: a random bounding-box point pushed to a random face.
            Vec3 c = rng.inBox(b.lo, b.hi);
            const int axis = static_cast<int>(rng.below(3));
            c[axis] = rng.uniform() < 0.5 ? b.lo[axis] : b.hi[axis];
            checkSplit(shape, randomCell(rng, c, 0.15 + 0.5 * rng.uniform()), stats);
        }
    }
    std::printf("fast clip: %d runs, %d declined (exact fallback)\n", stats.runs, stats.declined);
    EXPECT_LT(stats.declined, stats.runs / 10);
}

TEST(ConvexCellClipper, ChainedCutsStayValid) {
    Rng rng(77);
    Mesh m = makeSubdividedBox({-1, -1, -1}, {1, 1, 1}, 3);
    const double v0 = signedVolume(m);
    double removed = 0;
    int done = 0;
    for (int gen = 0; gen < 20; ++gen) {
        const Aabb b = m.bounds();
        Vec3 c = rng.inBox(b.lo, b.hi);
        c.x = b.hi.x;
        auto r = detail::clipByConvexCell(m, randomCell(rng, c, 0.4));
        if (!r) {
            std::printf("generation %d declined: %s\n", gen, r.error().message.c_str());
            continue;
        }
        ++done;
        removed += r->inside.empty() ? 0.0 : signedVolume(r->inside);
        m = r->outside;
        ASSERT_TRUE(closedAndOriented(m)) << "generation " << gen;
    }
    EXPECT_GT(done, 15);
    EXPECT_NEAR(signedVolume(m) + removed, v0, 1e-9 * v0);
}

TEST(ConvexCellClipper, FarFromOrigin) {
    const Vec3 far{1e5, -2e5, 3e5};
    const Mesh cube = makeSubdividedBox(far - Vec3{1, 1, 1}, far + Vec3{1, 1, 1}, 3);
    Rng rng(3);
    Stats stats;
    for (int i = 0; i < 30; ++i)
        checkSplit(cube, randomCell(rng, far + Vec3{1, rng.uniform(-0.8, 0.8), rng.uniform(-0.8, 0.8)}, 0.4),
                   stats);
    EXPECT_LT(stats.declined, stats.runs / 5);
}
