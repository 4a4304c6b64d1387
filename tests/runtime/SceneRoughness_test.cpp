// The roughness of a scene object's cuts: its world.cfg roughness field over its material's preset, or the
// loader's fracture parameters.
#include <gtest/gtest.h>

#include "ToyPhysics.hpp"
#include "rubble/fracture/Roughness.hpp"
#include "rubble/io/SceneConfig.hpp"
#include "rubble/runtime/DestructionRuntime.hpp"
#include "rubble/runtime/SceneLoader.hpp"

namespace rubble {
namespace {

/// The roughness of every object of the scene's object lines, loaded with materialRoughness as given.
std::vector<Roughness> loadedRoughness(bool materialRoughness) {
    const Result<SceneConfig> scene =
        parseSceneConfigText("a;b;c;d;e;f\n;;0;-15;0;100;10;100;0\n;;0;20;0;1;1;1;1\n"
                             ";;0;0;0;1;1;1;0\n"
                             ";;3;0;0;1;1;1;0;glass;0.2\n"
                             ";;6;0;0;1;1;1;0;steel\n"
                             ";;9;0;0;1;1;1;0;stone;flat\n",
                             "world.cfg");
    EXPECT_TRUE(scene) << scene.error().message;
    test::ToyPhysics engine;
    DestructionRuntime runtime(engine, DestructionRuntime::Config{});
    SceneLoadOptions options;
    options.loadVehicle = false;
    options.materialRoughness = materialRoughness;
    options.fracture.roughness.seed = 7;
    options.fracture.roughness.maxTrianglesPerPiece = 500;
    const LoadedScene loaded = loadScene(*scene, runtime, options);
    std::vector<Roughness> out;
    for (ObjectId id : loaded.objects)
        out.push_back(runtime.world().object(id)->fracture.roughness);
    return out;
}

TEST(SceneRoughness, MaterialPresetsAndTheRoughnessFieldSetTheCuts) {
    const std::vector<Roughness> r = loadedRoughness(true);
    ASSERT_EQ(r.size(), 4u);
    // No material: concrete's preset, with the loader's seed and budget.
    EXPECT_EQ(r[0].amplitude, roughnessPreset("concrete").amplitude);
    EXPECT_EQ(r[0].hurst, roughnessPreset("concrete").hurst);
    EXPECT_EQ(r[0].seed, 7u);
    EXPECT_EQ(r[0].maxTrianglesPerPiece, 500);
    // glass with the amplitude set by hand keeps glass's Hurst exponent.
    EXPECT_EQ(r[1].amplitude, 0.2);
    EXPECT_EQ(r[1].hurst, roughnessPreset("glass").hurst);
    EXPECT_FALSE(r[2].active()); // steel's preset is flat
    EXPECT_FALSE(r[3].active()); // stone, but the field says flat
}

TEST(SceneRoughness, WithoutMaterialRoughnessOnlyTheFieldMakesCutsRough) {
    const std::vector<Roughness> r = loadedRoughness(false);
    ASSERT_EQ(r.size(), 4u);
    EXPECT_FALSE(r[0].active());
    EXPECT_EQ(r[1].amplitude, 0.2);
    EXPECT_FALSE(r[2].active());
    EXPECT_FALSE(r[3].active());
}

} // namespace
} // namespace rubble
