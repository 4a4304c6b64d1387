// A scene loads MODEL.parts.json beside its model (made by `rubble decompose MODEL -o ...`) instead of
// decomposing at load: scaled with the model, and only when it was made for that very mesh.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "TestSupport.hpp"
#include "ToyPhysics.hpp"
#include "geometry/FormerMeshHash.hpp"
#include "rubble/io/DecompositionFile.hpp"
#include "rubble/io/MeshIO.hpp"
#include "rubble/io/SceneConfig.hpp"
#include "rubble/runtime/DestructionRuntime.hpp"
#include "rubble/runtime/SceneLoader.hpp"

namespace rubble {
namespace {

/// The convex parts the world holds for the scene's single object, after loading world.cfg in dir.
std::vector<ConvexPolytope> loadedParts(const std::filesystem::path& dir,
                                        std::vector<std::string>& warnings) {
    const Result<SceneConfig> scene = parseSceneConfigText(
        "a;b;c;d;e;f\n;;0;-15;0;100;10;100;0\n;;0;20;0;1;1;1;1\nblock.obj;;0;1;0;2;1;1;0\n", "world.cfg",
        dir.string());
    EXPECT_TRUE(scene) << scene.error().message;
    test::ToyPhysics engine;
    DestructionRuntime runtime(engine, DestructionRuntime::Config{});
    SceneLoadOptions options;
    options.loadVehicle = false;
    const LoadedScene loaded = loadScene(*scene, runtime, options);
    warnings = loaded.warnings;
    EXPECT_EQ(loaded.objects.size(), 1u);
    return loaded.objects.empty() ? std::vector<ConvexPolytope>{}
                                  : runtime.world().object(loaded.objects[0])->convexParts;
}

TEST(SceneDecompositionFile, PartsBesideTheModelAreLoadedScaledInsteadOfDecomposing) {
    const auto dir = test::tempDir("scene_parts_file");
    const Mesh block = makeBox({-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5});
    ASSERT_TRUE(writeObj(dir / "block.obj", block));
    const Mesh read = readMesh(dir / "block.obj").value();
    // Two halves: a decomposition at load would give one box, so two parts prove the file was used.
    DecompositionFile file{read.hash(),
                           1.0,
                           {ConvexPolytope::fromAabb({{-0.5, -0.5, -0.5}, {0, 0.5, 0.5}}),
                            ConvexPolytope::fromAabb({{0, -0.5, -0.5}, {0.5, 0.5, 0.5}})}};
    ASSERT_TRUE(writeDecompositionFile(decompositionPathFor(dir / "block.obj"), file));
    std::vector<std::string> warnings;
    const auto parts = loadedParts(dir, warnings);
    ASSERT_EQ(parts.size(), 2u) << test::joinLines(warnings);
    double volume = 0;
    Aabb bounds;
    for (const ConvexPolytope& p : parts) {
        volume += p.volume();
        bounds.extend(p.bounds());
    }
    EXPECT_NEAR(volume, 2.0, 1e-12); // scaled by (2, 1, 1)
    EXPECT_NEAR(bounds.size().x, 2.0, 1e-12);
    // Made for another mesh: a warning, and the object is decomposed at load (one box).
    file.meshHash ^= 1;
    ASSERT_TRUE(writeDecompositionFile(decompositionPathFor(dir / "block.obj"), file));
    const auto fresh = loadedParts(dir, warnings);
    EXPECT_EQ(fresh.size(), 1u);
    bool warned = false;
    for (const std::string& w : warnings)
        warned = warned || w.find("another mesh") != std::string::npos;
    EXPECT_TRUE(warned) << test::joinLines(warnings);
}

// A version-1 file names its mesh by Mesh::hash's former FNV-1a: still loaded, and still refused for
// another mesh.
TEST(SceneDecompositionFile, AVersionOneFileIsCheckedByTheFormerHash) {
    const auto dir = test::tempDir("scene_parts_file_v1");
    const Mesh block = makeBox({-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5});
    ASSERT_TRUE(writeObj(dir / "block.obj", block));
    const Mesh read = readMesh(dir / "block.obj").value();
    ASSERT_NE(detail::formerMeshHash(read), read.hash());
    const auto path = decompositionPathFor(dir / "block.obj");
    auto writeVersionOne = [&](std::uint64_t hash) {
        DecompositionFile file{hash,
                               1.0,
                               {ConvexPolytope::fromAabb({{-0.5, -0.5, -0.5}, {0, 0.5, 0.5}}),
                                ConvexPolytope::fromAabb({{0, -0.5, -0.5}, {0.5, 0.5, 0.5}})}};
        ASSERT_TRUE(writeDecompositionFile(path, file));
        std::stringstream text;
        text << std::ifstream(path).rdbuf();
        std::string json = text.str();
        const auto at = json.find("\"version\":2");
        ASSERT_NE(at, std::string::npos) << json;
        json.replace(at, 11, "\"version\":1");
        test::writeFile(path, json);
    };
    writeVersionOne(detail::formerMeshHash(read));
    std::vector<std::string> warnings;
    EXPECT_EQ(loadedParts(dir, warnings).size(), 2u) << test::joinLines(warnings);
    EXPECT_FALSE(test::mentions(warnings, "parts.json")) << test::joinLines(warnings);
    writeVersionOne(detail::formerMeshHash(read) ^ 1);
    EXPECT_EQ(loadedParts(dir, warnings).size(), 1u);
    EXPECT_TRUE(test::mentions(warnings, "another mesh")) << test::joinLines(warnings);
}

} // namespace
} // namespace rubble
