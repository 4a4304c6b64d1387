#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include <nlohmann/json.hpp>

#include "TestSupport.hpp"
#include "io/FileBytes.hpp"
#include "rubble/geometry/MassProperties.hpp"
#include "rubble/io/MeshIO.hpp"

using namespace rubble;

namespace {

std::string slurp(const std::filesystem::path& p) {
    return io::readFileBytes(p).value();
}

std::string decodeBase64(const std::string& text) {
    std::string out;
    std::uint32_t acc = 0;
    int bits = 0;
    for (char c : text) {
        const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        const char* at = std::strchr(table, c);
        if (c == '=' || at == nullptr || c == '\0')
            break;
        acc = acc << 6 | static_cast<std::uint32_t>(at - table);
        bits += 6;
        if (bits >= 8) {
            bits -= 8;
            out += static_cast<char>((acc >> bits) & 0xFF);
        }
    }
    return out;
}

// The floats of accessor `a` (which must be tightly packed floats).
std::vector<float> floats(const nlohmann::json& doc, const std::string& buffer, int a) {
    const auto& acc = doc["accessors"][a];
    const auto& view = doc["bufferViews"][acc["bufferView"].get<int>()];
    const std::size_t n = view["byteLength"].get<std::size_t>() / sizeof(float);
    std::vector<float> v(n);
    std::memcpy(v.data(), buffer.data() + view["byteOffset"].get<std::size_t>(), n * sizeof(float));
    return v;
}

// A box whose upper half of triangles are cut faces, with flat normals and some UVs.
Mesh boxWithInterior(const Vec3& lo, const Vec3& hi) {
    Mesh m = makeBox(lo, hi);
    m.computeFlatNormals();
    m.uvs.assign(3 * m.triangles.size(), Vec2f{0.25, 0.75});
    m.materials.assign(m.triangles.size(), 0);
    for (std::size_t t = 0; t < 4; ++t)
        m.materials[t] = kInteriorMaterial;
    return m;
}

} // namespace

TEST(GltfWriter, OneNodePerMeshAtItsOriginWithTwoMaterials) {
    const auto dir = test::tempDir("GltfWriter_nodes");
    const Mesh a = boxWithInterior({-1, -1, -1}, {1, 1, 1});
    const Mesh b = boxWithInterior({10, 0, 0}, {12, 4, 1});
    const Vec3 originB{11, 2, 0.5};
    const auto path = dir / "two.gltf";
    ASSERT_TRUE(writeGltf(path, {{"first", a, {0, 0, 0}}, {"second", b, originB}}).isOk());

    const nlohmann::json doc = nlohmann::json::parse(slurp(path));
    EXPECT_EQ(doc["asset"]["version"], "2.0");
    ASSERT_EQ(doc["nodes"].size(), 2u);
    EXPECT_EQ(doc["scenes"][0]["nodes"].size(), 2u);
    EXPECT_EQ(doc["nodes"][1]["name"], "second");
    EXPECT_EQ(doc["nodes"][1]["translation"], nlohmann::json({11.0, 2.0, 0.5}));
    ASSERT_EQ(doc["materials"].size(), 2u);
    EXPECT_EQ(doc["materials"][1]["name"], "interior");

    const std::string uri = doc["buffers"][0]["uri"];
    const std::string prefix = "data:application/octet-stream;base64,";
    ASSERT_EQ(uri.rfind(prefix, 0), 0u);
    const std::string buffer = decodeBase64(uri.substr(prefix.size()));
    EXPECT_EQ(buffer.size(), doc["buffers"][0]["byteLength"].get<std::size_t>());

    // Node 1: surface (8 triangles) and interior (4 triangles) primitives; positions relative to the origin.
    const auto& prims = doc["meshes"][1]["primitives"];
    ASSERT_EQ(prims.size(), 2u);
    std::size_t indices[2] = {0, 0};
    for (const auto& p : prims) {
        const int material = p["material"];
        indices[material] += doc["accessors"][p["indices"].get<int>()]["count"].get<std::size_t>();
        const int pos = p["attributes"]["POSITION"];
        const std::vector<float> xyz = floats(doc, buffer, pos);
        for (std::size_t i = 0; i + 2 < xyz.size(); i += 3) {
            EXPECT_LE(std::abs(xyz[i]), 1.0f);
            EXPECT_LE(std::abs(xyz[i + 1]), 2.0f);
            EXPECT_LE(std::abs(xyz[i + 2]), 0.5f);
        }
        EXPECT_EQ(doc["accessors"][pos]["max"][1], 2.0);
        const std::vector<float> n = floats(doc, buffer, p["attributes"]["NORMAL"]);
        for (std::size_t i = 0; i + 2 < n.size(); i += 3)
            EXPECT_NEAR(n[i] * n[i] + n[i + 1] * n[i + 1] + n[i + 2] * n[i + 2], 1.0, 1e-6);
        const std::vector<float> uv = floats(doc, buffer, p["attributes"]["TEXCOORD_0"]);
        for (std::size_t i = 0; i + 1 < uv.size(); i += 2) {
            EXPECT_EQ(uv[i], 0.25f);
            EXPECT_EQ(uv[i + 1], 0.25f); // V flipped: 1 − 0.75
        }
    }
    EXPECT_EQ(indices[0], 3u * 8);
    EXPECT_EQ(indices[1], 3u * 4);
}

TEST(GltfWriter, ReadsBackWithTheSameVolumeAndPlacement) {
    const auto dir = test::tempDir("GltfWriter_roundtrip");
    Mesh sphere = makeSphere({3, -2, 5}, 1.5, 24, 12);
    Mesh box = makeBox({-4, 0, 0}, {-2, 1, 3}); // no normals, no uvs, no materials
    const double volume = signedVolume(sphere) + signedVolume(box);
    const auto path = dir / "scene.gltf";
    ASSERT_TRUE(writeGltf(path, {{"sphere", sphere, computeMassProperties(sphere).centerOfMass},
                                 {"box", box, {-3, 0.5, 1.5}}})
                    .isOk());
    const auto back = readMesh(path); // Assimp applies the node translations
    ASSERT_TRUE(back.isOk()) << back.error().message;
    EXPECT_EQ(back->triangleCount(), sphere.triangleCount() + box.triangleCount());
    EXPECT_NEAR(signedVolume(back.value()), volume, 1e-5 * volume);
    const Aabb b = back->bounds();
    EXPECT_NEAR(b.lo.x, -4, 1e-5);
    EXPECT_NEAR(b.hi.x, 4.5, 1e-5);
    EXPECT_NEAR(b.hi.z, 6.5, 1e-5);
}

// Per-corner normals and texture coordinates come back through a glTF file (float there as here; V flipped
// on the way out and back) within a float step.
TEST(GltfWriter, ReadsBackNormalsAndTextureCoordinates) {
    const auto dir = test::tempDir("GltfWriter_attributes");
    Mesh m = makeSubdividedBox({-1, -0.5, -0.25}, {1, 0.5, 0.25}, 2);
    for (std::size_t t = 0; t < m.triangleCount(); ++t)
        for (const Vec3& p : m.corners(t)) {
            m.normals.emplace_back(normalized(normalized(m.triangleNormal(t)) + 0.3 * p));
            m.uvs.push_back({0.1 * p.x + 0.3, p.y / 3 + 0.25});
        }
    const auto path = dir / "box.gltf";
    ASSERT_TRUE(writeGltf(path, {{"box", m, {}}}).isOk());
    const auto back = readMesh(path);
    ASSERT_TRUE(back.isOk()) << back.error().message;
    ASSERT_EQ(back->triangleCount(), m.triangleCount());
    ASSERT_EQ(back->normals.size(), m.normals.size());
    ASSERT_EQ(back->uvs.size(), m.uvs.size());
    for (std::size_t i = 0; i < m.normals.size(); ++i) {
        EXPECT_LT(length(Vec3(back->normals[i]) - m.normals[i]), 1e-6) << "corner " << i;
        EXPECT_NEAR(back->uvs[i].x, m.uvs[i].x, 1e-6) << "corner " << i;
        EXPECT_NEAR(back->uvs[i].y, m.uvs[i].y, 1e-6) << "corner " << i;
    }
}

TEST(GltfWriter, SameInputGivesIdenticalBytes) {
    const auto dir = test::tempDir("GltfWriter_determinism");
    const Mesh m = boxWithInterior({0, 0, 0}, {1, 2, 3});
    ASSERT_TRUE(writeGltf(dir / "a.gltf", {{"m", m, {0.5, 1, 1.5}}}).isOk());
    ASSERT_TRUE(writeGltf(dir / "b.gltf", {{"m", m, {0.5, 1, 1.5}}}).isOk());
    EXPECT_EQ(slurp(dir / "a.gltf"), slurp(dir / "b.gltf"));
    // Shared corners are welded: a flat-shaded box has 24 distinct (position, normal) corners.
    const nlohmann::json doc = nlohmann::json::parse(slurp(dir / "a.gltf"));
    std::size_t vertices = 0;
    for (const auto& p : doc["meshes"][0]["primitives"])
        vertices += doc["accessors"][p["attributes"]["POSITION"].get<int>()]["count"].get<std::size_t>();
    EXPECT_EQ(vertices, 24u);
}

TEST(GltfWriter, RejectsEmptyInputAndNamesTheFile) {
    const auto dir = test::tempDir("GltfWriter_errors");
    const auto empty = writeGltf(dir / "e.gltf", {{"nothing", Mesh{}, {0, 0, 0}}});
    EXPECT_EQ(empty.error().code, ErrorCode::InvalidInput);
    EXPECT_NE(empty.message().find("e.gltf"), std::string::npos);
    EXPECT_EQ(writeGltf(dir / "n.gltf", {}).error().code, ErrorCode::InvalidInput);
    EXPECT_FALSE(std::filesystem::exists(dir / "e.gltf"));
    const auto io = writeGltf(dir / "no" / "such" / "dir.gltf", {{"box", makeBox({0, 0, 0}, {1, 1, 1}), {}}});
    EXPECT_EQ(io.error().code, ErrorCode::IoError);
    EXPECT_NE(io.message().find("dir.gltf"), std::string::npos);
}
