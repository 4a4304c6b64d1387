#include <gtest/gtest.h>

#include "TestSupport.hpp"
#include "rubble/io/SceneConfig.hpp"

using namespace rubble;

namespace {
const char* kSky = "top.jpg;bottom.jpg;left.jpg;right.jpg;front.jpg;back.jpg\n";
const char* kGround = ";grid.jpg;0;-15;0;1000;10;1000;0\n";
const char* kVehicle = "fighter.3ds;;0;20;0;0.5;0.5;0.5;100\n";

std::string errorOf(const std::string& text) {
    const auto r = parseSceneConfigText(text, "world.cfg");
    EXPECT_FALSE(r.isOk()) << text;
    return r.isOk() ? std::string() : r.error().message;
}
} // namespace

TEST(SceneConfig, ThesisExampleParses) {
    const std::string text = std::string(kSky) + kGround + kVehicle +
                             "building.obj;;-20;-11;-30;2;2;2;500\npyramid.obj;;50;-11;-100;5;10;5;800\n\n\n";
    const auto r = parseSceneConfigText(text, "world.cfg");
    ASSERT_TRUE(r.isOk()) << r.error().message;
    EXPECT_EQ(r->skybox[0], "top.jpg");
    EXPECT_EQ(r->skybox[5], "back.jpg");
    EXPECT_EQ(r->ground.texture, "grid.jpg");
    EXPECT_TRUE(r->ground.model.empty());
    EXPECT_EQ(r->ground.scale, (Vec3{1000, 10, 1000}));
    EXPECT_TRUE(r->ground.isStatic());
    EXPECT_EQ(r->vehicle.model, "fighter.3ds");
    EXPECT_EQ(r->vehicle.line, 3u);
    EXPECT_EQ(r->vehicle.mass, 100);
    ASSERT_EQ(r->objects.size(), 2u);
    EXPECT_EQ(r->objects[1].model, "pyramid.obj");
    EXPECT_EQ(r->objects[1].position, (Vec3{50, -11, -100}));
    EXPECT_EQ(r->objects[1].scale, (Vec3{5, 10, 5}));
    EXPECT_EQ(r->objects[1].mass, 800);
    EXPECT_EQ(r->objects[1].line, 5u);
    EXPECT_FALSE(r->objects[1].isStatic());
}

TEST(SceneConfig, OptionalMaterialField) {
    const std::string text =
        std::string(kSky) + kGround + kVehicle +
        "slab.obj;;0;0;0;1;1;1;0;glass\ncolumn.obj;;0;0;0;1;1;1;0\nbeam.obj;;0;0;0;1;1;1;0; steel ;\n";
    const auto r = parseSceneConfigText(text, "world.cfg");
    ASSERT_TRUE(r.isOk()) << r.error().message;
    ASSERT_EQ(r->objects.size(), 3u);
    EXPECT_EQ(r->objects[0].material, "glass");
    EXPECT_EQ(r->objects[1].material, "");
    EXPECT_EQ(r->objects[2].material, "steel");
    EXPECT_EQ(r->ground.material, "");
}

TEST(SceneConfig, OptionalRoughnessField) {
    const std::string text = std::string(kSky) + kGround + kVehicle +
                             "a.obj;;0;0;0;1;1;1;0;brick;0.2\nb.obj;;0;0;0;1;1;1;0;;flat\n"
                             "c.obj;;0;0;0;1;1;1;0;wood\nd.obj;;0;0;0;1;1;1;0;stone; 0 ;\n";
    const auto r = parseSceneConfigText(text, "world.cfg");
    ASSERT_TRUE(r.isOk()) << r.error().message;
    ASSERT_EQ(r->objects.size(), 4u);
    EXPECT_EQ(r->objects[0].material, "brick");
    EXPECT_EQ(r->objects[0].roughness, 0.2);
    EXPECT_EQ(r->objects[1].material, "");
    EXPECT_EQ(r->objects[1].roughness, 0.0);
    EXPECT_FALSE(r->objects[2].roughness.has_value());
    EXPECT_EQ(r->objects[3].roughness, 0.0);
    const std::string head = std::string(kSky) + kGround + kVehicle;
    const std::string expected =
        "world.cfg:4: field 'roughness' (11th): expected 'flat' or a finite number in [0, 1] "
        "(the amplitude relative to the cell size), got ";
    EXPECT_EQ(errorOf(head + "a.obj;;0;0;0;1;1;1;0;brick;rough\n"), expected + "'rough'");
    EXPECT_EQ(errorOf(head + "a.obj;;0;0;0;1;1;1;0;brick;1.5\n"), expected + "'1.5'");
    EXPECT_EQ(errorOf(head + "a.obj;;0;0;0;1;1;1;0;brick;-0.1\n"), expected + "'-0.1'");
    EXPECT_EQ(errorOf(head + "a.obj;;0;0;0;1;1;1;0;brick;nan\n"), expected + "'nan'");
    EXPECT_EQ(errorOf(head + "a.obj;;0;0;0;1;1;1;0;bricks;0.1\n"),
              "world.cfg:4: field 'material' (10th): unknown material 'bricks'; expected one of concrete, "
              "brick, stone, wood, glass, steel");
}

TEST(SceneConfig, MissingFilesAreWarningsNotErrors) {
    const auto dir = test::tempDir("SceneConfig_missing");
    test::writeFile(dir / "building.obj", "v 0 0 0\n");
    test::writeFile(dir / "top.jpg", "x");
    const std::string text = std::string(kSky) + kGround + kVehicle + "building.obj;wall.png;1;2;3;1;1;1;0\n";
    test::writeFile(dir / "world.cfg", text);
    const auto r = parseSceneConfig(dir / "world.cfg");
    ASSERT_TRUE(r.isOk()) << r.error().message;
    ASSERT_EQ(r->objects.size(), 1u);
    EXPECT_TRUE(r->objects[0].modelFound);
    EXPECT_EQ(r->objects[0].modelPath, dir / "building.obj");
    EXPECT_FALSE(r->objects[0].textureFound);
    EXPECT_FALSE(r->vehicle.modelFound);
    const std::string name = (dir / "world.cfg").string();
    std::vector<std::string> messages;
    for (const SceneWarning& w : r->warnings)
        messages.push_back(w.message);
    // 5 skybox images, the ground texture, the vehicle model, the object's texture.
    ASSERT_EQ(messages.size(), 8u);
    EXPECT_EQ(messages[0], name + ":1: skybox image 'bottom.jpg' not found");
    EXPECT_EQ(messages[5], name + ":2: texture 'grid.jpg' not found");
    EXPECT_EQ(messages[6], name + ":3: model 'fighter.3ds' not found");
    EXPECT_EQ(r->warnings[6].line, 3u);
    EXPECT_EQ(messages[7], name + ":4: texture 'wall.png' not found");
}

TEST(SceneConfig, MalformedLinesNameFileLineAndField) {
    const std::string head = std::string(kSky) + kGround + kVehicle;
    EXPECT_EQ(errorOf(head + "building.obj;;1;2;3;1;abc;1;5\n"),
              "world.cfg:4: field 'sy' (7th): expected a number, got 'abc'");
    EXPECT_EQ(errorOf(head + "building.obj;;1;2;3;1;1;1\n"),
              "world.cfg:4: expected 9 to 11 fields for the object "
              "(model;texture;x;y;z;sx;sy;sz;mass[;material[;roughness]]), got 8");
    EXPECT_EQ(errorOf(head + "building.obj;;1;2;3;1;1;1;5;wood;0.1;6\n"),
              "world.cfg:4: expected 9 to 11 fields for the object "
              "(model;texture;x;y;z;sx;sy;sz;mass[;material[;roughness]]), got 12");
    EXPECT_EQ(
        errorOf(head + "building.obj;;1;2;3;1;1;1;5;6\n"),
        "world.cfg:4: field 'material' (10th): unknown material '6'; expected one of concrete, brick, stone, "
        "wood, glass, steel");
    EXPECT_EQ(
        errorOf(head + "building.obj;;1;2;3;1;1;1;5;Wood\n"),
        "world.cfg:4: field 'material' (10th): unknown material 'Wood'; expected one of concrete, brick, "
        "stone, wood, glass, steel");
    EXPECT_EQ(errorOf(head + "building.obj;;1;2;3;1;1;1;-5\n"),
              "world.cfg:4: field 'mass' (9th): mass must not be negative, got '-5'");
    EXPECT_EQ(errorOf(head + "building.obj;;1;2;3;0;1;1;5\n"),
              "world.cfg:4: field 'sx' (6th): scale must not be 0");
    EXPECT_EQ(errorOf(head + "building.obj;;nan;2;3;1;1;1;5\n"),
              "world.cfg:4: field 'x' (3rd): expected a finite number, got 'nan'");
    EXPECT_EQ(errorOf(head + "building.obj;;1e999;2;3;1;1;1;5\n"),
              "world.cfg:4: field 'x' (3rd): expected a finite number, got '1e999'");
    EXPECT_EQ(errorOf(head + "building.obj;;;2;3;1;1;1;5\n"),
              "world.cfg:4: field 'x' (3rd): expected a number, got ''");
    EXPECT_EQ(errorOf("a;b;c\n"), "world.cfg:1: expected 6 skybox images separated by ';' (top, bottom, "
                                  "left, right, front, back), got 3 "
                                  "fields");
    EXPECT_EQ(errorOf("a;b;c;;e;f\n"), "world.cfg:1: skybox image 4 (right) is empty");
    EXPECT_EQ(errorOf(std::string(kSky) + "\n\n;grid.jpg;0;-15;0;1000;10\n"),
              "world.cfg:4: expected 9 to 11 fields for the ground "
              "(model;texture;x;y;z;sx;sy;sz;mass[;material[;roughness]]), got 7");
    EXPECT_EQ(errorOf(""),
              "world.cfg: missing the skybox line (line 1); a scene file needs a skybox, a ground and a "
              "vehicle line");
    EXPECT_EQ(errorOf(std::string(kSky) + kGround), "world.cfg: missing the vehicle line (line 3); a scene "
                                                    "file needs a skybox, a ground and a vehicle line");
    EXPECT_EQ(errorOf(head + std::string("a;;1;2;3;1;1;1;\x01\n")),
              "world.cfg:4: field 'mass' (9th): expected a number, got '\\x01'");
}

TEST(SceneConfig, CommentsCrlfBlankLinesSpacesAndTrailingSemicolon) {
    const std::string text = "\xEF\xBB\xBF# my scene\r\n\r\n"
                             "top.jpg;bottom.jpg;left.jpg;right.jpg;front.jpg;back.jpg\r\n"
                             "  ;grid.jpg; 0 ;-15;0;1000;10;1000;0  # the ground\r\n"
                             "fighter.3ds;;0;20;0;0.5;0.5;0.5;+100;\r\n"
                             "\r\n   \r\n"
                             "building.obj;;-20;-11;-30;2;2;2;5e2\r\n\r\n";
    const auto r = parseSceneConfigText(text, "crlf.cfg");
    ASSERT_TRUE(r.isOk()) << r.error().message;
    EXPECT_EQ(r->ground.line, 4u);
    EXPECT_EQ(r->vehicle.mass, 100);
    ASSERT_EQ(r->objects.size(), 1u);
    EXPECT_EQ(r->objects[0].line, 8u);
    EXPECT_EQ(r->objects[0].mass, 500);
    EXPECT_EQ(r->objects[0].model, "building.obj");
}

TEST(SceneConfig, RandomTextNeverCrashes) {
    std::uint64_t s = 1;
    const std::string alphabet = "0123456789;;;.-e \n\n#abc\r\x01";
    for (int i = 0; i < 2000; ++i) {
        std::string text(static_cast<std::size_t>(s % 400), ' ');
        for (char& c : text) {
            s = s * 6364136223846793005ull + 1442695040888963407ull;
            c = alphabet[(s >> 33) % alphabet.size()];
        }
        const auto r = parseSceneConfigText(text, "fuzz.cfg");
        if (!r.isOk()) {
            EXPECT_EQ(r.error().message.rfind("fuzz.cfg", 0), 0u);
        }
    }
}

TEST(SceneConfig, SeedSceneFilesParse) {
    RUBBLE_REQUIRE_SEED_MEDIA(media);
    for (const char* name : {"world.cfg", "performance_test.cfg", "cube_test.cfg"}) {
        const auto r = parseSceneConfig(media / name);
        ASSERT_TRUE(r.isOk()) << name << ": " << r.error().message;
        EXPECT_EQ(r->skybox[0], "skybox/top.jpg") << name;
        for (const auto& p : r->skyboxPaths)
            EXPECT_TRUE(std::filesystem::is_regular_file(p)) << p;
        EXPECT_EQ(r->ground.texture, "grid.jpg");
        EXPECT_EQ(r->vehicle.model, "fighter.3ds");
        EXPECT_FALSE(r->vehicle.modelFound); // the seed has no fighter.3ds: a warning, not an error
        bool warned = false;
        for (const SceneWarning& w : r->warnings)
            warned = warned || (w.line == 3 &&
                                w.message.find(":3: model 'fighter.3ds' not found") != std::string::npos);
        EXPECT_TRUE(warned) << name;
    }
    const auto world = parseSceneConfig(media / "world.cfg");
    ASSERT_TRUE(world.isOk());
    ASSERT_EQ(world->objects.size(), 12u);
    EXPECT_EQ(world->objects[0].model, "building.obj");
    EXPECT_TRUE(world->objects[0].modelFound);
    EXPECT_EQ(world->objects[0].position, (Vec3{-20, -11, -30}));
    EXPECT_EQ(world->objects[0].scale, (Vec3{2, 2, 2}));
    EXPECT_EQ(world->objects[0].mass, 500);
    EXPECT_EQ(world->objects[11].model, "ship.obj");
    EXPECT_EQ(world->objects[11].scale, (Vec3{0.3, 0.3, 0.3}));
    for (const SceneObject& o : world->objects)
        EXPECT_TRUE(o.modelFound) << o.model;
    const auto cube = parseSceneConfig(media / "cube_test.cfg");
    ASSERT_TRUE(cube.isOk());
    ASSERT_EQ(cube->objects.size(), 1u);
    EXPECT_EQ(cube->objects[0].model, "cube_12.obj");
    EXPECT_EQ(cube->vehicle.mass, 0);
    const auto perf = parseSceneConfig(media / "performance_test.cfg");
    ASSERT_TRUE(perf.isOk());
    EXPECT_EQ(perf->objects.size(), 12u);
}
