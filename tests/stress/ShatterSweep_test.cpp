// Seeded shatter sweep (issue #20): shatter patterns of 2-200 cells at random surface points of the
// repository's models and of subdivided boxes, on every backend. Every shatter must succeed with closed,
// oriented pieces that conserve volume. CI runs a slice; the full run is 2,000 per backend
// (RUBBLE_SWEEP_SHATTERS=2000, docs/robustness.md).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "RepositoryModels.hpp"
#include "TestSupport.hpp"
#include "rubble/core/Random.hpp"
#include "rubble/fracture/Fracture.hpp"
#include "rubble/geometry/MassProperties.hpp"
#include "rubble/io/MeshIO.hpp"

using namespace rubble;
using rubble::test::closedAndOriented;
using rubble::test::surfacePoint;

namespace {

using Shape = test::NamedMesh;

std::vector<Shape> sweepShapes() {
    std::vector<Shape> shapes{{"box1", makeSubdividedBox({0, 0, 0}, {1, 1, 1}, 1)},
                              {"box4", makeSubdividedBox({0, 0, 0}, {1, 1, 1}, 4)},
                              {"box16", makeSubdividedBox({-1, -1, -1}, {1, 1, 1}, 16)}};
    test::appendRepositoryModels(shapes,
                                 {"arch", "building", "column", "cube_588", "facade_x_window", "fighter",
                                  "missile", "pillar", "projectile", "pyramid", "ship", "slab", "wall"});
    return shapes;
}

// RUBBLE_SWEEP_SHATTERS=N: N per backend; else the CI count times RUBBLE_SWEEP_SCALE (sanitizer builds: 0.1).
// RUBBLE_SWEEP_FIRST=K: draw but skip the shatters before K (to resume a long run).
int sweepCount(int ciDefault) {
    if (const char* env = std::getenv("RUBBLE_SWEEP_SHATTERS"); env && std::atoi(env) > 0)
        return std::atoi(env);
    return std::max(1, static_cast<int>(std::lround(ciDefault * test::sweepScale())));
}

struct Sweep {
    int shatters = 0, failures = 0, redraws = 0, fallbacks = 0, pieces = 0;
    double worstVolumeError = 0;
};

Sweep runSweep(BooleanKind backend, int count, std::uint64_t seed) {
    const std::vector<Shape> shapes = sweepShapes();
    Sweep s;
    Rng rng(seed);
    const char* firstEnv = std::getenv("RUBBLE_SWEEP_FIRST");
    const int first = firstEnv ? std::max(0, std::atoi(firstEnv)) : 0;
    for (int i = 0; i < count; ++i) {
        const Shape& shape = shapes[static_cast<std::size_t>(i) % shapes.size()];
        const double d = shape.mesh.bounds().diagonal();
        FractureParams params;
        params.backend = backend;
        params.pattern = CellPattern::Shatter;
        params.cells =
            static_cast<int>(std::lround(2 * std::pow(100.0, rng.uniform()))); // 2..200, log-uniform
        params.sizeLaw.base = d * rng.uniform(0.1, 0.6);
        params.sizeLaw.scale = 0;
        const Impact impact{surfacePoint(shape.mesh, rng), rng.unitVector(), rng.uniform(0, 100)};
        const std::uint64_t cellSeed = rng.next();
        const std::string what = shape.name + " shatter " + std::to_string(i) + " (" +
                                 std::to_string(params.cells) + " cells, seed " + std::to_string(cellSeed) +
                                 ")";
        if (i < first)
            continue;
        if (i > first && (i - first) % 100 == 0)
            std::printf("%d shatters done, %d failed\n", i - first, s.failures);
        ++s.shatters;
        auto r = fracture(shape.mesh, impact, params, cellSeed);
        if (!r) {
            ++s.failures;
            ADD_FAILURE() << what << ": " << r.error().message;
            continue;
        }
        s.fallbacks += r->stats.exactFallback;
        s.redraws += r->stats.redraws;
        const double v0 = signedVolume(shape.mesh);
        double sum = r->droppedVolume;
        for (const Piece& p : r->pieces) {
            ++s.pieces;
            EXPECT_TRUE(closedAndOriented(p.mesh)) << what;
            EXPECT_GT(p.mass.volume, 0) << what;
            sum += p.mass.volume;
        }
        const double err = std::abs(sum - v0) / v0;
        s.worstVolumeError = std::max(s.worstVolumeError, err);
        EXPECT_LT(err, 1e-7) << what;
    }
    std::printf("%d shatters, %d failed, %d patterns redrawn, %d exact fallbacks, %d pieces, worst relative "
                "volume error %.3g\n",
                s.shatters, s.failures, s.redraws, s.fallbacks, s.pieces, s.worstVolumeError);
    return s;
}

} // namespace

TEST(ShatterSweep, Fast) {
    EXPECT_EQ(runSweep(BooleanKind::Fast, sweepCount(600), 0x5A1).failures, 0);
}

TEST(ShatterSweep, Corefine) {
    EXPECT_EQ(runSweep(BooleanKind::Corefine, sweepCount(100), 0x5A2).failures, 0);
}

TEST(ShatterSweep, Nef) {
    EXPECT_EQ(runSweep(BooleanKind::Nef, sweepCount(6), 0x5A3).failures, 0);
}
