#include <gtest/gtest.h>

#include <map>

#include "TestSupport.hpp"
#include "fracture/CellComplex.hpp"
#include "fracture/ConvexCellClipper.hpp"
#include "rubble/core/Random.hpp"
#include "rubble/fracture/Fracture.hpp"
#include "rubble/geometry/MassProperties.hpp"

using namespace rubble;
using rubble::test::closedAndOriented;

namespace {

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
            for (const PolytopeFaceView& f : cell.faces())
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

namespace {

Vec3 randomSurfacePoint(const Mesh& m, Rng& rng) {
    const auto c = m.corners(static_cast<std::size_t>(rng.below(m.triangleCount())));
    double a = rng.uniform(), b = rng.uniform();
    if (a + b > 1) {
        a = 1 - a;
        b = 1 - b;
    }
    return c[0] + (c[1] - c[0]) * a + (c[2] - c[0]) * b;
}

using CornerKey = std::array<double, 9>;

// A triangle by its corner positions, rotated to start at its smallest corner (so the same triangle from
// another mesh, whatever its vertex ids, gets the same key); reversed for the twin with opposite orientation.
CornerKey cornerKey(const Mesh& m, std::size_t t, bool reversed) {
    auto c = m.corners(t);
    if (reversed)
        std::swap(c[1], c[2]);
    auto less = [](const Vec3& a, const Vec3& b) {
        return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z);
    };
    const std::size_t s = less(c[1], c[0]) ? (less(c[2], c[1]) ? 2 : 1) : (less(c[2], c[0]) ? 2 : 0);
    CornerKey k{};
    for (std::size_t i = 0; i < 3; ++i) {
        const Vec3& p = c[(s + i) % 3];
        k[3 * i] = p.x;
        k[3 * i + 1] = p.y;
        k[3 * i + 2] = p.z;
    }
    return k;
}

// Every interior (cut) face of every output has a twin, the same triangle reversed, in another output: the
// pieces of neighbouring cells and the remainder meet without gaps or overlaps, bit for bit.
::testing::AssertionResult interiorFacesPairUp(const std::vector<const Mesh*>& outputs) {
    std::map<CornerKey, std::vector<std::size_t>> owners;
    for (std::size_t o = 0; o < outputs.size(); ++o)
        for (std::size_t t = 0; t < outputs[o]->triangles.size(); ++t)
            if (outputs[o]->material(t) == kInteriorMaterial)
                owners[cornerKey(*outputs[o], t, false)].push_back(o);
    for (std::size_t o = 0; o < outputs.size(); ++o)
        for (std::size_t t = 0; t < outputs[o]->triangles.size(); ++t) {
            if (outputs[o]->material(t) != kInteriorMaterial)
                continue;
            auto twin = owners.find(cornerKey(*outputs[o], t, true));
            if (twin == owners.end() || twin->second.size() != 1 || twin->second.front() == o)
                return ::testing::AssertionFailure() << "interior triangle " << t << " of output " << o
                                                     << " has no single twin in another output";
        }
    return ::testing::AssertionSuccess();
}

} // namespace

// Shatter patterns (adjacent Voronoi cells sharing faces) are split in one pass: every output closed and
// oriented, volume conserved, each cell's piece the same as when that cell alone cuts the mesh, shared faces
// matching exactly, and the same input gives the same bytes.
TEST(ConvexCellClipper, ShatterCellsSplitInOnePass) {
    Rng rng(2024);
    const std::vector<Mesh> shapes = {
        makeSubdividedBox({-1, -1, -1}, {1, 1, 1}, 7), makeSphere({0.1, 0, 0}, 1.0, 24, 12),
        makeTorus({0, 0, 0}, 1.0, 0.35, 32, 16), makeBox({-3, -0.05, -2}, {3, 0.05, 2}),
        makeSubdividedBox({-1, -1, -1}, {1, 1, 1}, 29)};
    int runs = 0, declined = 0, cellsCut = 0;
    for (const Mesh& mesh : shapes) {
        const double v0 = signedVolume(mesh);
        for (int i = 0; i < 30; ++i) {
            FractureParams params;
            params.pattern = CellPattern::Shatter;
            params.cells = 2 + static_cast<int>(rng.below(9));
            params.sizeLaw.base = mesh.bounds().diagonal() * rng.uniform(0.15, 0.6);
            params.sizeLaw.scale = 0;
            const Impact impact{randomSurfacePoint(mesh, rng), {0, 1, 0}, 10};
            const std::vector<ConvexPolytope> cells =
                generateCells(mesh.bounds(), impact, params, rng.next());
            ASSERT_GE(cells.size(), 2u);
            ++runs;
            auto r = detail::clipByConvexCells(mesh, cells);
            if (!r) {
                ++declined;
                std::printf("declined: %s\n", r.error().message.c_str());
                EXPECT_EQ(r.error().code, ErrorCode::GeometryFailure);
                continue;
            }
            ASSERT_EQ(r->inside.size(), cells.size());
            std::vector<const Mesh*> outputs{&r->outside};
            double sum = r->outside.empty() ? 0.0 : signedVolume(r->outside);
            EXPECT_TRUE(closedAndOriented(r->outside));
            for (std::size_t k = 0; k < cells.size(); ++k) {
                const Mesh& piece = r->inside[k];
                outputs.push_back(&piece);
                const double vk = piece.empty() ? 0.0 : signedVolume(piece);
                sum += vk;
                EXPECT_TRUE(closedAndOriented(piece)) << "cell " << k;
                EXPECT_TRUE(piece.validate().isOk()) << "cell " << k;
                EXPECT_LE(vk, cells[k].volume() * (1 + 1e-9)) << "cell " << k;
                cellsCut += vk > 0;
                auto alone = detail::clipByConvexCell(mesh, cells[k]);
                if (alone) {
                    EXPECT_NEAR(vk, alone->inside.empty() ? 0.0 : signedVolume(alone->inside), 1e-9 * v0)
                        << "cell " << k;
                }
            }
            EXPECT_NEAR(sum, v0, 1e-9 * v0);
            EXPECT_TRUE(interiorFacesPairUp(outputs));
            if (i % 5 == 0) {
                auto again = detail::clipByConvexCells(mesh, cells);
                ASSERT_TRUE(again.isOk());
                EXPECT_EQ(again->outside.hash(), r->outside.hash());
                for (std::size_t k = 0; k < cells.size(); ++k)
                    EXPECT_EQ(again->inside[k].hash(), r->inside[k].hash());
            }
        }
    }
    std::printf("shatter clip: %d runs, %d declined, %d cell pieces\n", runs, declined, cellsCut);
    EXPECT_GT(cellsCut, 2 * runs);
    EXPECT_LE(declined, runs / 20);
}

// Two boxes sharing a face cut a sphere like the single box they make together; the shared face's caps are
// twins.
TEST(ConvexCellClipper, AdjacentBoxesMatchTheirUnion) {
    const Mesh sphere = makeSphere({0.013, 0.021, -0.017}, 0.7, 32, 16);
    const std::vector<ConvexPolytope> halves = {ConvexPolytope::fromAabb({{-0.5, -0.5, -0.5}, {0, 0.5, 0.5}}),
                                                ConvexPolytope::fromAabb({{0, -0.5, -0.5}, {0.5, 0.5, 0.5}})};
    auto both = detail::clipByConvexCells(sphere, halves);
    auto whole =
        detail::clipByConvexCell(sphere, ConvexPolytope::fromAabb({{-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5}}));
    ASSERT_TRUE(both.isOk()) << both.error().message;
    ASSERT_TRUE(whole.isOk()) << whole.error().message;
    const double v0 = signedVolume(sphere);
    EXPECT_NEAR(signedVolume(both->outside), signedVolume(whole->outside), 1e-9 * v0);
    EXPECT_NEAR(signedVolume(both->inside[0]) + signedVolume(both->inside[1]), signedVolume(whole->inside),
                1e-9 * v0);
    EXPECT_GT(signedVolume(both->inside[0]), 0.3 * signedVolume(whole->inside));
    EXPECT_GT(signedVolume(both->inside[1]), 0.3 * signedVolume(whole->inside));
    EXPECT_TRUE(closedAndOriented(both->outside));
    EXPECT_TRUE(closedAndOriented(both->inside[0]));
    EXPECT_TRUE(closedAndOriented(both->inside[1]));
    EXPECT_TRUE(interiorFacesPairUp({&both->outside, &both->inside[0], &both->inside[1]}));
}

// Cells that overlap, or touch with faces that are not the same face, are not a complex: declined (the
// fracture then uses an exact backend).
TEST(ConvexCellClipper, CellsThatAreNotAComplexAreDeclined) {
    const Mesh sphere = makeSphere({0.013, 0.021, -0.017}, 0.7, 32, 16);
    const ConvexPolytope a = ConvexPolytope::fromAabb({{-0.5, -0.5, -0.5}, {0.1, 0.5, 0.5}});
    const ConvexPolytope overlapping = ConvexPolytope::fromAabb({{0, -0.5, -0.5}, {0.5, 0.5, 0.5}});
    const ConvexPolytope offset = ConvexPolytope::fromAabb({{0.1, -0.2, -0.5}, {0.5, 0.8, 0.5}});
    for (const ConvexPolytope& b : {overlapping, offset}) {
        auto r = detail::clipByConvexCells(sphere, {a, b});
        ASSERT_FALSE(r.isOk());
        EXPECT_EQ(r.error().code, ErrorCode::GeometryFailure);
    }
    EXPECT_FALSE(detail::clipByConvexCells(sphere, {}).isOk());
}

// A cell plane through mesh vertices is declined by the triangle clip with its reason (returned, not thrown),
// and the next clip on the same thread starts clean.
TEST(ConvexCellClipper, ACellPlaneThroughMeshVerticesIsDeclinedAndTheNextClipWorks) {
    const Mesh box = makeBox({-1, -1, -1}, {1, 1, 1});
    const auto declined = detail::clipByConvexCell(box, ConvexPolytope::fromAabb({{1, -2, -2}, {3, 2, 2}}));
    ASSERT_FALSE(declined);
    EXPECT_EQ(declined.error().code, ErrorCode::GeometryFailure);
    EXPECT_EQ(declined.error().message, "fast clip declined: point on a cell plane");
    const auto cut = detail::clipByConvexCell(box, ConvexPolytope::fromAabb({{0.5, -2, -2}, {3, 2, 2}}));
    ASSERT_TRUE(cut) << cut.error().message;
    EXPECT_TRUE(closedAndOriented(cut->inside));
    EXPECT_TRUE(closedAndOriented(cut->outside));
    EXPECT_NEAR(signedVolume(cut->inside), 2.0, 1e-9);
    EXPECT_NEAR(signedVolume(cut->outside), 6.0, 1e-9);
}

// The complex stage alone: two boxes sharing a face weld into 12 vertices and 11 faces, the shared one stored
// once with each box on one side; overlapping boxes are declined with the reason, not thrown.
TEST(ConvexCellClipper, TheComplexStoresASharedFaceOnceAndDeclinesOverlapsAsAnError) {
    const ConvexPolytope a = ConvexPolytope::fromAabb({{0, 0, 0}, {1, 1, 1}});
    const ConvexPolytope b = ConvexPolytope::fromAabb({{1, 0, 0}, {2, 1, 1}});
    const Result<detail::CellComplex> cx = detail::buildCellComplex({a, b}, 1e-10);
    ASSERT_TRUE(cx) << cx.error().message;
    EXPECT_EQ(cx->vertices.size(), 12u);
    EXPECT_EQ(cx->faces.size(), 11u);
    ASSERT_EQ(cx->cells.size(), 2u);
    int shared = 0;
    for (const detail::CellComplex::Face& f : cx->faces)
        shared += f.back == 0 && f.front == 1 ? 1 : 0;
    EXPECT_EQ(shared, 1);
    EXPECT_EQ(cx->cells[0].faces.size(), 6u);
    EXPECT_EQ(cx->cells[1].faces.size(), 6u);

    const ConvexPolytope overlapping = ConvexPolytope::fromAabb({{0.5, 0, 0}, {1.5, 1, 1}});
    const Result<detail::CellComplex> refused = detail::buildCellComplex({a, overlapping}, 1e-10);
    ASSERT_FALSE(refused);
    EXPECT_EQ(refused.error().code, ErrorCode::GeometryFailure);
    EXPECT_EQ(refused.error().message, "fast clip declined: cells overlap");
}
