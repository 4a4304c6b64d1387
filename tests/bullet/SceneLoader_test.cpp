// Scene loading into the runtime on the Bullet binding: ground, objects, stand-ins for missing models, static
// objects.
#include <gtest/gtest.h>

#include <algorithm>

#include "TestSupport.hpp"
#include "rubble/bullet/BulletBinding.hpp"
#include "rubble/io/SceneConfig.hpp"
#include "rubble/runtime/SceneLoader.hpp"

using namespace rubble;
using namespace rubble::bullet;

namespace {

struct World {
    World() {
        DestructionRuntime::Config rc;
        rc.world.workers = 1;
        physics = std::make_unique<PhysicsWorld>();
        binding = std::make_unique<BulletBinding>(*physics);
        runtime = std::make_unique<DestructionRuntime>(*binding, rc);
    }
    ~World() {
        runtime.reset();
        binding.reset();
    }
    std::unique_ptr<PhysicsWorld> physics;
    std::unique_ptr<BulletBinding> binding;
    std::unique_ptr<DestructionRuntime> runtime;
};

bool anyContains(const std::vector<std::string>& v, const std::string& s) {
    return std::any_of(v.begin(), v.end(),
                       [&](const std::string& w) { return w.find(s) != std::string::npos; });
}

} // namespace

TEST(SceneLoader, MissingModelGivesAWarningAndAStandInBox) {
    const std::string text = "a.jpg;b.jpg;c.jpg;d.jpg;e.jpg;f.jpg\n"
                             ";grid.jpg;0;-15;0;1000;10;1000;0\n"
                             "nothing.3ds;;0;20;0;0.5;0.5;0.5;100\n"
                             "no_such_model.obj;;3;-8;1;2;4;6;50\n"
                             "cube_12.obj;;-5;-9;0;1;1;1;0\n";
    Result<SceneConfig> scene =
        parseSceneConfigText(text, "test.cfg", test::sourceDir() / "assets" / "models");
    ASSERT_TRUE(scene) << scene.error().message;
    World w;
    const LoadedScene loaded = loadScene(*scene, *w.runtime);
    ASSERT_EQ(loaded.objects.size(), 2u);
    EXPECT_TRUE(anyContains(loaded.warnings, "no_such_model.obj"));
    EXPECT_TRUE(anyContains(loaded.warnings, "stand-in"));
    ASSERT_NE(loaded.ground, 0u);
    EXPECT_NEAR(loaded.groundTop, -10, 1e-9);
    ASSERT_NE(loaded.vehicle, 0u); // a stand-in too
    // the stand-in is a 2 × 4 × 6 box at (3, -8, 1) with mass 50
    const BodyRecord* standIn = w.runtime->bodyOf(loaded.objects[0]);
    ASSERT_NE(standIn, nullptr);
    EXPECT_NEAR(standIn->volume, 48, 1e-6);
    EXPECT_NEAR(standIn->mass, 50, 1e-6);
    const Vec3 c = w.runtime->motion(standIn->id).transform.translation;
    EXPECT_NEAR(c.x, 3, 1e-5);
    EXPECT_NEAR(c.y, -8, 1e-5);
    EXPECT_NEAR(c.z, 1, 1e-5);
    // the model that exists: a static, destructible object
    const BodyRecord* cube = w.runtime->bodyOf(loaded.objects[1]);
    ASSERT_NE(cube, nullptr);
    EXPECT_EQ(cube->motion, BodyMotionState::Static);
    EXPECT_NEAR(cube->volume, 8, 1e-6);
    EXPECT_NEAR(loaded.initialVolume, 56, 1e-6);
    for (int i = 0; i < 30; ++i)
        w.runtime->stepFrame();
}

TEST(SceneLoader, LoadsTheProjectsScenes) {
    for (const char* name : {"cube_test.cfg", "performance_test.cfg"}) {
        const auto path = test::sourceDir() / "assets" / "scenes" / name;
        if (!std::filesystem::exists(path))
            continue;
        Result<SceneConfig> scene = parseSceneConfig(path);
        ASSERT_TRUE(scene) << scene.error().message;
        World w;
        SceneLoadOptions options;
        options.loadVehicle = false;
        const LoadedScene loaded = loadScene(*scene, *w.runtime, options);
        EXPECT_EQ(loaded.objects.size(), scene->objects.size()) << name;
        EXPECT_GT(loaded.initialVolume, 0) << name;
    }
}

TEST(SceneLoader, SeedScenesLoadAsTheyAreWithWarningsForMissingFiles) {
    RUBBLE_REQUIRE_SEED_MEDIA(media);
    for (const char* name : {"world.cfg", "cube_test.cfg", "performance_test.cfg"}) {
        Result<SceneConfig> scene = parseSceneConfig(media / name);
        ASSERT_TRUE(scene) << name << ": " << scene.error().message;
        World w;
        const LoadedScene loaded = loadScene(*scene, *w.runtime);
        EXPECT_EQ(loaded.objects.size(), scene->objects.size()) << name;
        // the missing vehicle model and ground texture are named with file and line
        EXPECT_TRUE(anyContains(loaded.warnings, std::string(name) + ":3")) << name;
        EXPECT_TRUE(anyContains(loaded.warnings, "fighter.3ds")) << name;
        EXPECT_TRUE(anyContains(loaded.warnings, "grid.jpg")) << name;
        EXPECT_NE(loaded.vehicle, 0u) << name; // a stand-in
        for (int i = 0; i < 10; ++i)
            w.runtime->stepFrame();
    }
}

TEST(SceneLoader, PrepareMeshHookSeesEveryObjectAndIndicesMapToTheScene) {
    const std::string text = "a.jpg;b.jpg;c.jpg;d.jpg;e.jpg;f.jpg\n"
                             ";grid.jpg;0;-15;0;1000;10;1000;0\n"
                             "nothing.3ds;;0;20;0;0.5;0.5;0.5;100\n"
                             "cube_12.obj;;-5;-9;0;1;1;1;0\n"
                             "no_such_model.obj;;3;-8;1;2;4;6;50\n";
    Result<SceneConfig> scene =
        parseSceneConfigText(text, "test.cfg", test::sourceDir() / "assets" / "models");
    ASSERT_TRUE(scene) << scene.error().message;
    World w;
    SceneLoadOptions options;
    int calls = 0;
    options.prepareMesh = [&](Mesh& m) {
        ++calls;
        m.uvs.assign(m.triangles.size() * 3, Vec2f{0.25, 0.5});
    };
    const LoadedScene loaded = loadScene(*scene, *w.runtime, options);
    EXPECT_EQ(calls, 2);
    ASSERT_EQ(loaded.sceneIndex.size(), loaded.objects.size());
    ASSERT_EQ(loaded.objects.size(), 2u);
    EXPECT_EQ(loaded.sceneIndex[0], 0u);
    EXPECT_EQ(loaded.sceneIndex[1], 1u);
    for (ObjectId id : loaded.objects) {
        const ObjectState* st = w.runtime->world().object(id);
        ASSERT_NE(st, nullptr);
        ASSERT_FALSE(st->mesh.uvs.empty());
        EXPECT_EQ(st->mesh.uvs.front().x, 0.25);
    }
}

// Issue #20, hostile scenes: moving bodies placed inside each other would cost one unbounded physics step
// (600 buildings on one spot took 6.6 s and 1.4 GB), so only the first of a pile loads; objects that merely
// touch (a box standing on another) all load.
TEST(SceneLoader, APileOfInterpenetratingMovingObjectsLoadsOnlyItsFirst) {
    std::string text = "a.jpg;b.jpg;c.jpg;d.jpg;e.jpg;f.jpg\n"
                       ";grid.jpg;0;-15;0;1000;10;1000;0\n"
                       "nothing.3ds;;0;20;0;0.5;0.5;0.5;100\n";
    for (int i = 0; i < 50; ++i)
        text += "building.obj;;0;-10;0;2;2;2;500\n";
    text += "cube_12.obj;;40;-9;0;1;1;1;100\n"  // a 2 m cube standing on the ground
            "cube_12.obj;;40;-7;0;1;1;1;100\n"  // and one standing on it
            "cube_12.obj;;40;-6.5;0;1;1;1;0\n"; // a static one inside the second: refused too
    Result<SceneConfig> scene =
        parseSceneConfigText(text, "pile.cfg", test::sourceDir() / "assets" / "models");
    ASSERT_TRUE(scene) << scene.error().message;
    World w;
    const LoadedScene loaded = loadScene(*scene, *w.runtime);
    ASSERT_EQ(loaded.objects.size(), 3u);
    EXPECT_EQ(loaded.sceneIndex, (std::vector<std::size_t>{0, 50, 51}));
    int refused = 0;
    for (const std::string& warning : loaded.warnings)
        refused += warning.find("not loaded") != std::string::npos ? 1 : 0;
    EXPECT_EQ(refused, 50);
    EXPECT_TRUE(anyContains(loaded.warnings, "line 5: 'building.obj' lies inside the object of line 4"));
    for (int i = 0; i < 10; ++i)
        w.runtime->stepFrame();
}
