#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <sstream>

#include <csignal>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "TestSupport.hpp"
#include "rubble/core/Random.hpp"
#include "rubble/geometry/MassProperties.hpp"
#include "rubble/geometry/MeshCheck.hpp"
#include "rubble/io/MeshIO.hpp"

using namespace rubble;

namespace {
std::string slurp(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}
} // namespace

TEST(ObjWriter, RoundTripKeepsGeometryExactly) {
    const auto dir = test::tempDir("ObjWriter_roundtrip");
    Rng rng(1);
    Mesh m = makeSphere({0.1, -7.3, 1e3}, 2.5, 24, 12).transformed(rng.rotation(), {1, 2, 0.5}, {3, 4, 5});
    const auto path = dir / "sphere.obj";
    ASSERT_TRUE(writeObj(path, m).isOk());
    const auto r = readObj(path);
    ASSERT_TRUE(r.isOk()) << r.error().message;
    EXPECT_EQ(r->triangleCount(), m.triangleCount());
    EXPECT_EQ(r.value(), m); // shortest round-trip numbers: bit-identical positions
    EXPECT_EQ(signedVolume(r.value()), signedVolume(m));
    EXPECT_FALSE(std::filesystem::exists(dir / "sphere.mtl")); // no materials, no MTL
}

TEST(ObjWriter, RoundTripKeepsNormalsUvsAndMaterialNames) {
    const auto dir = test::tempDir("ObjWriter_attributes");
    Mesh m = makeBox({-1, -1, -1}, {1, 1, 1});
    m.computeFlatNormals();
    for (std::size_t t = 0; t < m.triangleCount(); ++t)
        for (int c = 0; c < 3; ++c) {
            const Vec3 p = m.positions[m.triangles[t][c]];
            m.uvs.push_back({p.x * 0.5 + 0.5, p.y * 0.25 + 0.125});
        }
    m.materialNames = {"stone", "moss"};
    for (std::size_t t = 0; t < m.triangleCount(); ++t)
        m.materials.push_back(t < 4 ? 0u : t < 8 ? kInteriorMaterial : 1u);
    const auto path = dir / "box.obj";
    ASSERT_TRUE(writeObj(path, m).isOk());
    const auto r = readObj(path);
    ASSERT_TRUE(r.isOk()) << r.error().message;
    EXPECT_EQ(r->positions, m.positions);
    EXPECT_EQ(r->triangles, m.triangles);
    EXPECT_EQ(r->normals, m.normals);
    EXPECT_EQ(r->uvs, m.uvs);
    ASSERT_EQ(r->materials.size(), m.materials.size());
    for (std::size_t t = 0; t < m.triangleCount(); ++t) {
        const std::uint32_t a = m.materials[t], b = r->materials[t];
        if (a == kInteriorMaterial)
            EXPECT_EQ(b, kInteriorMaterial);
        else
            EXPECT_EQ(r->materialNames.at(b), m.materialNames.at(a));
    }
    const std::string mtl = slurp(dir / "box.mtl");
    EXPECT_NE(mtl.find("newmtl interior"), std::string::npos);
    EXPECT_NE(mtl.find("newmtl stone"), std::string::npos);
    EXPECT_NE(mtl.find("newmtl moss"), std::string::npos);
    EXPECT_NE(slurp(path).find("mtllib box.mtl"), std::string::npos);
    EXPECT_TRUE(checkMesh(r.value()).valid());
}

// Normals and texture coordinates that float does not hold exactly (0.1, 1/3, a rotated normal) come back
// bit for bit, written as a float's shortest text (at most 9 significant digits, not a double's 17).
TEST(ObjWriter, RoundTripKeepsFloatAttributesExactlyAndShort) {
    const auto dir = test::tempDir("ObjWriter_float_attributes");
    Rng rng(5);
    const Mat3 turn = rng.rotation();
    Mesh m = makeSubdividedBox({-1, -1, -1}, {1, 1, 1}, 2);
    for (std::size_t t = 0; t < m.triangleCount(); ++t)
        for (const Vec3& p : m.corners(t)) {
            m.normals.emplace_back(turn * normalized(m.triangleNormal(t)));
            m.uvs.push_back({0.1 * p.x + 0.3, p.y / 3});
        }
    const auto path = dir / "box.obj";
    ASSERT_TRUE(writeObj(path, m).isOk());
    const auto r = readObj(path);
    ASSERT_TRUE(r.isOk()) << r.error().message;
    EXPECT_EQ(r->normals, m.normals);
    EXPECT_EQ(r->uvs, m.uvs);
    std::istringstream text(slurp(path));
    std::size_t lines = 0;
    for (std::string line; std::getline(text, line);) {
        if (line.rfind("vt ", 0) != 0 && line.rfind("vn ", 0) != 0)
            continue;
        ++lines;
        std::istringstream fields(line.substr(3));
        for (std::string number; fields >> number;) {
            const std::string mantissa = number.substr(0, number.find('e'));
            EXPECT_LE(std::count_if(mantissa.begin(), mantissa.end(), [](char c) { return std::isdigit(c); }),
                      10)
                << line;
        }
    }
    EXPECT_GT(lines, 10u);
}

TEST(ObjWriter, OptionsLeaveOutAttributesAndNameTheObject) {
    const auto dir = test::tempDir("ObjWriter_options");
    Mesh m = makeBox({0, 0, 0}, {1, 1, 1});
    m.computeFlatNormals();
    m.materials.assign(m.triangleCount(), 0);
    ObjWriteOptions o;
    o.writeNormals = false;
    o.writeMaterials = false;
    o.objectName = "my box";
    ASSERT_TRUE(writeObj(dir / "plain.obj", m, o).isOk());
    const std::string text = slurp(dir / "plain.obj");
    EXPECT_EQ(text.find("vn "), std::string::npos);
    EXPECT_EQ(text.find("usemtl"), std::string::npos);
    EXPECT_NE(text.find("o my_box\n"), std::string::npos);
    const auto objects = readObjObjects(dir / "plain.obj");
    ASSERT_TRUE(objects.isOk());
    ASSERT_EQ(objects->size(), 1u);
    EXPECT_EQ((*objects)[0].name, "my_box");
}

TEST(ObjWriter, RoundTripOfTheSubdividedCubeKeepsVolumeAndCount) {
    const auto dir = test::tempDir("ObjWriter_cube");
    const Mesh m =
        makeSubdividedBox({-1, 0.033073, -1}, {1, 2.033073, 1}, 29); // 10092 triangles like the seed
    ASSERT_EQ(m.triangleCount(), 10092u);
    ASSERT_TRUE(writeObj(dir / "cube.obj", m).isOk());
    const auto r = readObj(dir / "cube.obj");
    ASSERT_TRUE(r.isOk()) << r.error().message;
    EXPECT_EQ(r->triangleCount(), 10092u);
    EXPECT_EQ(signedVolume(r.value()), signedVolume(m));
    EXPECT_NEAR(signedVolume(r.value()), 8.0, 1e-9);
}

TEST(ObjWriter, ErrorsNameTheFile) {
    const Mesh m = makeBox({0, 0, 0}, {1, 1, 1});
    const Status s = writeObj("/nonexistent-dir/x.obj", m);
    ASSERT_FALSE(s.isOk());
    EXPECT_EQ(s.error().code, ErrorCode::IoError);
    EXPECT_EQ(s.message().rfind("/nonexistent-dir/x.obj: cannot open for writing", 0), 0u) << s.message();
    Mesh broken = m;
    broken.triangles[0][0] = 50;
    const Status b = writeObj(test::tempDir("ObjWriter_err") / "b.obj", broken);
    ASSERT_FALSE(b.isOk());
    EXPECT_EQ(b.error().code, ErrorCode::InvalidInput);
}

TEST(ObjWriter, AFailedWriteLeavesThePreviousFileAndNoStagingFile) {
    // A full disk left a truncated OBJ whose header promised triangles it did not hold. The child process
    // below gets a 4 KiB file size limit (with SIGXFSZ ignored, writes beyond it fail with EFBIG).
    const auto dir = test::tempDir("ObjWriter_failed_write");
    const auto path = dir / "out.obj";
    test::writeFile(path, "old content\n");
    const Mesh big = makeSphere({0, 0, 0}, 1, 48, 24);
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
        std::signal(SIGXFSZ, SIG_IGN);
        const rlimit limit{4096, 4096};
        ::setrlimit(RLIMIT_FSIZE, &limit);
        const Status s = writeObj(path, big);
        const bool ok = !s && s.error().code == ErrorCode::IoError &&
                        s.error().message == path.string() + ": write failed: File too large";
        ::_exit(ok ? 0 : 1);
    }
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 0) << "the write did not fail with the expected message";
    EXPECT_EQ(slurp(path), "old content\n");
    for (const auto& e : std::filesystem::directory_iterator(dir))
        EXPECT_EQ(e.path().filename(), "out.obj") << "left behind: " << e.path();
    // Without the limit the file is replaced as a whole.
    ASSERT_TRUE(writeObj(path, big).isOk());
    EXPECT_EQ(readObj(path).value().triangleCount(), big.triangleCount());
}
