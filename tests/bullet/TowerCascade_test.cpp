// tower.cfg brought down by one charge at its base, on Bullet (docs/structure.md, "A tower that falls").
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <limits>
#include <memory>
#include <vector>

#include "TestSupport.hpp"
#include "rubble/bullet/BulletBinding.hpp"
#include "rubble/io/SceneConfig.hpp"
#include "rubble/runtime/SceneLoader.hpp"

using namespace rubble;
using namespace rubble::bullet;

namespace {

constexpr int kStoreys = 6; // each: four pillars, then the slab they carry (the scene's order)

struct TowerRun {
    int accepted = 0;                     // impacts the charge made
    std::vector<ImpactMark> chargeMarks;  // where
    std::vector<int> broke;               // per storey: frame its first object broke (-1: none)
    std::vector<int> fell;                // per storey: frame its first object stopped being static
    int staticObjects = 0;                // at the end
    long long impacts = 0, collapses = 0; // at the end
};

// The tower with the demo's runtime settings, settled, charged (impulse > 0), stepped; RUBBLE_TOWER_CSV:
// heights.
TowerRun runTower(double impulse, const ImpactPolicy& afterCharge, int frames, bool writeCsv = false) {
    const Result<SceneConfig> scene = parseSceneConfig(test::sourceDir() / "assets/scenes/tower.cfg");
    EXPECT_TRUE(scene) << scene.error().message;
    if (!scene)
        return {};
    DestructionRuntime::Config rc;
    rc.world.workers = 1;
    rc.world.deterministic = true;
    rc.world.seed = 20260522;
    rc.world.minPieceVolume = 0.02;
    rc.structure.enabled = true;
    auto physics = std::make_unique<PhysicsWorld>();
    auto binding = std::make_unique<BulletBinding>(*physics);
    auto runtime = std::make_unique<DestructionRuntime>(*binding, rc);
    SceneLoadOptions options;
    options.loadVehicle = false;
    const LoadedScene loaded = loadScene(*scene, *runtime, options);
    EXPECT_EQ(loaded.objects.size(), static_cast<std::size_t>(5 * kStoreys));
    for (int i = 0; i < 60; ++i)
        runtime->stepFrame();
    TowerRun out;
    out.broke.assign(kStoreys, -1);
    out.fell.assign(kStoreys, -1);
    if (impulse > 0) {
        out.accepted = runtime->blast({0, -12, 0}, 4, impulse).impacts;
        out.chargeMarks.assign(runtime->recentImpacts().begin(), runtime->recentImpacts().end());
    }
    runtime->setImpactPolicy(afterCharge);
    std::FILE* csv = nullptr;
    if (const char* path = std::getenv("RUBBLE_TOWER_CSV"); path && writeCsv)
        csv = std::fopen(path, "w");
    if (csv)
        std::fprintf(
            csv, "frame,seconds,slab1_y,slab2_y,slab3_y,slab4_y,slab5_y,slab6_y,storeys_intact,impacts\n");
    for (int f = 0; f < frames; ++f) {
        runtime->stepFrame();
        int intact = 0;
        for (int s = 0; s < kStoreys; ++s) {
            bool whole = true;
            for (int k = 0; k < 5; ++k) {
                const BodyRecord* r = runtime->bodyOf(loaded.objects[static_cast<std::size_t>(5 * s + k)]);
                if (!r && out.broke[s] < 0)
                    out.broke[s] = f;
                if ((!r || r->motion != BodyMotionState::Static) && out.fell[s] < 0)
                    out.fell[s] = f;
                whole = whole && r;
            }
            intact += whole;
        }
        if (csv) {
            std::fprintf(csv, "%d,%.4f", f, f / 60.0);
            for (int s = 0; s < kStoreys; ++s) {
                const BodyRecord* slab = runtime->bodyOf(loaded.objects[static_cast<std::size_t>(5 * s + 4)]);
                if (slab)
                    std::fprintf(csv, ",%.3f", runtime->motion(slab->id).transform.translation.y);
                else
                    std::fprintf(csv, ",");
            }
            std::fprintf(csv, ",%d,%lld\n", intact, runtime->counters().impacts);
        }
    }
    if (csv)
        std::fclose(csv);
    for (ObjectId id : loaded.objects)
        if (const BodyRecord* r = runtime->bodyOf(id))
            out.staticObjects += r->motion == BodyMotionState::Static;
    out.impacts = runtime->counters().impacts;
    out.collapses = runtime->counters().piecesCollapsed;
    runtime.reset();
    binding.reset();
    return out;
}

} // namespace

// The charge breaks the ground floor; the storeys above fall at once and break bottom-up as they land.
TEST(TowerCascade, OneChargeAtItsBaseBringsTheTowerDownStoreyByStoreyThroughLandingImpacts) {
    const int frames = 360;
    const TowerRun unshot = runTower(0, ImpactPolicy{}, frames);
    EXPECT_EQ(unshot.staticObjects, 5 * kStoreys);
    EXPECT_EQ(unshot.collapses, 0);
    EXPECT_EQ(unshot.impacts, 0);

    const TowerRun run = runTower(20000, ImpactPolicy{}, frames, true);
    ASSERT_EQ(run.broke.size(), static_cast<std::size_t>(kStoreys)) << "the scene loaded";
    EXPECT_EQ(run.accepted, 5) << "the ground floor's four pillars and the first slab";
    for (const ImpactMark& m : run.chargeMarks)
        EXPECT_LT(m.point.y, -6.5) << "below the first slab's top";
    EXPECT_EQ(run.broke[0], 1) << "the charge's fractures, adopted in the second frame";
    for (int s = 1; s < kStoreys; ++s) {
        EXPECT_EQ(run.fell[s], run.fell[1]) << "every storey above lost its support in the same frame";
        EXPECT_GT(run.broke[s], run.broke[s - 1]) << "storey " << s << " broke after the one beneath it";
    }
    EXPECT_GE(run.broke[kStoreys - 1] - run.broke[1], 60) << "the top broke over a second after storey 1";
    EXPECT_GT(run.impacts, run.accepted + kStoreys - 1) << "landings: impacts the charge did not make";
    EXPECT_EQ(run.staticObjects, 0);

    ImpactPolicy noCollisions;
    noCollisions.collisionImpulseThreshold = std::numeric_limits<double>::infinity();
    const TowerRun off = runTower(20000, noCollisions, frames);
    ASSERT_EQ(off.broke.size(), static_cast<std::size_t>(kStoreys));
    EXPECT_EQ(off.accepted, 5);
    EXPECT_EQ(off.impacts, 5) << "the charge's only";
    for (int s = 1; s < kStoreys; ++s) {
        EXPECT_EQ(off.broke[s], -1) << "storey " << s << " fell and did not break";
        EXPECT_EQ(off.fell[s], run.fell[s]);
    }
    std::printf("storeys broke in frames");
    for (int s = 0; s < kStoreys; ++s)
        std::printf(" %d", run.broke[s]);
    std::printf(" (fell in %d), impacts %lld\n", run.fell[1], run.impacts);
}
