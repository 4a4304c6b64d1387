// Property tests of the fracture kernel: volume conservation, closed and oriented pieces, determinism and
// chained fractures over many seeded random impacts, plus degenerate hits and backend cross-checks.

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <map>

#include "PieceHash.hpp"
#include "TestSupport.hpp"
#include "fracture/BooleanBackend.hpp"
#include "fracture/ConvexCellClipper.hpp"
#include "rubble/core/Random.hpp"
#include "rubble/fracture/Fracture.hpp"
#include "rubble/geometry/MassProperties.hpp"
#include "rubble/geometry/MeshCheck.hpp"
#include "rubble/io/MeshIO.hpp"

using namespace rubble;
using rubble::test::closedAndOriented;
using rubble::test::surfacePoint;

namespace {

Mesh lPrism() {
    // An L-shaped (concave) prism: the L in the xy-plane, extruded along z.
    const Vec3 p[6] = {{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {1, 1, 0}, {1, 2, 0}, {0, 2, 0}};
    Mesh m;
    for (const Vec3& q : p)
        m.positions.push_back(q);
    for (const Vec3& q : p)
        m.positions.push_back(q + Vec3{0, 0, 1});
    // Bottom (facing -z) and top (facing +z): the L as 4 triangles.
    const std::uint32_t tris[4][3] = {{0, 1, 2}, {0, 2, 3}, {0, 3, 5}, {3, 4, 5}};
    for (const auto& t : tris) {
        m.triangles.push_back({t[0], t[2], t[1]});
        m.triangles.push_back({t[0] + 6, t[1] + 6, t[2] + 6});
    }
    for (std::uint32_t i = 0; i < 6; ++i) {
        const std::uint32_t j = (i + 1) % 6;
        m.triangles.push_back({i, j, j + 6});
        m.triangles.push_back({i, j + 6, i + 6});
    }
    return m;
}

Mesh twoBoxes() {
    Mesh m = makeSubdividedBox({-1, -1, -1}, {0, 1, 1}, 2);
    m.append(makeSubdividedBox({0.25, -1, -1}, {1.25, 1, 1}, 2));
    return m;
}

struct Shape {
    std::string name;
    Mesh mesh;
};

std::vector<Shape> shapes() {
    return {{"box", makeSubdividedBox({-1, -1, -1}, {1, 1, 1}, 2)},
            {"sphere", makeSphere({0, 0, 0}, 1, 16, 8)},
            {"torus", makeTorus({0, 0, 0}, 1, 0.35, 16, 8)},
            {"lprism", lPrism()},
            {"plate", makeSubdividedBox({-1, -0.02, -1}, {1, 0.02, 1}, 1)},
            {"twoboxes", twoBoxes()}};
}

FractureParams paramsFor(const Mesh& m, Rng& rng) {
    FractureParams p;
    const double d = m.bounds().diagonal();
    p.sizeLaw.base = d * rng.uniform(0.15, 0.6);
    p.sizeLaw.scale = 0;
    p.seedPoints = 8 + static_cast<int>(rng.below(12));
    if (rng.below(4) == 0) {
        p.pattern = CellPattern::Shatter;
        p.cells = 2 + static_cast<int>(rng.below(5));
    }
    return p;
}

// The invariants every successful fracture keeps.
void checkResult(const Mesh& input, const FractureResult& r, const std::string& what) {
    const double v0 = signedVolume(input);
    double sum = r.droppedVolume;
    for (const Piece& p : r.pieces) {
        sum += p.mass.volume;
        EXPECT_GT(p.mass.volume, 0) << what;
        EXPECT_TRUE(closedAndOriented(p.mesh)) << what;
        EXPECT_TRUE(p.mesh.validate().isOk()) << what;
        EXPECT_EQ(p.mesh.materials.size(), p.mesh.triangles.size()) << what;
        EXPECT_EQ(p.mesh.uvs.size(), 3 * p.mesh.triangles.size()) << what;
        EXPECT_NEAR(signedVolume(p.mesh), p.mass.volume, 1e-12 * v0) << what;
    }
    EXPECT_NEAR(sum, v0, 1e-6 * v0) << what;
    EXPECT_NEAR(r.inputVolume, v0, 1e-12 * v0) << what;
    EXPECT_GE(r.stats.timings.totalMs, r.stats.timings.booleanMs) << what;
}

/// Fallbacks to the exact backend, by cell pattern.
struct Fallbacks {
    int single = 0, singleImpacts = 0;   ///< CellPattern::SingleCell
    int shatter = 0, shatterImpacts = 0; ///< CellPattern::Shatter
};

int runImpacts(const Mesh& mesh, const std::string& name, int count, BooleanKind backend, std::uint64_t seed,
               Fallbacks* fallbacks = nullptr) {
    Rng rng(seed);
    int ok = 0;
    for (int i = 0; i < count; ++i) {
        Impact impact;
        impact.point = surfacePoint(mesh, rng);
        impact.impulse = rng.uniform(0, 100);
        FractureParams params = paramsFor(mesh, rng);
        params.backend = backend;
        const std::uint64_t s = rng.next();
        auto r = fracture(mesh, impact, params, s);
        const std::string what = name + " impact " + std::to_string(i);
        if (!r) {
            // A cell built around a surface point can only miss a mesh when the surface there is thinner than
            // rounding; anything else is a failure.
            ADD_FAILURE() << what << ": " << r.error().message;
            continue;
        }
        ++ok;
        if (fallbacks) {
            const bool shatter = params.pattern == CellPattern::Shatter;
            (shatter ? fallbacks->shatterImpacts : fallbacks->singleImpacts)++;
            if (r->stats.exactFallback)
                (shatter ? fallbacks->shatter : fallbacks->single)++;
        }
        checkResult(mesh, *r, what);
        // Same seed, same pieces, bit for bit (also for multi-cell patterns).
        if (i % 5 == 0) {
            auto again = fracture(mesh, impact, params, s);
            EXPECT_TRUE(again.isOk());
            if (again) {
                EXPECT_EQ(test::hashPieces(*r), test::hashPieces(*again)) << what << ": not deterministic";
            }
        }
    }
    return ok;
}

} // namespace

// The property tests run for both production backends: Corefine (exact) and Fast (the clipper, with its
// exact fallback).
class FractureBackend : public ::testing::TestWithParam<BooleanKind> {};

std::string backendName(const ::testing::TestParamInfo<BooleanKind>& info) {
    return info.param == BooleanKind::Fast ? "Fast" : info.param == BooleanKind::Nef ? "Nef" : "Corefine";
}

TEST(Fracture, FastIsTheDefaultBackend) {
    EXPECT_EQ(FractureParams{}.backend, BooleanKind::Fast);
}

TEST_P(FractureBackend, RandomImpactsOnGeneratedShapes) {
    int total = 0;
    Fallbacks fb;
    for (const Shape& s : shapes())
        total += runImpacts(s.mesh, s.name, 120, GetParam(), 1000 + s.name.size(), &fb);
    EXPECT_EQ(total, 720);
    std::printf("%s: exact fallback on %d of %d single-cell and %d of %d shatter impacts\n",
                backendName({GetParam(), 0}).c_str(), fb.single, fb.singleImpacts, fb.shatter,
                fb.shatterImpacts);
    EXPECT_GT(fb.singleImpacts, 400);
    EXPECT_GT(fb.shatterImpacts, 100);
    if (GetParam() == BooleanKind::Fast) {
        // The clipper is the fast path for the thesis's single cell and for shatter patterns (adjacent cells
        // are cut in one pass as a complex): it must rarely decline for either (measured: 0 of 531 and 0 of
        // 189).
        EXPECT_LE(fb.single, fb.singleImpacts / 50) << "the clipper declines too often to be the fast path";
        EXPECT_LE(fb.shatter, fb.shatterImpacts / 20) << "the clipper declines too often on shatter patterns";
    } else {
        EXPECT_EQ(fb.single + fb.shatter, 0);
    }
}

TEST_P(FractureBackend, RandomImpactsOnSeedMedia) {
    RUBBLE_REQUIRE_SEED_MEDIA(media);
    int used = 0;
    for (const auto& entry : std::filesystem::directory_iterator(media)) {
        if (entry.path().extension() != ".obj")
            continue;
        auto m = readObj(entry.path());
        if (!m || m->empty()) {
            std::printf("skip %s: %s\n", entry.path().filename().c_str(),
                        m ? "empty" : m.error().message.c_str());
            continue;
        }
        Mesh mesh = *m;
        FractureParams probe;
        auto check = fractureWithCells(mesh, {}, probe);
        if (!check && check.error().code == ErrorCode::InvalidInput) {
            std::printf("skip %s: %s\n", entry.path().filename().c_str(), check.error().message.c_str());
            continue;
        }
        const int n = mesh.triangleCount() > 3000 ? 5 : 25;
        EXPECT_EQ(runImpacts(mesh, entry.path().filename().string(), n, GetParam(), 5), n);
        ++used;
    }
    std::printf("seed models fractured: %d\n", used);
    EXPECT_GT(used, 0);
}

TEST_P(FractureBackend, ChainedFractureTwentyGenerations) {
    const BooleanKind backend = GetParam();
    {
        for (std::uint64_t seed : {1u, 2u, 3u}) {
            Rng rng(seed);
            Mesh current = seed == 2 ? makeTorus({0, 0, 0}, 1, 0.35, 16, 8)
                                     : makeSubdividedBox({-1, -1, -1}, {1, 1, 1}, 3);
            for (int g = 0; g < 20; ++g) {
                Impact impact{surfacePoint(current, rng), {0, 1, 0}, 10};
                FractureParams params;
                params.backend = backend;
                params.sizeLaw.base = current.bounds().diagonal() * 0.4;
                params.sizeLaw.scale = 0;
                auto r = fracture(current, impact, params, rng.next());
                const std::string what = "seed " + std::to_string(seed) + " generation " + std::to_string(g);
                ASSERT_TRUE(r.isOk()) << what << ": " << r.error().message;
                checkResult(current, *r, what);
                ASSERT_FALSE(r->pieces.empty());
                // Continue with the largest piece.
                std::size_t best = 0;
                for (std::size_t i = 1; i < r->pieces.size(); ++i)
                    if (r->pieces[i].mass.volume > r->pieces[best].mass.volume)
                        best = i;
                current = r->pieces[best].mesh;
            }
        }
    }
}

TEST(Fracture, NefFastAndCorefineAgreeOnTheSameCells) {
    Rng rng(9);
    const std::vector<Shape> all = shapes();
    for (int i = 0; i < 24; ++i) {
        const Shape& s = all[static_cast<std::size_t>(i) % all.size()];
        Impact impact{surfacePoint(s.mesh, rng), {0, 1, 0}, 5};
        FractureParams params = paramsFor(s.mesh, rng);
        const auto cells = generateCells(s.mesh.bounds(), impact, params, rng.next());
        auto a = makeBooleanBackend(BooleanKind::Corefine)->split(s.mesh, cells);
        auto b = makeBooleanBackend(i >= 12 ? BooleanKind::Fast : BooleanKind::Nef)->split(s.mesh, cells);
        ASSERT_TRUE(a.isOk()) << a.error().message;
        ASSERT_TRUE(b.isOk()) << b.error().message;
        const double v0 = signedVolume(s.mesh);
        auto vol = [](const Mesh& m) { return m.empty() ? 0.0 : signedVolume(m); };
        EXPECT_NEAR(vol(a->remainder), vol(b->remainder), 1e-9 * v0) << s.name;
        ASSERT_EQ(a->inside.size(), b->inside.size());
        for (std::size_t k = 0; k < a->inside.size(); ++k)
            EXPECT_NEAR(vol(a->inside[k]), vol(b->inside[k]), 1e-9 * v0) << s.name << " cell " << k;
        EXPECT_TRUE(b->remainder.empty() || closedAndOriented(b->remainder)) << s.name;
    }
}

// Shatter patterns only: Fast (without falling back) and Corefine give the same piece per cell.
TEST(Fracture, FastAndCorefineAgreeOnShatterCells) {
    Rng rng(31);
    const std::vector<Shape> all = shapes();
    int fastSplits = 0;
    for (int i = 0; i < 30; ++i) {
        const Shape& s = all[static_cast<std::size_t>(i) % all.size()];
        Impact impact{surfacePoint(s.mesh, rng), {0, 1, 0}, 5};
        FractureParams params = paramsFor(s.mesh, rng);
        params.pattern = CellPattern::Shatter;
        params.cells = 2 + static_cast<int>(rng.below(7));
        const auto cells = generateCells(s.mesh.bounds(), impact, params, rng.next());
        ASSERT_GE(cells.size(), 2u);
        auto a = makeBooleanBackend(BooleanKind::Corefine)->split(s.mesh, cells);
        auto b = makeBooleanBackend(BooleanKind::Fast)->split(s.mesh, cells);
        ASSERT_TRUE(a.isOk()) << a.error().message;
        ASSERT_TRUE(b.isOk()) << b.error().message;
        fastSplits += !b->exactFallback;
        const double v0 = signedVolume(s.mesh);
        auto vol = [](const Mesh& m) { return m.empty() ? 0.0 : signedVolume(m); };
        EXPECT_NEAR(vol(a->remainder), vol(b->remainder), 1e-9 * v0) << s.name;
        ASSERT_EQ(a->inside.size(), b->inside.size());
        for (std::size_t k = 0; k < a->inside.size(); ++k) {
            EXPECT_NEAR(vol(a->inside[k]), vol(b->inside[k]), 1e-9 * v0) << s.name << " cell " << k;
            EXPECT_TRUE(b->inside[k].empty() || closedAndOriented(b->inside[k])) << s.name << " cell " << k;
        }
        EXPECT_TRUE(b->remainder.empty() || closedAndOriented(b->remainder)) << s.name;
    }
    EXPECT_GE(fastSplits, 28) << "Fast fell back to Corefine too often";
}

TEST(Fracture, NefBackendFractures) {
    const Mesh box = makeSubdividedBox({-1, -1, -1}, {1, 1, 1}, 2);
    FractureParams params;
    params.backend = BooleanKind::Nef;
    params.sizeLaw.base = 1.0;
    params.sizeLaw.scale = 0;
    auto r = fracture(box, {{0.99, 0.1, 0}, {1, 0, 0}, 1}, params, 4);
    ASSERT_TRUE(r.isOk()) << r.error().message;
    checkResult(box, *r, "nef");
    // Nef's output order follows its internal storage; the backend makes it canonical: same seed, same bytes.
    for (int i = 0; i < 3; ++i) {
        auto again = fracture(box, {{0.99, 0.1, 0}, {1, 0, 0}, 1}, params, 4);
        ASSERT_TRUE(again.isOk());
        EXPECT_EQ(test::hashPieces(*again), test::hashPieces(*r));
    }
}

TEST_P(FractureBackend, DegenerateHitsOnVerticesEdgesAndCoplanarFaces) {
    const Mesh box = makeSubdividedBox({-1, -1, -1}, {1, 1, 1}, 2);
    FractureParams params;
    params.sizeLaw.base = 0.8;
    params.sizeLaw.scale = 0;
    {
        params.backend = GetParam();
        // Exactly on a corner, on an edge midpoint, on a grid vertex of a face.
        for (const Vec3 p : {Vec3{1, 1, 1}, Vec3{1, 0, 1}, Vec3{1, 0, 0}, Vec3{-1, -1, 0.5}}) {
            for (std::uint64_t seed = 0; seed < 5; ++seed) {
                auto r = fracture(box, {p, {1, 0, 0}, 1}, params, seed);
                ASSERT_TRUE(r.isOk()) << r.error().message;
                checkResult(box, *r, "degenerate hit");
            }
        }
        // An axis-aligned cell whose faces are coplanar with the box's faces and grid lines.
        const std::vector<ConvexPolytope> cells{ConvexPolytope::fromAabb({{0, 0, 0}, {1, 1, 1}}),
                                                ConvexPolytope::fromAabb({{-1, 0, 0}, {0, 1, 1}})};
        auto r = fractureWithCells(box, cells, params);
        ASSERT_TRUE(r.isOk()) << r.error().message;
        checkResult(box, *r, "coplanar cells");
        double inside = 0;
        for (const Piece& p : r->pieces)
            if (p.cell >= 0)
                inside += p.mass.volume;
        EXPECT_NEAR(inside, 2.0, 1e-12);
        // A cell larger than the mesh swallows it whole: no remainder.
        auto all = fractureWithCells(box, {ConvexPolytope::fromAabb({{-2, -2, -2}, {2, 2, 2}})}, params);
        ASSERT_TRUE(all.isOk()) << all.error().message;
        checkResult(box, *all, "swallowed");
        for (const Piece& p : all->pieces)
            EXPECT_EQ(p.cell, 0);
    }
}

TEST(Fracture, ImpactOutsideTheMeshIsNoIntersection) {
    const Mesh box = makeBox({-1, -1, -1}, {1, 1, 1});
    FractureParams params;
    params.sizeLaw.base = 0.5;
    params.sizeLaw.scale = 0;
    for (BooleanKind backend : {BooleanKind::Corefine, BooleanKind::Fast, BooleanKind::Nef}) {
        params.backend = backend;
        auto r = fracture(box, {{5, 0, 0}, {1, 0, 0}, 1}, params, 1);
        ASSERT_FALSE(r.isOk());
        EXPECT_EQ(r.error().code, ErrorCode::NoIntersection);
        EXPECT_FALSE(r.error().message.empty());
        // Bounding boxes overlap but the cell misses the (concave) L prism.
        auto l = fracture(lPrism(), {{1.7, 1.7, 0.5}, {1, 0, 0}, 1}, params, 2);
        ASSERT_FALSE(l.isOk());
        EXPECT_EQ(l.error().code, ErrorCode::NoIntersection) << l.error().message;
    }
}

// A closed, consistently oriented mesh that intersects itself (two overlapping boxes) passes the input check
// but is not a solid the exact backends can cut where it intersects itself. CGAL 5.5's Nef polyhedra could
// write through a bogus handle on such input (the fracture fuzzer's
// crash_nef_self_intersecting_sphere_shatter .bin): the Nef backend refuses any self-intersecting mesh as a
// GeometryFailure. Corefinement (and Fast, through its exact fallback) check only the faces the cells cut: a
// cut through the intersection is refused, one away from it may succeed and must then be sound. Nothing
// crashes; a refused mesh stays whole.
TEST(Fracture, SelfIntersectingMeshIsRefusedWhereItIsCut) {
    Mesh overlapping = makeBox({-1, -1, -1}, {0.5, 1, 1});
    overlapping.append(makeBox({-0.5, -0.8, -0.8}, {1, 0.8, 0.8}));
    ASSERT_GT(findSelfIntersections(overlapping, 1).pairs, 0u);
    FractureParams params;
    params.pattern = CellPattern::Shatter;
    params.cells = 4;
    params.sizeLaw.base = 0.6;
    params.sizeLaw.scale = 0;
    const Impact throughIt{{0.5, 0, 0.8}, {0, 0, 1}, 1}; // on a line where the surfaces cross
    const Impact awayFromIt{{1, 0.1, 0.2}, {1, 0, 0}, 1};
    for (BooleanKind backend : {BooleanKind::Corefine, BooleanKind::Fast, BooleanKind::Nef}) {
        params.backend = backend;
        auto r = fracture(overlapping, throughIt, params, 5);
        ASSERT_FALSE(r.isOk()) << static_cast<int>(backend);
        EXPECT_EQ(r.error().code, ErrorCode::GeometryFailure) << r.error().message;
        // The message says what failed: the mesh intersects itself (not CGAL's own words).
        EXPECT_NE(r.error().message.find("intersects itself"), std::string::npos) << r.error().message;
        EXPECT_EQ(r.error().message.find("Self-intersection detected"), std::string::npos)
            << r.error().message;
        auto away = fracture(overlapping, awayFromIt, params, 5);
        if (backend == BooleanKind::Nef) {
            ASSERT_FALSE(away.isOk());
            EXPECT_NE(away.error().message.find("intersects itself"), std::string::npos)
                << away.error().message;
        } else if (away.isOk()) {
            checkResult(overlapping, *away, "a cut away from the self-intersection");
        } else {
            EXPECT_EQ(away.error().code, ErrorCode::GeometryFailure) << away.error().message;
        }
    }
}

// Issue #20: many-cell shatters of a unit cube hit on its top face. Before the cells were built as one
// complex, 1 or 2 seeds in 10 failed at each of these counts (listed in `failed`) on Fast and Corefine. The
// clipper may still hand a near-degenerate split to its exact fallback, but every split succeeds.
TEST(Fracture, ManyCellShattersOfTheUnitCubeSucceed) {
    const Mesh cube = makeBox({0, 0, 0}, {1, 1, 1});
    const std::vector<std::pair<int, std::uint64_t>> failed{{30, 10}, {50, 10}, {100, 1},
                                                            {100, 8}, {150, 1}, {150, 2}};
    int fallbacks = 0, redraws = 0;
    for (int cells : {30, 50, 100, 150})
        for (std::uint64_t seed : test::sweepSeeds(10, {1, 2, 8, 10})) {
            FractureParams params;
            params.pattern = CellPattern::Shatter;
            params.cells = cells;
            std::vector<BooleanKind> backends{BooleanKind::Fast};
            if (std::find(failed.begin(), failed.end(), std::pair{cells, seed}) != failed.end())
                backends.push_back(BooleanKind::Corefine);
            if (cells <= 50 && seed == 10) // Nef takes seconds at these counts: the smaller cases only
                backends.push_back(BooleanKind::Nef);
            for (BooleanKind backend : backends) {
                params.backend = backend;
                const std::string what = std::to_string(cells) + " cells, seed " + std::to_string(seed) +
                                         ", backend " + std::to_string(static_cast<int>(backend));
                auto r = fracture(cube, {{0.5, 0.5, 1}, {0, 0, 1}, 1}, params, seed);
                ASSERT_TRUE(r.isOk()) << what << ": " << r.error().message;
                fallbacks += r->stats.exactFallback;
                redraws += r->stats.redraws;
                checkResult(cube, *r, what);
            }
        }
    std::printf("fast backend: %d patterns redrawn, %d exact fallbacks\n", redraws, fallbacks);
    EXPECT_EQ(fallbacks, 0);
}

// A pattern the clipper declines as near-degenerate (here an ill-conditioned crossing of a cell edge, found
// by a search over the repository's models) is redrawn from a derived seed instead of being cut by the slow
// exact backend; the seed still decides it.
TEST(Fracture, FastRedrawsADeclinedPattern) {
    auto arch = readObj(test::sourceDir() / "assets" / "models" / "arch.obj");
    ASSERT_TRUE(arch.isOk());
    const auto corners = arch->corners(3);
    const Impact impact{(corners[0] + corners[1] + corners[2]) * (1.0 / 3), {0, 0, 1}, 1};
    FractureParams params;
    params.pattern = CellPattern::Shatter;
    params.cells = 1000;
    std::vector<ConvexPolytope> own;
    for (ConvexPolytope& c : generateCells(arch->bounds(), impact, params, 3))
        if (c.bounds().overlaps(arch->bounds()))
            own.push_back(std::move(c));
    ASSERT_FALSE(detail::clipByConvexCells(*arch, own).isOk())
        << "the seed's own pattern is no longer declined";
    auto r = fracture(*arch, impact, params, 3);
    ASSERT_TRUE(r.isOk()) << r.error().message;
    EXPECT_GE(r->stats.redraws, 1);
    EXPECT_FALSE(r->stats.exactFallback);
    checkResult(*arch, *r, "redrawn pattern");
    auto again = fracture(*arch, impact, params, 3);
    ASSERT_TRUE(again.isOk());
    EXPECT_EQ(test::hashPieces(*r), test::hashPieces(*again));
}

TEST(Fracture, OpenOrInvalidInputIsRejected) {
    Mesh open = makeBox({-1, -1, -1}, {1, 1, 1});
    open.triangles.pop_back();
    auto r = fracture(open, {{1, 0, 0}, {1, 0, 0}, 1}, {}, 1);
    ASSERT_FALSE(r.isOk());
    EXPECT_EQ(r.error().code, ErrorCode::InvalidInput);
    Mesh nan = makeBox({-1, -1, -1}, {1, 1, 1});
    nan.positions[0].x = std::nan("");
    EXPECT_EQ(fracture(nan, {{1, 0, 0}, {1, 0, 0}, 1}, {}, 1).error().code, ErrorCode::InvalidInput);
    Mesh inverted = makeBox({-1, -1, -1}, {1, 1, 1});
    for (Triangle& t : inverted.triangles)
        std::swap(t[1], t[2]);
    EXPECT_EQ(fracture(inverted, {{1, 0, 0}, {1, 0, 0}, 1}, {}, 1).error().code, ErrorCode::InvalidInput);
    EXPECT_EQ(fracture(Mesh{}, {{1, 0, 0}, {1, 0, 0}, 1}, {}, 1).error().code, ErrorCode::InvalidInput);
}

TEST_P(FractureBackend, TinyAndHugeImpulsesAndFarFromOrigin) {
    const Mesh box = makeSubdividedBox({-1, -1, -1}, {1, 1, 1}, 3);
    FractureParams params;
    params.backend = GetParam();
    for (double impulse : {0.0, 1e-9, 1e6, 1e12}) {
        auto r = fracture(box, {{0.99, 0.2, 0.1}, {1, 0, 0}, impulse}, params, 3);
        ASSERT_TRUE(r.isOk()) << r.error().message;
        checkResult(box, *r, "impulse " + std::to_string(impulse));
    }
    // Beyond kMaxImpulse (ParameterCheck.hpp) an impulse is refused, as every API refuses it.
    auto huge = fracture(box, {{0.99, 0.2, 0.1}, {1, 0, 0}, 1e300}, params, 3);
    ASSERT_FALSE(huge.isOk());
    EXPECT_EQ(huge.error().code, ErrorCode::InvalidInput);
    params.sizeLaw.minSize = 1e-4;
    params.sizeLaw.base = 1e-4;
    params.sizeLaw.scale = 0;
    auto tiny = fracture(box, {{1, 0.2, 0.1}, {1, 0, 0}, 1}, params, 3);
    ASSERT_TRUE(tiny.isOk()) << tiny.error().message;
    checkResult(box, *tiny, "tiny cell");

    const Vec3 far{1e5, -2e5, 3e5};
    const Mesh farBox = box.translated(far);
    FractureParams fp;
    fp.sizeLaw.base = 1.0;
    fp.sizeLaw.scale = 0;
    {
        fp.backend = GetParam();
        Rng rng(8);
        for (int i = 0; i < 10; ++i) {
            auto r = fracture(farBox, {surfacePoint(farBox, rng), {1, 0, 0}, 1}, fp, rng.next());
            ASSERT_TRUE(r.isOk()) << r.error().message;
            checkResult(farBox, *r, "far from origin");
        }
    }
}

// Three generations of pieces (each fracture interpolates in double and stores float): texture coordinates
// that are a linear function of position stay on it within a few float steps, and normals stay unit and
// outward.
TEST(Fracture, AttributesStayWithinFloatPrecisionThroughPiecesOfPieces) {
    Mesh mesh = makeSubdividedBox({-1, -1, -1}, {1, 1, 1}, 2);
    mesh.computeFlatNormals();
    mesh.materials.assign(mesh.triangleCount(), 3u);
    auto uvOf = [](const Vec3& p) { return Vec2{p.x + 2 * p.y, p.z - 0.5 * p.x}; };
    for (std::size_t t = 0; t < mesh.triangleCount(); ++t)
        for (const Vec3& p : mesh.corners(t))
            mesh.uvs.emplace_back(uvOf(p));
    FractureParams params;
    params.pattern = CellPattern::Shatter;
    params.cells = 3;
    params.sizeLaw.base = 0.9;
    params.sizeLaw.scale = 0;
    std::size_t outerCorners = 0;
    for (int generation = 0; generation < 3; ++generation) {
        const Vec3 at = mesh.bounds().hi;
        auto r = fracture(mesh, {at, normalized(at), 1}, params, 7 + static_cast<std::uint64_t>(generation));
        ASSERT_TRUE(r.isOk()) << r.error().message;
        const Piece* largest = nullptr;
        for (const Piece& piece : r->pieces) {
            const Mesh& m = piece.mesh;
            ASSERT_EQ(m.normals.size(), 3 * m.triangleCount());
            for (std::size_t t = 0; t < m.triangleCount(); ++t) {
                const auto c = m.corners(t);
                const Vec3 n = normalized(m.triangleNormal(t));
                for (std::size_t k = 0; k < 3; ++k) {
                    const Vec3 stored = m.normals[3 * t + k];
                    EXPECT_NEAR(length(stored), 1.0, 1e-6);
                    EXPECT_GT(dot(stored, n), 0.999);
                    if (m.materials[t] != 3u)
                        continue;
                    ++outerCorners;
                    const Vec2 want = uvOf(c[k]); // values up to 3: a float step is 2.4e-7
                    EXPECT_NEAR(m.uvs[3 * t + k].x, want.x, 1e-6) << "generation " << generation;
                    EXPECT_NEAR(m.uvs[3 * t + k].y, want.y, 1e-6) << "generation " << generation;
                }
            }
            if (!largest || piece.mass.volume > largest->mass.volume)
                largest = &piece;
        }
        ASSERT_TRUE(largest);
        mesh = largest->mesh;
    }
    EXPECT_GT(outerCorners, 100u);
}

TEST(Fracture, AttributesAreKeptAndCutFacesGetInteriorUvs) {
    // UVs and normals that are linear functions of position: interpolation must reproduce them within the
    // float they are stored in (a few units in the last place of values up to 5).
    constexpr double kUvTolerance = 2e-6;
    Mesh box = makeSubdividedBox({-1, -1, -1}, {1, 1, 1}, 3);
    box.computeFlatNormals();
    box.uvs.clear();
    box.materials.assign(box.triangleCount(), 3u);
    auto uvOf = [](const Vec3& p) { return Vec2{p.x + 2 * p.y, p.z - 0.5 * p.x}; };
    for (std::size_t t = 0; t < box.triangleCount(); ++t)
        for (const Vec3& p : box.corners(t))
            box.uvs.emplace_back(uvOf(p));
    for (BooleanKind backend : {BooleanKind::Corefine, BooleanKind::Fast, BooleanKind::Nef}) {
        FractureParams params;
        params.backend = backend;
        params.uvScale = 2.5;
        params.pattern = CellPattern::Shatter;
        params.cells = 3;
        params.sizeLaw.base = 1.2;
        params.sizeLaw.scale = 0;
        auto r = fracture(box, {{0.99, 0.1, 0.2}, {1, 0, 0}, 1}, params, 11);
        ASSERT_TRUE(r.isOk()) << r.error().message;
        checkResult(box, *r, "attributes");
        int cut = 0;
        for (const Piece& piece : r->pieces) {
            const Mesh& m = piece.mesh;
            ASSERT_EQ(m.normals.size(), 3 * m.triangleCount());
            for (std::size_t t = 0; t < m.triangleCount(); ++t) {
                const auto c = m.corners(t);
                const Vec3 n = normalized(m.triangleNormal(t));
                for (int k = 0; k < 3; ++k) {
                    const std::size_t i = 3 * t + static_cast<std::size_t>(k);
                    EXPECT_GT(dot(m.normals[i], n), 0.999);
                    if (m.materials[t] == 3u) {
                        const Vec2 want = uvOf(c[static_cast<std::size_t>(k)]);
                        EXPECT_NEAR(m.uvs[i].x, want.x, kUvTolerance);
                        EXPECT_NEAR(m.uvs[i].y, want.y, kUvTolerance);
                    }
                }
                if (m.materials[t] != kInteriorMaterial)
                    continue;
                ++cut;
                // Planar projection: the uv difference of two corners has the length of their distance.
                const double du =
                    std::hypot(m.uvs[3 * t + 1].x - m.uvs[3 * t].x, m.uvs[3 * t + 1].y - m.uvs[3 * t].y);
                EXPECT_NEAR(du, 2.5 * length(c[1] - c[0]), kUvTolerance);
            }
        }
        EXPECT_GT(cut, 0);
    }
}

INSTANTIATE_TEST_SUITE_P(Backends, FractureBackend,
                         ::testing::Values(BooleanKind::Corefine, BooleanKind::Fast), backendName);

// Round 3, defects 6 and 10: fracture refuses what check calls invalid: nested shells both facing outward
// (pieces overlapped, summing to 9 for a solid of 8), coordinates whose volume integrals overflow.
TEST(Fracture, RefusesMisnestedShellsAndHugeCoordinates) {
    Mesh nested = makeBox({-1, -1, -1}, {1, 1, 1});
    nested.append(makeBox({-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5}));
    FractureParams shatter;
    shatter.pattern = CellPattern::Shatter;
    shatter.cells = 8;
    const Impact impact{{0.9, 0.9, 1}, {0, 0, -1}, 200};
    auto r = fracture(nested, impact, shatter, 1);
    ASSERT_FALSE(r.isOk());
    EXPECT_EQ(r.error().code, ErrorCode::InvalidInput);
    EXPECT_NE(r.error().message.find("faces the wrong way for its nesting"), std::string::npos)
        << r.error().message;
    EXPECT_FALSE(analyzeMesh(nested).isOk());

    // With the inner shell facing inward (a cavity) the pieces keep the volume 8 - 1.
    Mesh hollow = makeBox({-1, -1, -1}, {1, 1, 1});
    Mesh inner = makeBox({-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5});
    for (Triangle& t : inner.triangles)
        std::swap(t[1], t[2]);
    hollow.append(inner);
    auto ok = fracture(hollow, impact, shatter, 1);
    ASSERT_TRUE(ok.isOk()) << ok.error().message;
    double volume = ok->droppedVolume;
    for (const Piece& p : ok->pieces)
        volume += p.mass.volume;
    EXPECT_NEAR(volume, 7.0, 1e-6);

    const double h = 1e150;
    auto huge = fracture(makeBox({-h, -h, -h}, {h, h, h}), Impact{{0, 0, h}, {0, 0, -1}, 200}, shatter, 1);
    ASSERT_FALSE(huge.isOk());
    EXPECT_EQ(huge.error().code, ErrorCode::InvalidInput);
    EXPECT_NE(huge.error().message.find("beyond ±1e+50"), std::string::npos) << huge.error().message;
}
