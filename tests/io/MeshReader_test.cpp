#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>

#include <sys/stat.h>

#include "TestSupport.hpp"
#include "rubble/core/Random.hpp"
#include "rubble/geometry/MassProperties.hpp"
#include "rubble/geometry/MeshCheck.hpp"
#include "rubble/io/MeshIO.hpp"

using namespace rubble;

namespace {
const std::filesystem::path kData = test::sourceDir() / "tests/data/meshes";

std::string problemsOf(const MeshReport& r) {
    std::string s;
    for (const std::string& p : r.problems)
        s += p + "\n";
    return s;
}

std::string base64(const std::string& bytes) {
    static const char* tbl = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    std::size_t i = 0;
    for (; i + 2 < bytes.size(); i += 3) {
        const auto n = static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[i]) << 16 |
                                                  static_cast<unsigned char>(bytes[i + 1]) << 8 |
                                                  static_cast<unsigned char>(bytes[i + 2]));
        for (int k = 3; k >= 0; --k)
            out += tbl[(n >> (6 * k)) & 63];
    }
    if (i + 1 == bytes.size()) {
        const std::uint32_t n = static_cast<unsigned char>(bytes[i]) << 16;
        out += std::string{tbl[n >> 18 & 63], tbl[n >> 12 & 63], '=', '='};
    } else if (i + 2 == bytes.size()) {
        const std::uint32_t n =
            static_cast<unsigned char>(bytes[i]) << 16 | static_cast<unsigned char>(bytes[i + 1]) << 8;
        out += std::string{tbl[n >> 18 & 63], tbl[n >> 12 & 63], tbl[n >> 6 & 63], '='};
    }
    return out;
}

template <class T>
void put(std::string& s, T v) {
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    s.append(b, sizeof(T));
}

// A tetrahedron as glTF buffer data: 4 float3 positions then 12 uint16 indices.
std::string tetraBuffer() {
    std::string b;
    const float p[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (const auto& v : p)
        for (float c : v)
            put(b, c);
    const std::uint16_t idx[12] = {0, 2, 1, 0, 1, 3, 1, 2, 3, 2, 0, 3};
    for (std::uint16_t i : idx)
        put(b, i);
    return b;
}

std::string gltfJson(const std::string& bufferEntry, unsigned positionCount = 4) {
    return R"({"asset":{"version":"2.0"},"scenes":[{"nodes":[0]}],"scene":0,"nodes":[{"mesh":0}],)"
           R"("meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],)"
           R"("buffers":[)" +
           bufferEntry +
           R"(],"bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":48},{"buffer":0,"byteOffset":48,"byteLength":24}],)"
           R"("accessors":[{"bufferView":0,"componentType":5126,"count":)" +
           std::to_string(positionCount) +
           R"(,"type":"VEC3","min":[0,0,0],"max":[1,1,1]},{"bufferView":1,"componentType":5123,"count":12,"type":"SCALAR"}]})";
}

void expectValidTetra(const Result<Mesh>& r) {
    ASSERT_TRUE(r.isOk()) << r.error().message;
    EXPECT_EQ(r->vertexCount(), 4u);
    EXPECT_EQ(r->triangleCount(), 4u);
    const MeshReport rep = checkMesh(r.value());
    EXPECT_TRUE(rep.valid()) << problemsOf(rep);
    EXPECT_NEAR(rep.volume, 1.0 / 6.0, 1e-7);
}

Error errorOf(const std::filesystem::path& p) {
    const auto r = readMesh(p);
    EXPECT_FALSE(r.isOk()) << p;
    return r.isOk() ? Error{} : r.error();
}
} // namespace

TEST(MeshReader, ObjStlPlyOffFixturesAreValidSolids) {
    expectValidTetra(readMesh(kData / "tetra.obj"));
    expectValidTetra(readMesh(kData / "tetra.stl")); // STL repeats corners per facet: welded exactly
    expectValidTetra(readMesh(kData / "tetra.3ds"));
    for (const char* name : {"cube.obj", "cube.ply", "cube_binary.ply", "cube.off"}) {
        const auto r = readMesh(kData / name);
        ASSERT_TRUE(r.isOk()) << name << ": " << r.error().message;
        EXPECT_EQ(r->vertexCount(), 8u) << name;
        EXPECT_EQ(r->triangleCount(), 12u) << name;
        const MeshReport rep = checkMesh(r.value());
        EXPECT_TRUE(rep.valid()) << name << "\n" << problemsOf(rep);
        EXPECT_NEAR(rep.volume, 1.0, 1e-12) << name;
    }
}

TEST(MeshReader, GltfWithDataUriAndGlbAreRead) {
    const auto dir = test::tempDir("MeshReader_gltf");
    const std::string buf = tetraBuffer();
    const std::string entry =
        R"({"byteLength":72,"uri":"data:application/octet-stream;base64,)" + base64(buf) + R"("})";
    test::writeFile(dir / "tetra.gltf", gltfJson(entry));
    expectValidTetra(readMesh(dir / "tetra.gltf"));

    // The same as an external .bin buffer.
    test::writeFile(dir / "tetra.bin", buf);
    test::writeFile(dir / "external.gltf", gltfJson(R"({"byteLength":72,"uri":"tetra.bin"})"));
    expectValidTetra(readMesh(dir / "external.gltf"));

    // GLB: header, JSON chunk (padded with spaces), BIN chunk.
    std::string json = gltfJson(R"({"byteLength":72})");
    while (json.size() % 4)
        json += ' ';
    std::string glb = "glTF";
    put(glb, std::uint32_t{2});
    put(glb, static_cast<std::uint32_t>(12 + 8 + json.size() + 8 + buf.size()));
    put(glb, static_cast<std::uint32_t>(json.size()));
    put(glb, std::uint32_t{0x4E4F534A});
    glb += json;
    put(glb, static_cast<std::uint32_t>(buf.size()));
    put(glb, std::uint32_t{0x004E4942});
    glb += buf;
    test::writeFile(dir / "tetra.glb", glb);
    expectValidTetra(readMesh(dir / "tetra.glb"));
}

TEST(MeshReader, HugeSizeClaimsAreRejectedBeforeAssimp) {
    Error e = errorOf(kData / "huge_claim.stl");
    EXPECT_EQ(e.code, ErrorCode::ParseError);
    EXPECT_NE(
        e.message.find("huge_claim.stl: binary STL header claims 2000000000 triangles (100000000084 bytes) "
                       "but the file has 134 bytes"),
        std::string::npos)
        << e.message;
    e = errorOf(kData / "huge_claim.ply");
    EXPECT_EQ(e.code, ErrorCode::ParseError);
    EXPECT_NE(e.message.find("huge_claim.ply:4: header claims 2000000000 'vertex' elements"),
              std::string::npos)
        << e.message;
    e = errorOf(kData / "huge_claim.off");
    EXPECT_NE(e.message.find("huge_claim.off:2: header claims 2000000000 vertices"), std::string::npos)
        << e.message;

    const auto dir = test::tempDir("MeshReader_claims");
    // ASCII PLY claiming more faces than it could hold.
    test::writeFile(dir / "ascii.ply",
                    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                    "property float z\nelement face 4000000000\nproperty list uchar int "
                    "vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
    e = errorOf(dir / "ascii.ply");
    EXPECT_NE(e.message.find("ascii.ply:7: header claims 4000000000 'face' elements"), std::string::npos)
        << e.message;
    // glTF accessor claiming two billion positions in a 48-byte view.
    const std::string entry =
        R"({"byteLength":72,"uri":"data:application/octet-stream;base64,)" + base64(tetraBuffer()) + R"("})";
    test::writeFile(dir / "huge.gltf", gltfJson(entry, 2000000000u));
    e = errorOf(dir / "huge.gltf");
    EXPECT_NE(e.message.find("huge.gltf: accessor 0 claims 2000000000 elements"), std::string::npos)
        << e.message;
    // glTF buffer longer than its data.
    test::writeFile(dir / "short.gltf", gltfJson(R"({"byteLength":7200000000,"uri":"data:;base64,AAAA"})"));
    e = errorOf(dir / "short.gltf");
    EXPECT_NE(e.message.find("short.gltf: buffer 0 claims 7200000000 bytes but only 3 are available"),
              std::string::npos)
        << e.message;
    // GLB whose header claims more bytes than the file has.
    std::string glb = "glTF";
    put(glb, std::uint32_t{2});
    put(glb, std::uint32_t{2000000000});
    put(glb, std::uint32_t{0});
    put(glb, std::uint32_t{0x4E4F534A});
    test::writeFile(dir / "huge.glb", glb);
    e = errorOf(dir / "huge.glb");
    EXPECT_NE(e.message.find("huge.glb: GLB header claims 2000000000 bytes but the file has 20 bytes"),
              std::string::npos)
        << e.message;
    // 3DS main chunk claiming 2 GB.
    std::string tds;
    put(tds, std::uint16_t{0x4D4D});
    put(tds, std::uint32_t{2000000000});
    tds += std::string(32, '\0');
    test::writeFile(dir / "huge.3ds", tds);
    e = errorOf(dir / "huge.3ds");
    EXPECT_NE(e.message.find("huge.3ds: 3DS main chunk claims 2000000000 bytes but the file has 38 bytes"),
              std::string::npos)
        << e.message;
}

TEST(MeshReader, UnknownExtensionMissingAndEmptyFiles) {
    const auto dir = test::tempDir("MeshReader_misc");
    test::writeFile(dir / "model.xyz", "whatever");
    Error e = errorOf(dir / "model.xyz");
    EXPECT_EQ(e.code, ErrorCode::Unsupported);
    EXPECT_NE(
        e.message.find("model.xyz: unsupported mesh format '.xyz' (supported: .obj, .off, .stl, .ply, .3ds, "
                       ".gltf, .glb)"),
        std::string::npos)
        << e.message;
    e = errorOf(dir / "missing.stl");
    EXPECT_EQ(e.code, ErrorCode::IoError);
    EXPECT_NE(e.message.find("missing.stl: cannot open"), std::string::npos) << e.message;
    for (const char* name :
         {"empty.obj", "empty.stl", "empty.ply", "empty.off", "empty.3ds", "empty.gltf", "empty.glb"}) {
        test::writeFile(dir / name, "");
        e = errorOf(dir / name);
        EXPECT_EQ(e.code, ErrorCode::ParseError) << name;
        EXPECT_NE(e.message.find(std::string(name) + ": no triangles"), std::string::npos) << e.message;
    }
    // Upper-case extensions are accepted.
    std::filesystem::copy_file(kData / "tetra.stl", dir / "TETRA.STL");
    expectValidTetra(readMesh(dir / "TETRA.STL"));
}

TEST(MeshReader, RandomBytesInEveryFormatGiveErrorsNotCrashes) {
    const auto dir = test::tempDir("MeshReader_random");
    Rng rng(77);
    int errors = 0;
    for (const std::string ext : {".obj", ".stl", ".ply", ".off", ".3ds", ".gltf", ".glb"}) {
        for (int i = 0; i < 25; ++i) {
            std::string bytes(1 + rng.below(2000), '\0');
            for (char& c : bytes)
                c = static_cast<char>(rng.below(256));
            if (i % 5 == 1 && ext == ".ply")
                bytes =
                    "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nend_header\n" +
                    bytes;
            if (i % 5 == 2 && ext == ".stl")
                bytes = "solid " + bytes;
            if (i % 5 == 3 && ext == ".off")
                bytes = "OFF\n3 1 0\n" + bytes;
            if (i % 5 == 4 && ext == ".3ds") {
                std::string h;
                put(h, std::uint16_t{0x4D4D});
                put(h, static_cast<std::uint32_t>(bytes.size() + 6));
                bytes = h + bytes;
            }
            const auto path = dir / ("random" + std::to_string(i) + ext);
            test::writeFile(path, bytes);
            const auto r = readMesh(path);
            if (!r.isOk()) {
                ++errors;
                EXPECT_NE(r.error().message.find(path.filename().string()), std::string::npos)
                    << r.error().message;
            } else {
                (void)checkMesh(r.value());
            }
        }
    }
    EXPECT_GT(errors, 150);
}

TEST(MeshReader, BinaryStlWithTrailingBytesAndAsciiStl) {
    const auto dir = test::tempDir("MeshReader_stl");
    std::string bin;
    {
        std::ifstream in(kData / "tetra.stl", std::ios::binary);
        bin.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }
    test::writeFile(dir / "padded.stl", bin + std::string(10, '\0'));
    expectValidTetra(readMesh(dir / "padded.stl"));
    std::string ascii = "solid tetra\n";
    const float p[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    const int f[4][3] = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}};
    for (const auto& tri : f) {
        ascii += "facet normal 0 0 0\nouter loop\n";
        for (int k : tri)
            ascii += "vertex " + std::to_string(p[k][0]) + " " + std::to_string(p[k][1]) + " " +
                     std::to_string(p[k][2]) + "\n";
        ascii += "endloop\nendfacet\n";
    }
    ascii += "endsolid tetra\n";
    test::writeFile(dir / "ascii.stl", ascii);
    expectValidTetra(readMesh(dir / "ascii.stl"));
}

namespace {
// The tetra glTF with its single node replaced by `nodes` and `extras` added to the top level.
std::string gltfWithNodes(const std::string& nodes, const std::string& extras = "0") {
    const std::string entry =
        R"({"byteLength":72,"uri":"data:application/octet-stream;base64,)" + base64(tetraBuffer()) + R"("})";
    std::string json = gltfJson(entry);
    const std::string single = R"("nodes":[{"mesh":0}])";
    json.replace(json.find(single), single.size(), R"("nodes":)" + nodes);
    return R"({"extras":)" + extras + "," + json.substr(1);
}

// A chain of `depth` nodes, each the only child of the one before; the last holds the mesh.
std::string nodeChain(std::size_t depth) {
    std::string nodes = "[";
    for (std::size_t i = 0; i + 1 < depth; ++i)
        nodes += R"({"children":[)" + std::to_string(i + 1) + "]},";
    return nodes + R"({"mesh":0}])";
}
} // namespace

TEST(MeshReader, DeepGltfNestingIsRefusedBeforeAssimp) {
    // Assimp recursed once per level and crashed (SIGSEGV) on both of these.
    const auto dir = test::tempDir("MeshReader_deep_gltf");
    test::writeFile(dir / "chain.gltf", gltfWithNodes(nodeChain(20000)));
    Error e = errorOf(dir / "chain.gltf");
    EXPECT_EQ(e.code, ErrorCode::ParseError);
    EXPECT_EQ(e.message, (dir / "chain.gltf").string() +
                             ": the node hierarchy is more than 1024 levels deep (node 1024)");
    const std::size_t deep = 1000000;
    test::writeFile(dir / "extras.gltf",
                    gltfWithNodes(nodeChain(1), std::string(deep, '[') + std::string(deep, ']')));
    e = errorOf(dir / "extras.gltf");
    EXPECT_NE(e.message.find("extras.gltf: its JSON is nested more than 256 levels deep (at byte 265)"),
              std::string::npos)
        << e.message;
    // Brackets inside strings do not count.
    test::writeFile(dir / "strings.gltf",
                    gltfWithNodes(nodeChain(1), "\"" + std::string(1000, '[') + "\\\"\""));
    expectValidTetra(readMesh(dir / "strings.gltf"));
    // Up to the limits the files are read (the node transforms are identities).
    test::writeFile(dir / "chain1024.gltf", gltfWithNodes(nodeChain(1024)));
    expectValidTetra(readMesh(dir / "chain1024.gltf"));
    test::writeFile(dir / "extras250.gltf",
                    gltfWithNodes(nodeChain(1), std::string(250, '[') + std::string(250, ']')));
    expectValidTetra(readMesh(dir / "extras250.gltf"));
    // Cycles, shared children and children out of range (glTF nodes form disjoint trees).
    test::writeFile(dir / "cycle.gltf", gltfWithNodes(R"([{"mesh":0,"children":[1]},{"children":[0]}])"));
    EXPECT_NE(errorOf(dir / "cycle.gltf").message.find("is its own ancestor (a cycle)"), std::string::npos);
    test::writeFile(dir / "self.gltf", gltfWithNodes(R"([{"mesh":0,"children":[0]}])"));
    EXPECT_NE(errorOf(dir / "self.gltf").message.find("node 0 has more than one parent"), std::string::npos);
    test::writeFile(dir / "shared.gltf", gltfWithNodes(R"([{"children":[2]},{"children":[2]},{"mesh":0}])"));
    EXPECT_NE(errorOf(dir / "shared.gltf").message.find("node 2 has more than one parent"),
              std::string::npos);
    test::writeFile(dir / "range.gltf", gltfWithNodes(R"([{"mesh":0,"children":[7]}])"));
    EXPECT_NE(errorOf(dir / "range.gltf").message.find("node 0 has child 7 but there are only 1 nodes"),
              std::string::npos);
}

TEST(MeshReader, OnlyRegularFilesOfBoundedSizeAreRead) {
    // /dev/zero behind a mesh name was read until memory ran out, and a FIFO blocked forever.
    const auto dir = test::tempDir("MeshReader_special");
    std::filesystem::create_symlink("/dev/zero", dir / "zero.obj");
    Error e = errorOf(dir / "zero.obj");
    EXPECT_EQ(e.code, ErrorCode::IoError);
    EXPECT_EQ(e.message,
              (dir / "zero.obj").string() + ": cannot read: it is a character device, not a regular file");
    ASSERT_EQ(::mkfifo((dir / "pipe.stl").c_str(), 0600), 0);
    e = errorOf(dir / "pipe.stl"); // returns at once: the FIFO is never opened
    EXPECT_EQ(e.message, (dir / "pipe.stl").string() + ": cannot read: it is a FIFO, not a regular file");
    // A (sparse) file one byte over the 2 GiB limit.
    { std::ofstream big(dir / "big.off"); }
    std::filesystem::resize_file(dir / "big.off", (std::uint64_t{1} << 31) + 1);
    e = errorOf(dir / "big.off");
    EXPECT_EQ(e.message, (dir / "big.off").string() +
                             ": the file has 2147483649 bytes, more than the limit of 2147483648 bytes");
    // Symbolic links to regular files are fine.
    std::filesystem::create_symlink(kData / "tetra.stl", dir / "link.stl");
    expectValidTetra(readMesh(dir / "link.stl"));
}

TEST(MeshReader, BinaryStlCountsAreCheckedAndFloatsWidenedExactly) {
    const auto dir = test::tempDir("MeshReader_counts");
    std::string bin;
    {
        std::ifstream in(kData / "tetra.stl", std::ios::binary);
        bin.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    }
    // A binary STL whose header says 0 triangles but holds 4 was called "empty".
    std::string zero = bin;
    zero.replace(80, 4, std::string(4, '\0'));
    test::writeFile(dir / "zero.stl", zero);
    EXPECT_EQ(errorOf(dir / "zero.stl").message,
              (dir / "zero.stl").string() +
                  ": binary STL header claims 0 triangles but 200 bytes of facets (4 triangles) follow it");
    std::string more = bin;
    more[80] = 5;
    test::writeFile(dir / "more.stl", more);
    EXPECT_EQ(errorOf(dir / "more.stl").message,
              (dir / "more.stl").string() +
                  ": binary STL header claims 5 triangles (334 bytes) but the file has " +
                  std::to_string(bin.size()) + " bytes");
    // A corner at a float that is not a short decimal is kept exactly as the float.
    const float odd = 0.1f;
    std::string shifted = bin;
    for (int f = 0; f < 4; ++f)
        for (int c = 0; c < 3; ++c) {
            float x = 0;
            std::memcpy(&x, shifted.data() + 84 + 50 * f + 12 + 12 * c, 4);
            x += odd;
            std::memcpy(shifted.data() + 84 + 50 * f + 12 + 12 * c, &x, 4);
        }
    test::writeFile(dir / "shifted.stl", shifted);
    const auto m = readMesh(dir / "shifted.stl");
    ASSERT_TRUE(m.isOk()) << m.error().message;
    ASSERT_EQ(m->vertexCount(), 4u);
    EXPECT_EQ(m->bounds().lo.x, static_cast<double>(odd));
    EXPECT_EQ(m->bounds().hi.x, static_cast<double>(1.0f + odd));
}

namespace {
// The unit cube as binary PLY with double coordinates, a colour per vertex and quads; `big` writes
// big-endian.
std::string binaryPlyCube(bool big, int declaredFaces = 6,
                          const std::vector<std::vector<int>>& extraFaces = {}) {
    std::string ply = std::string("ply\nformat ") + (big ? "binary_big_endian" : "binary_little_endian") +
                      " 1.0\nelement vertex 8\nproperty double x\nproperty double y\nproperty double z\n"
                      "property uchar red\nelement face " +
                      std::to_string(declaredFaces) +
                      "\nproperty list uchar int vertex_indices\nend_header\n";
    auto put = [&](const void* p, std::size_t n) {
        const auto* c = static_cast<const char*>(p);
        for (std::size_t i = 0; i < n; ++i)
            ply += c[big ? n - 1 - i : i];
    };
    const double third = 1.0 / 3.0;
    const double v[8][3] = {{0, 0, 0},     {1, 0, 0},     {1, 1, 0},     {0, 1, 0},
                            {0, 0, third}, {1, 0, third}, {1, 1, third}, {0, 1, third}};
    for (const auto& p : v) {
        put(&p[0], 8);
        put(p + 1, 8);
        put(p + 2, 8);
        ply += '\xff';
    }
    std::vector<std::vector<int>> faces = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                                           {3, 7, 6, 2}, {0, 4, 7, 3}, {1, 2, 6, 5}};
    faces.insert(faces.end(), extraFaces.begin(), extraFaces.end());
    for (const auto& f : faces) {
        ply += static_cast<char>(f.size());
        for (int i : f) {
            const std::int32_t k = i;
            put(&k, 4);
        }
    }
    return ply;
}
} // namespace

TEST(MeshReader, BinaryPlyIsReadExactlyWithByteOffsets) {
    const auto dir = test::tempDir("MeshReader_binary_ply");
    auto read = [&](const std::string& file, const std::string& bytes) {
        test::writeFile(dir / file, bytes);
        return readMesh(dir / file);
    };
    for (bool big : {false, true}) {
        const auto cube = read(big ? "big.ply" : "little.ply", binaryPlyCube(big));
        ASSERT_TRUE(cube.isOk()) << cube.error().message;
        EXPECT_EQ(cube->vertexCount(), 8u);
        EXPECT_TRUE(checkMesh(cube.value()).valid());
        EXPECT_EQ(cube->bounds().hi.z, 1.0 / 3.0); // a double, not rounded to float
        EXPECT_NEAR(signedVolume(cube.value()), 1.0 / 3.0, 1e-15);
    }
    const std::string p = (dir / "").string();
    const std::size_t header = binaryPlyCube(false).find("end_header\n") + 11;
    const std::size_t faces = header + 8 * 25;
    // The header declares one face more than the file holds: the missing one is named, not dropped.
    EXPECT_EQ(read("short.ply", binaryPlyCube(false, 7)).error().message,
              p + "short.ply: byte " + std::to_string(faces + 6 * 17) +
                  ": the file ends after 6 of the 7 declared 'face' elements");
    EXPECT_EQ(read("more.ply", binaryPlyCube(false, 5)).error().message,
              p + "more.ply: byte " + std::to_string(faces + 5 * 17) +
                  ": 17 bytes after the declared elements (the header's counts do not match the file)");
    EXPECT_TRUE(read("newline.ply", binaryPlyCube(false) + "\n").isOk()) << "a final newline is fine";
    EXPECT_EQ(read("line.ply", binaryPlyCube(false, 7, {{0, 1}})).error().message,
              p + "line.ply: byte " + std::to_string(faces + 6 * 17) +
                  ": 'face' 6 has 2 corners; at least 3 are needed");
    EXPECT_EQ(read("index.ply", binaryPlyCube(false, 7, {{0, 1, 8}})).error().message,
              p + "index.ply: byte " + std::to_string(faces + 6 * 17) +
                  ": 'face' 6 refers to vertex 8 but there are 8 (PLY indices start at 0)");
    std::string cut = binaryPlyCube(false);
    cut.resize(cut.size() - 2);
    EXPECT_EQ(read("cut.ply", cut).error().message,
              p + "cut.ply: byte " + std::to_string(faces + 5 * 17) +
                  ": 'face' 5: the file ends inside 'vertex_indices' (truncated?)");
}

namespace {
// The unit cube as ASCII PLY: vertices with a colour, quads; `faces` replaces the face block when given.
std::string asciiPlyCube(const std::string& faces = "", int declaredFaces = 6) {
    std::string ply =
        "ply\nformat ascii 1.0\ncomment cube\nelement vertex 8\nproperty double x\nproperty double y\n"
        "property double z\nproperty uchar red\nelement face " +
        std::to_string(declaredFaces) + "\nproperty list uchar int vertex_indices\nend_header\n";
    for (const char* v : {"0 0 0", "1 0 0", "1 1 0", "0 1 0", "0 0 1", "1 0 1", "1 1 1", "0 1 1"})
        ply += std::string(v) + " 255\n";
    return ply +
           (faces.empty() ? "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 3 7 6 2\n4 0 4 7 3\n4 1 2 6 5\n" : faces);
}
} // namespace

TEST(MeshReader, AsciiPlyIsReadExactlyWithLineNumbers) {
    const auto dir = test::tempDir("MeshReader_ascii_ply");
    auto read = [&](const std::string& file, const std::string& text) {
        test::writeFile(dir / file, text);
        return readMesh(dir / file);
    };
    const auto cube = read("cube.ply", asciiPlyCube());
    ASSERT_TRUE(cube.isOk()) << cube.error().message;
    EXPECT_EQ(cube->vertexCount(), 8u);
    EXPECT_TRUE(checkMesh(cube.value()).valid());
    // Doubles exactly as written (Assimp rounded them to float).
    std::string exact = asciiPlyCube();
    exact.replace(exact.find("1 1 1 255"), 9, "10.2041 1 1 255");
    const auto e = read("exact.ply", exact);
    ASSERT_TRUE(e.isOk()) << e.error().message;
    bool found = false;
    for (const Vec3& p : e->positions)
        found = found || p.x == 10.2041;
    EXPECT_TRUE(found);
    // Vertices split per face (as exporters write them for normals or colours) are welded exactly.
    std::string split =
        "ply\nformat ascii 1.0\nelement vertex 12\nproperty float x\nproperty float y\n"
        "property float z\nelement face 4\nproperty list uchar uint vertex_index\nend_header\n";
    for (const char* v : {"0 0 0", "0 1 0", "1 0 0", "0 0 0", "1 0 0", "0 0 1", "1 0 0", "0 1 0", "0 0 1",
                          "0 1 0", "0 0 0", "0 0 1"})
        split += std::string(v) + "\n";
    split += "3 0 1 2\n3 3 4 5\n3 6 7 8\n3 9 10 11\n";
    expectValidTetra(read("split.ply", split));
    // Truncated lines, a file that ends early, counts that do not match: file:line messages (Assimp's text
    // had no line, or Assimp silently filled in a face).
    const std::string faces5 = "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 3 7 6 2\n4 0 4 7 3\n";
    const std::string p = dir.string() + "/";
    EXPECT_EQ(read("short.ply", asciiPlyCube(faces5)).error().message,
              p + "short.ply:24: the file ends after 5 of the 6 declared 'face' elements");
    EXPECT_EQ(read("trunc.ply", asciiPlyCube(faces5 + "4 1 2 6\n")).error().message,
              p + "trunc.ply:25: 'face' 5: the line ends before its properties do (4 numbers; truncated?)");
    EXPECT_EQ(
        read("long.ply", asciiPlyCube(faces5 + "4 1 2 6 5\n4 1 2 6 5\n")).error().message,
        p + "long.ply:26: unexpected '4' after the declared elements (the header's counts do not match the "
            "file)");
    std::string truncVertex = asciiPlyCube();
    truncVertex.replace(truncVertex.find("1 1 0 255"), 9, "1 1");
    EXPECT_EQ(read("tv.ply", truncVertex).error().message,
              p + "tv.ply:14: 'vertex' 2: the line ends before its properties do (2 numbers; truncated?)");
    EXPECT_EQ(read("idx.ply", asciiPlyCube(faces5 + "4 1 2 6 8\n")).error().message,
              p + "idx.ply:25: 'face' 5 refers to vertex 8 but there are 8 (PLY indices start at 0)");
    EXPECT_EQ(read("two.ply", asciiPlyCube(faces5 + "2 1 2\n")).error().message,
              p + "two.ply:25: 'face' 5 has 2 corners; at least 3 are needed");
    std::string bad = asciiPlyCube();
    bad.replace(bad.find("0 1 1 255"), 9, "0 1 abc 255");
    EXPECT_EQ(read("bad.ply", bad).error().message,
              p + "bad.ply:19: 'vertex' 7: expected a number for 'z', got 'abc'");
    bad.replace(bad.find("abc"), 3, "1e999");
    EXPECT_EQ(read("big.ply", bad).error().message,
              p + "big.ply:19: 'vertex' 7: value '1e999' for 'z' is out of range");
    EXPECT_EQ(read("extra.ply", asciiPlyCube(faces5 + "4 1 2 6 5 7\n")).error().message,
              p + "extra.ply:25: 'face' 5: 1 more numbers than its properties need");
    // A 12-gon face (Assimp's OFF importer dropped polygons over 9 corners; PLY polygons are kept whole
    // here).
    std::string prism =
        "ply\nformat ascii 1.0\nelement vertex 24\nproperty double x\nproperty double y\n"
        "property double z\nelement face 14\nproperty list uchar int vertex_indices\nend_header\n";
    for (int z = 0; z < 2; ++z)
        for (int i = 0; i < 12; ++i)
            prism += std::to_string(std::cos(i * 3.141592653589793 / 6)) + " " +
                     std::to_string(std::sin(i * 3.141592653589793 / 6)) + " " + std::to_string(z) + "\n";
    std::string bottom = "12", top = "12";
    for (int i = 0; i < 12; ++i) {
        bottom += " " + std::to_string(11 - i);
        top += " " + std::to_string(12 + i);
    }
    prism += bottom + "\n" + top + "\n";
    for (int i = 0; i < 12; ++i)
        prism += "4 " + std::to_string(i) + " " + std::to_string((i + 1) % 12) + " " +
                 std::to_string(12 + (i + 1) % 12) + " " + std::to_string(12 + i) + "\n";
    const auto pr = read("prism.ply", prism);
    ASSERT_TRUE(pr.isOk()) << pr.error().message;
    EXPECT_EQ(pr->triangleCount(), 2u * 10 + 24);
    EXPECT_TRUE(checkMesh(pr.value()).valid());
}

TEST(MeshReader, AsciiStlIsReadExactlyWithLineNumbers) {
    const auto dir = test::tempDir("MeshReader_ascii_stl");
    auto read = [&](const std::string& file, const std::string& text) {
        test::writeFile(dir / file, text);
        return readMesh(dir / file);
    };
    const char* p[4] = {"0 0 0", "10.2041 0 0", "0 1 0", "0 0 1"};
    const int f[4][3] = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}};
    std::string stl = "solid tetra\n";
    for (const auto& tri : f) {
        stl += "  facet normal 0 0 0\n    outer loop\n";
        for (int k : tri)
            stl += "      vertex " + std::string(p[k]) + "\n";
        stl += "    endloop\n  endfacet\n";
    }
    const std::string whole = stl + "endsolid tetra\n";
    const auto r = read("tetra.stl", whole);
    ASSERT_TRUE(r.isOk()) << r.error().message;
    EXPECT_EQ(r->vertexCount(), 4u);       // every corner repeated per facet, welded exactly
    EXPECT_EQ(r->positions[2].x, 10.2041); // Assimp rounded to float: 10.204099655...
    EXPECT_TRUE(checkMesh(r.value()).valid());
    // Upper-case keywords, two solids in one file.
    const auto two =
        read("two.stl", whole + "SOLID b\nFACET NORMAL 0 0 1\nOUTER LOOP\nVERTEX 5 5 5\nVERTEX 6 5 5\n"
                                "VERTEX 5 6 5\nENDLOOP\nENDFACET\nENDSOLID b\n");
    ASSERT_TRUE(two.isOk()) << two.error().message;
    EXPECT_EQ(two->triangleCount(), 5u);
    const std::string d = dir.string() + "/";
    EXPECT_EQ(read("trunc.stl", stl).error().message,
              d + "trunc.stl:29: the file ends without 'endsolid' (truncated?)");
    EXPECT_EQ(read("mid.stl", stl.substr(0, stl.rfind("      vertex"))).error().message,
              d + "mid.stl:26: the file ends inside a facet");
    std::string bad = whole;
    bad.replace(bad.find("vertex 0 1 0"), 12, "vertex 0 x 0");
    EXPECT_EQ(read("bad.stl", bad).error().message,
              d + "bad.stl:5: vertex: expected a number for y, got 'x'");
    bad = whole;
    bad.replace(bad.find("vertex 0 1 0"), 12, "vertex 0 1");
    EXPECT_EQ(read("short.stl", bad).error().message, d + "short.stl:5: vertex needs 3 numbers, got 2");
    bad = whole;
    bad.replace(bad.find("vertex 0 1 0"), 12, "vertex 0 1e999 0");
    EXPECT_EQ(read("huge.stl", bad).error().message,
              d + "huge.stl:5: vertex: value '1e999' for y is out of range");
    EXPECT_EQ(read("two_corners.stl",
                   "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\n"
                   "endfacet\nendsolid\n")
                  .error()
                  .message,
              d + "two_corners.stl:6: facet has 2 vertices; at least 3 are needed");
    EXPECT_EQ(read("junk.stl", "solid x\nhello\n").error().message,
              d + "junk.stl:2: expected 'facet' or 'endsolid', got 'hello'");
    EXPECT_EQ(read("empty_solid.stl", "solid x\nendsolid x\n").error().message,
              d + "empty_solid.stl: no triangles");
}

// Round 3, defect 2: 5,000 nodes instancing one 20k-triangle mesh (a 238 KB glTF) grew to 2 GB and aborted
// with bad_alloc; the triangles the nodes place are bounded before Assimp reads the file.
TEST(MeshReader, GltfInstancesAreBoundedBeforeAnyAllocation) {
    const auto dir = test::tempDir("MeshReader_instances");
    std::string buf;
    for (float c : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f})
        put(buf, c);
    const std::size_t indices = 3 * 20000;
    for (std::size_t i = 0; i < indices; ++i)
        put(buf, static_cast<std::uint16_t>(i % 4));
    auto file = [&](std::size_t nodes) {
        std::string list, refs;
        for (std::size_t n = 0; n < nodes; ++n) {
            list += std::string(n ? "," : "") + R"({"mesh":0})";
            refs += std::string(n ? "," : "") + std::to_string(n);
        }
        return R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[)" + refs + R"(]}],"nodes":[)" +
               list + R"(],"meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],)" +
               R"("buffers":[{"byteLength":)" + std::to_string(buf.size()) +
               R"(,"uri":"data:application/octet-stream;base64,)" + base64(buf) + R"("}],)" +
               R"("bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":48},{"buffer":0,"byteOffset":48,)" +
               R"("byteLength":)" + std::to_string(2 * indices) + R"(}],"accessors":[{"bufferView":0,)" +
               R"("componentType":5126,"count":4,"type":"VEC3","min":[0,0,0],"max":[1,1,1]},)" +
               R"({"bufferView":1,"componentType":5123,"count":)" + std::to_string(indices) +
               R"(,"type":"SCALAR"}]})";
    };
    test::writeFile(dir / "instances.gltf", file(5000));
    const Error e = errorOf(dir / "instances.gltf");
    EXPECT_EQ(e.code, ErrorCode::ParseError);
    EXPECT_EQ(e.message,
              (dir / "instances.gltf").string() +
                  ": its nodes place 100000000 triangles (every node a copy of its mesh), more than "
                  "the limit of 16777216");
    const auto scene = readScene(dir / "instances.gltf");
    ASSERT_FALSE(scene.isOk());
    EXPECT_EQ(scene.error().message, e.message);
    // Two instances are read: twice the triangles.
    test::writeFile(dir / "two.gltf", file(2));
    const auto two = readScene(dir / "two.gltf");
    ASSERT_TRUE(two.isOk()) << two.error().message;
    ASSERT_EQ(two->objects.size(), 2u);
    EXPECT_EQ(two->objects[0].mesh.triangleCount() + two->objects[1].mesh.triangleCount(), 2 * 20000u);
}
