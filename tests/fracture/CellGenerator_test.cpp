// Cell generators: the thesis's single Voronoi cell and the shatter pattern.

#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "TestSupport.hpp"
#include "fracture/ConvexCellClipper.hpp"
#include "rubble/core/Random.hpp"
#include "rubble/fracture/Fracture.hpp"
#include "rubble/geometry/MassProperties.hpp"

using namespace rubble;
using rubble::test::closedAndOriented;

namespace {

// Every face is planar, counter-clockwise seen from outside, and every vertex is inside every plane.
void checkConvexCell(const ConvexPolytope& cell, double size) {
    ASSERT_FALSE(cell.empty());
    const auto verts = cell.vertices();
    for (std::size_t i = 0; i < cell.faces().size(); ++i) {
        const PolytopeFaceView& f = cell.faces()[i];
        EXPECT_EQ(f.tag, static_cast<std::int32_t>(i));
        EXPECT_NEAR(length(f.plane.normal), 1.0, 1e-12);
        Vec3 n;
        for (std::size_t k = 0; k < f.corners.size(); ++k)
            n += cross(f.corners[k], f.corners[(k + 1) % f.corners.size()]);
        EXPECT_GT(dot(n, f.plane.normal), 0) << "face " << i << " is not counter-clockwise from outside";
        for (const Vec3& c : f.corners)
            EXPECT_NEAR(f.plane.signedDistance(c), 0, 1e-9 * size);
        for (const Vec3& v : verts)
            EXPECT_LE(f.plane.signedDistance(v), 1e-9 * size);
    }
    const Mesh m = cell.toMesh();
    EXPECT_TRUE(closedAndOriented(m));
    EXPECT_GT(signedVolume(m), 0);
    EXPECT_NEAR(signedVolume(m), cell.volume(), 1e-9 * size * size * size);
}

} // namespace

TEST(CellSizeLaw, ClampsAndGrows) {
    CellSizeLaw law;
    EXPECT_DOUBLE_EQ(law.sizeFor(0), 0.5);
    EXPECT_GT(law.sizeFor(100), law.sizeFor(1));
    EXPECT_DOUBLE_EQ(law.sizeFor(1e300), law.maxSize);
    EXPECT_DOUBLE_EQ(law.sizeFor(-5), 0.5);
    EXPECT_DOUBLE_EQ(law.sizeFor(std::nan("")), 0.5);
}

// SingleCell and Shatter keep the law's size; Adaptive chips below kShatterGrowth times a touch's size and
// shatters above, and cuts larger objects larger (sqrt of the diagonal over the reference), within maxSize.
TEST(ImpactCut, AdaptiveChipsWeakHitsShattersStrongOnesAndGrowsWithTheObject) {
    FractureParams p;
    p.sizeLaw.base = 0.8;
    p.sizeLaw.scale = 0.04;
    p.sizeLaw.exponent = 0.5;
    p.sizeLaw.maxSize = 30;
    const Aabb small{{0, 0, 0}, {4, 4, 4}};    // diagonal 6.9 < reference
    const Aabb large{{0, 0, 0}, {40, 40, 40}}; // diagonal 69.3
    for (CellPattern fixed : {CellPattern::SingleCell, CellPattern::Shatter}) {
        p.pattern = fixed;
        const ImpactCut c = impactCut(p, large, 9000);
        EXPECT_EQ(c.pattern, fixed);
        EXPECT_DOUBLE_EQ(c.size, p.sizeLaw.sizeFor(9000)) << "the object's size does not count";
    }
    p.pattern = CellPattern::Adaptive;
    // threshold: base + scale * sqrt(i) = 3 * base  <=>  i = (2 * 0.8 / 0.04)^2 = 1600
    EXPECT_EQ(impactCut(p, small, 680).pattern, CellPattern::SingleCell) << "a cannon shell chips";
    EXPECT_EQ(impactCut(p, small, 1599).pattern, CellPattern::SingleCell);
    EXPECT_EQ(impactCut(p, small, 1601).pattern, CellPattern::Shatter);
    EXPECT_EQ(impactCut(p, small, 8000).pattern, CellPattern::Shatter) << "a heavy shell shatters";
    EXPECT_EQ(impactCut(p, small, std::nan("")).pattern, CellPattern::SingleCell);
    EXPECT_DOUBLE_EQ(impactCut(p, small, 680).size, p.sizeLaw.sizeFor(680)) << "small objects: the law";
    EXPECT_DOUBLE_EQ(impactCut(p, Aabb{}, 680).size, p.sizeLaw.sizeFor(680)) << "empty bounds: the law";
    const double growth = std::sqrt(large.diagonal() / kAdaptiveReferenceSize);
    EXPECT_NEAR(impactCut(p, large, 680).size, p.sizeLaw.sizeFor(680) * growth, 1e-12);
    EXPECT_EQ(impactCut(p, large, 680).pattern, CellPattern::SingleCell)
        << "strength does not depend on size";
    EXPECT_DOUBLE_EQ(impactCut(p, large, 1e12).size, p.sizeLaw.maxSize);
    double last = 0;
    for (double i = 0; i < 20000; i += 250) { // monotone in the impulse
        const double s = impactCut(p, large, i).size;
        EXPECT_GE(s, last);
        last = s;
    }
}

TEST(CellGenerator, AdaptiveCutsOneCellForAWeakHitAndKForAStrongOne) {
    FractureParams p;
    p.pattern = CellPattern::Adaptive;
    p.cells = 9;
    p.sizeLaw.base = 0.8;
    p.sizeLaw.scale = 0.04;
    const Aabb bounds{{-3, -3, -3}, {3, 3, 3}};
    for (std::uint64_t seed = 0; seed < 20; ++seed) {
        EXPECT_EQ(generateCells(bounds, {{0, 0, 3}, {0, 0, 1}, 400}, p, seed).size(), 1u);
        const auto strong = generateCells(bounds, {{0, 0, 3}, {0, 0, 1}, 5000}, p, seed);
        EXPECT_EQ(strong.size(), 9u);
        for (const ConvexPolytope& c : strong)
            checkConvexCell(c, 10);
    }
}

TEST(CellGenerator, SingleCellIsTheImpactsConvexVoronoiCell) {
    Rng rng(3);
    for (int i = 0; i < 300; ++i) {
        FractureParams params;
        params.seedPoints = static_cast<int>(rng.below(30));
        const Vec3 impact = rng.inBox({-10, -10, -10}, {10, 10, 10});
        const double size = params.sizeLaw.sizeFor(rng.uniform(0, 500));
        const auto cells = generateCells({}, {impact, {0, 1, 0}, 0}, params, rng.next());
        (void)size;
        ASSERT_EQ(cells.size(), 1u);
        const ConvexPolytope& c = cells[0];
        const double s = params.sizeLaw.sizeFor(0) * 50;
        checkConvexCell(c, s);
        EXPECT_TRUE(c.contains(impact, 1e-12));
        // The cell lies in the rotated cubic domain: within half a space diagonal of the impact.
        for (const Vec3& v : c.vertices())
            EXPECT_LE(length(v - impact), params.sizeLaw.maxSize);
    }
}

TEST(CellGenerator, SingleCellVolumeBoundedByDomainAndShrinksWithMoreSeeds) {
    FractureParams params;
    params.sizeLaw.base = 2;
    params.sizeLaw.scale = 0;
    double few = 0, many = 0;
    for (std::uint64_t seed = 0; seed < 50; ++seed) {
        params.seedPoints = 0;
        const auto whole = generateCells({}, {{1, 2, 3}, {0, 1, 0}, 1}, params, seed);
        ASSERT_EQ(whole.size(), 1u);
        EXPECT_NEAR(whole[0].volume(), 8.0, 1e-9); // no other site: the whole (rotated) domain
        params.seedPoints = 3;
        few += generateCells({}, {{1, 2, 3}, {0, 1, 0}, 1}, params, seed)[0].volume();
        params.seedPoints = 40;
        many += generateCells({}, {{1, 2, 3}, {0, 1, 0}, 1}, params, seed)[0].volume();
    }
    EXPECT_LT(many, few);
    EXPECT_LT(few, 50 * 8.0);
}

TEST(CellGenerator, DeterministicInSeed) {
    FractureParams params;
    for (CellPattern pattern : {CellPattern::SingleCell, CellPattern::Shatter}) {
        params.pattern = pattern;
        const auto a = generateCells({}, {{0, 0, 0}, {0, 1, 0}, 3}, params, 42);
        const auto b = generateCells({}, {{0, 0, 0}, {0, 1, 0}, 3}, params, 42);
        const auto c = generateCells({}, {{0, 0, 0}, {0, 1, 0}, 3}, params, 43);
        ASSERT_EQ(a.size(), b.size());
        for (std::size_t i = 0; i < a.size(); ++i)
            EXPECT_EQ(a[i].toMesh(), b[i].toMesh());
        EXPECT_FALSE(a[0].toMesh() == c[0].toMesh());
    }
}

TEST(CellGenerator, ShatterCellsAreDisjointConvexAndAroundTheImpact) {
    Rng rng(5);
    for (int i = 0; i < 60; ++i) {
        FractureParams params;
        params.pattern = CellPattern::Shatter;
        params.cells = 1 + static_cast<int>(rng.below(8));
        params.sizeLaw.base = 1;
        params.sizeLaw.scale = 0;
        const Vec3 impact = rng.inBox({-5, -5, -5}, {5, 5, 5});
        const auto cells = generateCells({}, {impact, {0, 1, 0}, 1}, params, rng.next());
        ASSERT_EQ(cells.size(), static_cast<std::size_t>(params.cells));
        EXPECT_TRUE(cells[0].contains(impact, 1e-12));
        double total = 0;
        for (const ConvexPolytope& c : cells) {
            checkConvexCell(c, 1);
            total += c.volume();
        }
        EXPECT_LE(total, 1.25 * 1.25 * 1.25 + 1e-9);
        // Interiors are disjoint: each cell's centroid is strictly outside every other cell.
        for (std::size_t a = 0; a < cells.size(); ++a)
            for (std::size_t b = 0; b < cells.size(); ++b)
                if (a != b) {
                    EXPECT_FALSE(cells[b].contains(cells[a].centroid(), -1e-9));
                }
        // Shared corners are bit-identical across neighbouring cells (one Voronoi vertex per Delaunay
        // tetrahedron, short edges contracted): no near-duplicates remain.
        std::vector<Vec3> all;
        for (const ConvexPolytope& c : cells)
            for (const Vec3& v : c.vertices())
                all.push_back(v);
        for (std::size_t a = 0; a < all.size(); ++a)
            for (std::size_t b = a + 1; b < all.size(); ++b)
                if (!(all[a] == all[b])) {
                    EXPECT_GT(length(all[a] - all[b]), 1e-9);
                }
    }
}

// The issue #20 configurations (unit cube, impact on its top face, 30-1,000 cells, seeds 1-10) and random
// ones: the cells form a complex, so the clipper splits a box that holds them all without declining, and
// every cell comes back whole (its piece has the cell's volume).
TEST(CellGenerator, ShatterCellsFormAComplex) {
    const Mesh box = makeSubdividedBox({-2, -2, -2}, {3, 3, 3}, 1);
    std::vector<std::pair<int, std::uint64_t>> cases;
    for (int cells : {30, 50, 100, 150, 200, 1000})
        for (std::uint64_t seed : test::sweepSeeds(10, {1, 2, 8, 10}))
            cases.emplace_back(cells, seed);
    for (const auto& [k, seed] : cases) {
        FractureParams params;
        params.pattern = CellPattern::Shatter;
        params.cells = k;
        const auto cells = generateCells({}, {{0.5, 0.5, 1}, {0, 0, 1}, 1}, params, seed);
        ASSERT_EQ(cells.size(), static_cast<std::size_t>(k));
        auto split = detail::clipByConvexCells(box, cells);
        ASSERT_TRUE(split.isOk()) << k << " cells, seed " << seed << ": " << split.error().message;
        double total = 0;
        for (std::size_t i = 0; i < cells.size(); ++i) {
            EXPECT_NEAR(signedVolume(split->inside[i]), cells[i].volume(), 1e-9 * cells[i].volume())
                << k << " cells, seed " << seed << ", cell " << i;
            total += cells[i].volume();
        }
        EXPECT_NEAR(signedVolume(split->outside), 125 - total, 1e-9) << k << " cells, seed " << seed;
    }
}

// Every layout's cells form a complex that clips a box exactly (no gaps, no overlaps), at every size.
TEST(CellGenerator, EveryShatterLayoutFormsAComplex) {
    const Mesh box = makeSubdividedBox({-2, -2, -2}, {3, 3, 3}, 1);
    for (ShatterLayout layout : {ShatterLayout::Radial, ShatterLayout::Splinter, ShatterLayout::Uniform})
        for (int k : {2, 16, 100, 400})
            for (std::uint64_t seed = 1; seed <= 4; ++seed) {
                FractureParams params;
                params.pattern = CellPattern::Shatter;
                params.layout = layout;
                params.cells = k;
                const std::string what = "layout " + std::to_string(static_cast<int>(layout)) + ", " +
                                         std::to_string(k) + " cells, seed " + std::to_string(seed);
                const auto cells = generateCells(box.bounds(), {{0.5, 0.5, 1}, {0, 0, 1}, 1}, params, seed);
                ASSERT_EQ(cells.size(), static_cast<std::size_t>(k)) << what;
                auto split = detail::clipByConvexCells(box, cells);
                ASSERT_TRUE(split.isOk()) << what << ": " << split.error().message;
                double total = 0;
                for (std::size_t i = 0; i < cells.size(); ++i) {
                    EXPECT_NEAR(signedVolume(split->inside[i]), cells[i].volume(), 1e-9 * cells[i].volume())
                        << what << ", cell " << i;
                    total += cells[i].volume();
                }
                EXPECT_NEAR(signedVolume(split->outside), 125 - total, 1e-9) << what;
            }
}

namespace {
// Extent of a polytope along a unit direction.
double extent(const ConvexPolytope& p, const Vec3& d) {
    double lo = 1e300, hi = -1e300;
    for (const Vec3& v : p.vertices()) {
        lo = std::min(lo, dot(v, d));
        hi = std::max(hi, dot(v, d));
    }
    return hi - lo;
}
} // namespace

// Glass: the cut faces between radial cells stand across the pane (their normals lie in the pane's plane), so
// a hit on a pane breaks it into wedges through its whole thickness.
TEST(CellGenerator, RadialCellsAreWedgesThroughThePane) {
    FractureParams params;
    params.pattern = CellPattern::Shatter;
    params.layout = ShatterLayout::Radial;
    params.cells = 24;
    const Vec3 normal = normalized(Vec3{1, 2, 3});
    for (std::uint64_t seed = 1; seed <= 5; ++seed) {
        const auto cells = generateCells({}, {{0, 0, 0}, normal, 1}, params, seed);
        ASSERT_EQ(cells.size(), 24u);
        int across = 0, caps = 0, faces = 0;
        for (const ConvexPolytope& c : cells)
            for (const PolytopeFaceView& f : c.faces()) {
                const double along = std::abs(dot(f.plane.normal, normal));
                ++faces;
                across += along < 0.3 ? 1 : 0;
                caps += along > 0.9 ? 1 : 0; // where the domain ends above and below the pane
            }
        EXPECT_EQ(across + caps, faces) << "seed " << seed << ": a face neither across the pane nor a cap";
        EXPECT_GT(across, 2 * caps) << "seed " << seed;
    }
}

// Wood: cells are long along the grain (the longest axis of the mesh's bounds), short across it.
TEST(CellGenerator, SplinterCellsAreLongAlongTheGrain) {
    FractureParams params;
    params.pattern = CellPattern::Shatter;
    params.cells = 16;
    const Aabb beam{{-0.1, -0.1, -2}, {0.1, 0.1, 2}}; // grain along z
    auto meanRatio = [&](ShatterLayout layout) {
        params.layout = layout;
        double ratio = 0;
        for (std::uint64_t seed = 1; seed <= 5; ++seed)
            for (const ConvexPolytope& c : generateCells(beam, {{0, 0.1, 0}, {0, 1, 0}, 1}, params, seed))
                ratio += extent(c, {0, 0, 1}) / std::max(extent(c, {1, 0, 0}), extent(c, {0, 1, 0}));
        return ratio / (5 * 16);
    };
    const double splinter = meanRatio(ShatterLayout::Splinter),
                 clustered = meanRatio(ShatterLayout::Clustered);
    EXPECT_GT(splinter, 1.5) << "splinters: mean length over width";
    EXPECT_GT(splinter, 3 * clustered) << "clustered cells are not elongated";
}

// Steel: uniform cells vary less in size than clustered ones (fine at the impact, coarse further out).
TEST(CellGenerator, UniformCellsVaryLessInSizeThanClusteredOnes) {
    auto spread = [](ShatterLayout layout) {
        FractureParams params;
        params.pattern = CellPattern::Shatter;
        params.layout = layout;
        params.cells = 32;
        double total = 0;
        for (std::uint64_t seed = 1; seed <= 8; ++seed) {
            const auto cells = generateCells({}, {{0, 0, 0}, {0, 0, 1}, 1}, params, seed);
            double lo = 1e300, hi = 0;
            for (const ConvexPolytope& c : cells) {
                lo = std::min(lo, c.volume());
                hi = std::max(hi, c.volume());
            }
            total += std::log(hi / lo);
        }
        return total / 8;
    };
    EXPECT_LT(spread(ShatterLayout::Uniform), spread(ShatterLayout::Clustered) - 0.5);
}

TEST(CellGenerator, ShatterCellCountIsClampedToTheMaximum) {
    FractureParams params;
    params.pattern = CellPattern::Shatter;
    params.cells = kMaxShatterCells + 500;
    EXPECT_EQ(generateCells({}, {{0, 0, 0}, {0, 0, 1}, 1}, params, 1).size(),
              static_cast<std::size_t>(kMaxShatterCells));
}
