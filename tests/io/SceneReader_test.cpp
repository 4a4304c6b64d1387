#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "TestSupport.hpp"
#include "io/FileBytes.hpp"
#include "rubble/geometry/MassProperties.hpp"
#include "rubble/io/MeshIO.hpp"
#include "rubble/io/SceneIO.hpp"

using namespace rubble;
using rubble::test::tempDir;
using rubble::test::writeFile;

namespace {

std::string slurp(const std::filesystem::path& p) {
    return io::readFileBytes(p).value();
}

// A box with a source material (id 0, "stone") on its first half of triangles and cut faces on the rest.
Mesh materialBox(const Vec3& lo, const Vec3& hi) {
    Mesh m = makeBox(lo, hi);
    m.materials.assign(m.triangles.size(), 0);
    for (std::size_t t = 6; t < m.triangles.size(); ++t)
        m.materials[t] = kInteriorMaterial;
    m.materialNames = {"stone"};
    return m;
}

AssetMaterial stone(const std::filesystem::path& image) {
    AssetMaterial m;
    m.name = "stone";
    m.baseColor = {0.5, 0.4, 0.3};
    m.maps.push_back({"map_Kd", "-s 2 2 1", image, "", ""});
    m.statements = {"Ns 10", "illum 2"};
    return m;
}

const AssetMaterial* find(const AssetScene& scene, const std::string& name) {
    for (const AssetMaterial& m : scene.materials)
        if (m.name == name)
            return &m;
    return nullptr;
}

} // namespace

TEST(SceneReader, CollisionNamesFollowGodotAndUnreal) {
    EXPECT_TRUE(isCollisionName("piece_000_hull_00-convcolonly"));
    EXPECT_TRUE(isCollisionName("Wall-COLONLY"));
    EXPECT_TRUE(isCollisionName("UCX_piece_000_01"));
    EXPECT_FALSE(isCollisionName("piece_000"));
    EXPECT_FALSE(isCollisionName("convcolonly_piece"));
    EXPECT_FALSE(isCollisionName("myUCX_thing"));
}

// glTF: each piece node comes back as an object with its -convcolonly children as collision parts, in scene
// coordinates; the texture is copied next to the file and read back; readMesh leaves the parts out.
TEST(SceneReader, GltfPiecesComeBackWithCollisionPartsAndTextures) {
    const auto dir = tempDir("scene_gltf");
    const auto image = writeFile(dir / "src" / "stone.png", "not really a png, but bytes to copy");
    const Mesh a = materialBox({0, 0, 0}, {1, 2, 1});
    const Mesh b = materialBox({1, 0, 0}, {2, 1, 3});
    const std::vector<Mesh> partsA = {makeBox({0, 0, 0}, {1, 1, 1}), makeBox({0, 1, 0}, {1, 2, 1})};
    std::vector<GltfNode> nodes;
    nodes.emplace_back("piece_000", a, computeMassProperties(a).centerOfMass, partsA,
                       R"({"rubble":{"level":1}})");
    nodes.emplace_back("piece_001", b, Vec3{1.5, 0.5, 1.5}, std::vector<Mesh>{b});
    const auto path = dir / "out" / "pieces.gltf";
    std::filesystem::create_directories(path.parent_path());
    ASSERT_TRUE(writeGltf(path, nodes, {stone(image)}, R"({"rubble":{"bonds":[]}})").isOk());

    const nlohmann::json doc = nlohmann::json::parse(slurp(path));
    EXPECT_EQ(doc["nodes"][0]["extras"]["rubble"]["level"], 1);
    EXPECT_TRUE(doc["scenes"][0]["extras"]["rubble"]["bonds"].is_array());
    EXPECT_EQ(doc["scenes"][0]["nodes"].size(), 2u);
    EXPECT_EQ(doc["images"][0]["uri"], "textures/stone.png");
    EXPECT_EQ(slurp(dir / "out" / "textures" / "stone.png"), slurp(image));

    auto scene = readScene(path);
    ASSERT_TRUE(scene.isOk()) << scene.error().message;
    ASSERT_EQ(scene->objects.size(), 2u);
    EXPECT_EQ(scene->objects[0].name, "piece_000");
    EXPECT_EQ(scene->objects[1].name, "piece_001");
    ASSERT_EQ(scene->objects[0].collision.size(), 2u);
    ASSERT_EQ(scene->objects[1].collision.size(), 1u);
    EXPECT_NEAR(signedVolume(scene->objects[0].mesh), 2.0, 1e-5);
    EXPECT_NEAR(signedVolume(scene->objects[1].mesh), 3.0, 1e-5);
    EXPECT_NEAR(signedVolume(scene->objects[0].collision[1]), 1.0, 1e-5);
    EXPECT_NEAR(scene->objects[0].collision[1].bounds().lo.y, 1.0, 1e-6); // scene coordinates
    // Cut faces are the interior material again; the source material keeps its name, colour and texture.
    const Mesh& m = scene->objects[0].mesh;
    std::size_t interior = 0;
    for (std::size_t t = 0; t < m.triangleCount(); ++t)
        interior += m.material(t) == kInteriorMaterial;
    EXPECT_EQ(interior, 6u);
    const AssetMaterial* s = find(*scene, "stone");
    ASSERT_NE(s, nullptr);
    ASSERT_EQ(s->maps.size(), 1u);
    EXPECT_EQ(slurp(s->maps[0].file), slurp(image));

    // The merged reader takes the render meshes only: collision children would make it non-manifold.
    auto merged = readMesh(path);
    ASSERT_TRUE(merged.isOk());
    EXPECT_NEAR(signedVolume(merged.value()), 5.0, 1e-5);
}

TEST(SceneReader, GltfNodeTreeKeepsParents) {
    const auto dir = tempDir("scene_tree");
    const Mesh whole = makeBox({0, 0, 0}, {2, 1, 1});
    const Mesh left = makeBox({0, 0, 0}, {1, 1, 1});
    const Mesh right = makeBox({1, 0, 0}, {2, 1, 1});
    std::vector<GltfNode> nodes;
    nodes.emplace_back("chunk", whole, Vec3{1, 0.5, 0.5});
    nodes.emplace_back("chunk_000", left, Vec3{0.5, 0.5, 0.5}, std::vector<Mesh>{left}, "", 0);
    nodes.emplace_back("chunk_001", right, Vec3{1.5, 0.5, 0.5}, std::vector<Mesh>{right}, "", 0);
    const auto path = dir / "tree.gltf";
    ASSERT_TRUE(writeGltf(path, nodes).isOk());
    const nlohmann::json doc = nlohmann::json::parse(slurp(path));
    EXPECT_EQ(doc["scenes"][0]["nodes"], nlohmann::json::array({0}));
    EXPECT_EQ(doc["nodes"][1]["translation"],
              nlohmann::json::array({-0.5, 0.0, 0.0})); // relative to its parent

    auto scene = readScene(path);
    ASSERT_TRUE(scene.isOk()) << scene.error().message;
    ASSERT_EQ(scene->objects.size(), 3u);
    EXPECT_EQ(scene->objects[0].parent, -1);
    EXPECT_EQ(scene->objects[1].parent, 0);
    EXPECT_EQ(scene->objects[2].parent, 0);
    EXPECT_NEAR(scene->objects[2].mesh.bounds().lo.x, 1.0, 1e-6);
    EXPECT_EQ(scene->objects[2].collision.size(), 1u);

    GltfNode orphan("orphan", left, Vec3{});
    orphan.parent = 5;
    const Status bad = writeGltf(dir / "bad.gltf", {orphan});
    EXPECT_FALSE(bad.isOk());
    EXPECT_NE(bad.message().find("orphan"), std::string::npos);
}

// OBJ: UCX_<object>_<n> objects are the object's collision parts; the MTL keeps the source statements and
// maps with their options, the image copied into textures/.
TEST(SceneReader, ObjUcxPartsAndMtlMapsRoundTrip) {
    const auto dir = tempDir("scene_obj");
    const auto image = writeFile(dir / "src" / "stone.png", "image bytes");
    const Mesh piece = materialBox({0, 0, 0}, {1, 2, 1});
    ObjWriteOptions options;
    options.objectName = "piece_000";
    options.collision = {makeBox({0, 0, 0}, {1, 1, 1}), makeBox({0, 1, 0}, {1, 2, 1})};
    options.materials = std::vector<AssetMaterial>{stone(image)};
    const auto path = dir / "out" / "piece_000.obj";
    std::filesystem::create_directories(path.parent_path());
    ASSERT_TRUE(writeObj(path, piece, options).isOk());
    const std::string obj = slurp(path);
    EXPECT_NE(obj.find("o UCX_piece_000_00\n"), std::string::npos);
    EXPECT_NE(obj.find("o UCX_piece_000_01\n"), std::string::npos);
    const std::string mtl = slurp(dir / "out" / "piece_000.mtl");
    EXPECT_NE(mtl.find("map_Kd -s 2 2 1 textures/stone.png\n"), std::string::npos) << mtl;
    EXPECT_NE(mtl.find("Ns 10\n"), std::string::npos);
    EXPECT_NE(mtl.find("newmtl interior\n"), std::string::npos);
    EXPECT_EQ(slurp(dir / "out" / "textures" / "stone.png"), "image bytes");

    auto scene = readScene(path);
    ASSERT_TRUE(scene.isOk()) << scene.error().message;
    EXPECT_TRUE(scene->warnings.empty()) << scene->warnings.front();
    ASSERT_EQ(scene->objects.size(), 1u);
    EXPECT_EQ(scene->objects[0].name, "piece_000");
    ASSERT_EQ(scene->objects[0].collision.size(), 2u);
    EXPECT_DOUBLE_EQ(signedVolume(scene->objects[0].mesh), 2.0);
    EXPECT_DOUBLE_EQ(signedVolume(scene->objects[0].collision[1]), 1.0);
    const AssetMaterial* s = find(*scene, "stone");
    ASSERT_NE(s, nullptr);
    EXPECT_EQ(s->baseColor, (Vec3{0.5, 0.4, 0.3}));
    ASSERT_EQ(s->maps.size(), 1u);
    EXPECT_EQ(s->maps[0].options, "-s 2 2 1");
    EXPECT_EQ(s->maps[0].file, (dir / "out" / "textures" / "stone.png").lexically_normal());

    ObjWriteOptions unnamed;
    unnamed.collision = options.collision;
    EXPECT_FALSE(writeObj(dir / "bad.obj", piece, unnamed).isOk());
}

TEST(SceneReader, MissingImagesAreReferencedNotFatal) {
    const auto dir = tempDir("scene_missing");
    const Mesh piece = materialBox({0, 0, 0}, {1, 1, 1});
    ObjWriteOptions options;
    options.objectName = "p";
    options.materials = std::vector<AssetMaterial>{stone(dir / "elsewhere" / "gone.png")};
    std::filesystem::create_directories(dir / "out");
    ASSERT_TRUE(writeObj(dir / "out" / "p.obj", piece, options).isOk());
    EXPECT_NE(slurp(dir / "out" / "p.mtl").find("map_Kd -s 2 2 1 ../elsewhere/gone.png\n"),
              std::string::npos);
    auto scene = readScene(dir / "out" / "p.obj");
    ASSERT_TRUE(scene.isOk());
    ASSERT_EQ(scene->warnings.size(), 1u);
    EXPECT_NE(scene->warnings[0].find("gone.png"), std::string::npos);
}

TEST(SceneReader, ParseMtlNamesLineOfErrors) {
    auto ok =
        parseMtl("# c\nnewmtl a\nKd 0.1 0.2 0.3\nmap_Kd -o 0.5 0.5 0 -clamp on my image.png\nbump n.png\n",
                 "m.mtl", "/tex");
    ASSERT_TRUE(ok.isOk()) << ok.error().message;
    ASSERT_EQ(ok->size(), 1u);
    EXPECT_EQ((*ok)[0].baseColor, (Vec3{0.1, 0.2, 0.3}));
    ASSERT_EQ((*ok)[0].maps.size(), 2u);
    EXPECT_EQ((*ok)[0].maps[0].options, "-o 0.5 0.5 0 -clamp on");
    EXPECT_EQ((*ok)[0].maps[0].file, std::filesystem::path("/tex/my image.png"));
    EXPECT_EQ((*ok)[0].maps[1].slot, "bump");

    auto early = parseMtl("Kd 1 1 1\n", "m.mtl", ".");
    ASSERT_FALSE(early.isOk());
    EXPECT_NE(early.error().message.find("m.mtl:1"), std::string::npos);
    auto noFile = parseMtl("newmtl a\n\nmap_Kd -s 1 1 1\n", "m.mtl", ".");
    ASSERT_FALSE(noFile.isOk());
    EXPECT_NE(noFile.error().message.find("m.mtl:3"), std::string::npos);
}

// An OBJ without `o` statements is one object even when `g` groups split it.
TEST(SceneReader, ObjGroupsWithoutObjectsAreOneObject) {
    const auto dir = tempDir("scene_groups");
    const auto path = writeFile(dir / "g.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\ng a\nf 1 3 2\nf 1 2 4\n"
                                               "g b\nf 1 4 3\nf 2 3 4\n");
    auto scene = readScene(path);
    ASSERT_TRUE(scene.isOk()) << scene.error().message;
    ASSERT_EQ(scene->objects.size(), 1u);
    EXPECT_EQ(scene->objects[0].name, "g");
    EXPECT_EQ(scene->objects[0].mesh.triangleCount(), 4u);
}

// Round 3: `map_Kd /etc/passwd` ended up in OUT/textures/. An image named by an absolute path is not used (a
// warning), so writing the scene copies nothing from elsewhere; relative paths ("../textures/") still work.
TEST(SceneReader, ImagesNamedByAbsolutePathsAreNotUsed) {
    const auto dir = std::filesystem::absolute(tempDir("scene_absolute"));
    const auto secret = writeFile(dir / "outside" / "secret.txt", "secret");
    writeFile(dir / "textures" / "ok.png", "image bytes");
    std::string cube = slurp(test::sourceDir() / "tests" / "data" / "meshes" / "cube.obj");
    cube.insert(cube.rfind("\nf ") + 1, "usemtl b\n"); // the last face in material b
    const auto obj = writeFile(dir / "model" / "m.obj", "mtllib m.mtl\nusemtl a\n" + cube);
    writeFile(dir / "model" / "m.mtl",
              "newmtl a\nKd 1 0 0\nmap_Kd " + secret.string() + "\nnewmtl b\nmap_Kd ../textures/ok.png\n");
    auto scene = readScene(obj);
    ASSERT_TRUE(scene.isOk()) << scene.error().message;
    ASSERT_EQ(scene->warnings.size(), 1u) << test::joinLines(scene->warnings);
    EXPECT_EQ(scene->warnings[0], "material 'a': image " + secret.string() +
                                      " is named by an absolute path: not used (images are copied only from "
                                      "paths relative to the model's folder)");
    const AssetMaterial* a = find(*scene, "a");
    const AssetMaterial* b = find(*scene, "b");
    ASSERT_TRUE(a && b);
    EXPECT_TRUE(a->maps.empty());
    ASSERT_EQ(b->maps.size(), 1u);
    EXPECT_EQ(b->maps[0].file, (dir / "textures" / "ok.png").lexically_normal());

    ObjWriteOptions options;
    options.objectName = "m";
    options.materials = scene->materials;
    std::filesystem::create_directories(dir / "out");
    ASSERT_TRUE(writeObj(dir / "out" / "m.obj", scene->objects[0].mesh, options).isOk());
    std::vector<std::string> copied;
    for (const auto& e : std::filesystem::directory_iterator(dir / "out" / "textures"))
        copied.push_back(e.path().filename().string());
    EXPECT_EQ(copied, std::vector<std::string>{"ok.png"});
}

// Round 3: a malformed .mtl made check and fracture exit 2 while decompose (which reads no materials) exited
// 0; like a missing .mtl it is now a warning naming its line, and the geometry is read.
TEST(SceneReader, AMalformedMtlIsAWarningLikeAMissingOne) {
    const auto dir = tempDir("scene_bad_mtl");
    const std::string cube = slurp(test::sourceDir() / "tests" / "data" / "meshes" / "cube.obj");
    const auto obj = writeFile(dir / "m.obj", "mtllib bad.mtl\n" + cube);
    writeFile(dir / "bad.mtl", "Kd 1 1 1\n");
    auto scene = readScene(obj);
    ASSERT_TRUE(scene.isOk()) << scene.error().message;
    ASSERT_EQ(scene->warnings.size(), 1u);
    EXPECT_NE(scene->warnings[0].find("bad.mtl:1: 'Kd' before the first newmtl (its materials are not used)"),
              std::string::npos)
        << scene->warnings[0];
    EXPECT_TRUE(scene->materials.empty());
    EXPECT_EQ(scene->objects.at(0).mesh.triangleCount(), 12u);
}
