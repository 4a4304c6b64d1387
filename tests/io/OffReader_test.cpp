#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "TestSupport.hpp"
#include "rubble/geometry/MeshCheck.hpp"
#include "rubble/io/MeshIO.hpp"

using namespace rubble;

namespace {
const char* kCubeVertices = "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n";
const char* kCubeFaces = "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 3 7 6 2\n4 0 4 7 3\n4 1 2 6 5\n";

std::string problemsOf(const MeshReport& r) {
    std::string s;
    for (const std::string& p : r.problems)
        s += p + "\n";
    return s;
}

std::string errorOf(const std::string& text, const std::string& name = "t.off") {
    const auto r = parseOff(text, name);
    EXPECT_FALSE(r.isOk()) << "expected an error for:\n" << text;
    return r.isOk() ? std::string() : r.error().message;
}

void expectValidSolid(const Result<Mesh>& r, std::size_t triangles, double volume) {
    ASSERT_TRUE(r.isOk()) << r.error().message;
    EXPECT_EQ(r->triangleCount(), triangles);
    const MeshReport rep = checkMesh(r.value());
    EXPECT_TRUE(rep.valid()) << problemsOf(rep);
    EXPECT_NEAR(rep.volume, volume, 1e-12);
}

// A prism over a regular n-gon (radius 1, height 1), its caps one n-gon face each, as OFF text.
std::string prism(int n) {
    std::string off = "OFF\n" + std::to_string(2 * n) + " " + std::to_string(n + 2) + " 0\n";
    for (int z = 0; z < 2; ++z)
        for (int i = 0; i < n; ++i) {
            const double a = 2 * std::numbers::pi * i / n;
            off += std::to_string(std::cos(a)) + " " + std::to_string(std::sin(a)) + " " + std::to_string(z) +
                   "\n";
        }
    std::string bottom = std::to_string(n), top = std::to_string(n);
    for (int i = 0; i < n; ++i) {
        bottom += " " + std::to_string(n - 1 - i);
        top += " " + std::to_string(n + i);
    }
    off += bottom + "\n" + top + "\n";
    for (int i = 0; i < n; ++i) {
        const int j = (i + 1) % n;
        off += "4 " + std::to_string(i) + " " + std::to_string(j) + " " + std::to_string(n + j) + " " +
               std::to_string(n + i) + "\n";
    }
    return off;
}

double prismVolume(const std::string& off) {
    return checkMesh(parseOff(off, "p.off").value()).volume;
}
} // namespace

TEST(OffReader, PolygonsWithMoreThanNineCornersAreKept) {
    // Assimp's OFF importer skipped faces with more than 9 corners: the prism was "not closed (holes)".
    for (int n : {10, 64, 2000}) {
        const std::string off = prism(n);
        const auto r = parseOff(off, "prism.off");
        ASSERT_TRUE(r.isOk()) << r.error().message;
        EXPECT_EQ(r->vertexCount(), static_cast<std::size_t>(2 * n));
        EXPECT_EQ(r->triangleCount(), static_cast<std::size_t>(2 * (n - 2) + 2 * n)) << n;
        const MeshReport rep = checkMesh(r.value());
        EXPECT_TRUE(rep.valid()) << n << "\n" << problemsOf(rep);
        EXPECT_NEAR(rep.volume, n / 2.0 * std::sin(2 * std::numbers::pi / n), 1e-5)
            << n; // 6-digit coordinates
    }
}

TEST(OffReader, CommentsAnywhereAndHeaderLayouts) {
    // A '#' line in the face block made Assimp lose the last face.
    const std::string faces = kCubeFaces;
    const std::string commented = "# a cube\nOFF # header\n\n8 6 12 # counts\n" + std::string(kCubeVertices) +
                                  "# faces follow\n" + faces.substr(0, 20) + "# in the middle\n" +
                                  faces.substr(20) + "# the end\n";
    expectValidSolid(parseOff(commented, "c.off"), 12, 1.0);
    expectValidSolid(parseOff("OFF 8 6 12\n" + std::string(kCubeVertices) + kCubeFaces, "one.off"), 12, 1.0);
    expectValidSolid(parseOff("OFF\n8\n6\n" + std::string(kCubeVertices) + kCubeFaces, "split.off"), 12, 1.0);
    expectValidSolid(
        parseOff("\xEF\xBB\xBFOFF\r\n8 6 0\r\n" + std::string(kCubeVertices) + kCubeFaces, "bom.off"), 12,
        1.0);
    // Colours after vertices and faces, normals, texture coordinates: ignored.
    std::string coff = "STCNOFF\n8 6 0\n";
    for (const char* v : {"0 0 0", "1 0 0", "1 1 0", "0 1 0", "0 0 1", "1 0 1", "1 1 1", "0 1 1"})
        coff += std::string(v) + " 0 0 1 0.5 0.5 0.5 1 0.25 0.75\n";
    for (const char* f : {"4 0 3 2 1", "4 4 5 6 7", "4 0 1 5 4", "4 3 7 6 2", "4 0 4 7 3", "4 1 2 6 5"})
        coff += std::string(f) + " 255 0 0\n";
    expectValidSolid(parseOff(coff, "colour.off"), 12, 1.0);
    // 4OFF divides by w; nOFF with dimension 3.
    std::string four = "4OFF\n8 6 0\n";
    for (const char* v : {"0 0 0", "2 0 0", "2 2 0", "0 2 0", "0 0 2", "2 0 2", "2 2 2", "0 2 2"})
        four += std::string(v) + " 2\n";
    expectValidSolid(parseOff(four + kCubeFaces, "four.off"), 12, 1.0);
    expectValidSolid(parseOff("nOFF 3 8 6 0\n" + std::string(kCubeVertices) + kCubeFaces, "n.off"), 12, 1.0);
}

TEST(OffReader, NumbersAreExactDoubles) {
    // Assimp read OFF in single precision: 10.2041 became 10.204099655...
    const auto r = parseOff("OFF\n4 4 0\n10.2041 0 0\n0 0.1 0\n0 0 1e-300\n0.3 0.7 1e300\n"
                            "3 0 2 1\n3 0 1 3\n3 1 2 3\n3 2 0 3\n",
                            "exact.off");
    ASSERT_TRUE(r.isOk()) << r.error().message;
    EXPECT_EQ(r->positions[0].x, 10.2041);
    EXPECT_EQ(r->positions[1].y, 0.1);
    EXPECT_EQ(r->positions[2].z, 1e-300);
    EXPECT_EQ(r->positions[3].z, 1e300);
}

TEST(OffReader, DeclaredCountsAreChecked) {
    const std::string v = kCubeVertices, f = kCubeFaces;
    EXPECT_EQ(errorOf("OFF\n8 7 0\n" + v + f), "t.off:16: the file ends after 6 of the 7 declared faces");
    EXPECT_EQ(errorOf("OFF\n9 6 0\n" + v), "t.off:10: the file ends after 8 of the 9 declared vertices");
    EXPECT_EQ(
        errorOf("OFF\n8 5 0\n" + v + f),
        "t.off:16: unexpected '4' after the 5 declared faces (the header's counts do not match the file)");
    EXPECT_EQ(
        errorOf("OFF\n8 6 0\n" + v + f + "4 1 2\n"),
        "t.off:17: unexpected '4' after the 6 declared faces (the header's counts do not match the file)");
    // Truncated lines.
    EXPECT_EQ(errorOf("OFF\n8 6 0\n0 0 0\n1 0\n"), "t.off:4: vertex 1 needs 3 numbers, got 2");
    EXPECT_EQ(errorOf("OFF\n8 6 0\n" + v + "4 0 3 2\n"),
              "t.off:11: face declares 4 corners but lists 3 numbers");
    EXPECT_EQ(errorOf("OFF\n8 6 0\n" + v + "2 0 3\n"), "t.off:11: face has 2 corners; at least 3 are needed");
    EXPECT_EQ(errorOf("OFF\n"), "t.off:1: expected the vertex and face counts after 'OFF'");
    EXPECT_EQ(errorOf("OFF\n8\n"), "t.off:2: expected the vertex and face counts after 'OFF'");
    EXPECT_EQ(errorOf("OFF\n8 6 0\n" + v + "3 0 1 8\n"),
              "t.off:11: face refers to vertex 8 but only 8 are declared (OFF indices start at 0)");
    EXPECT_EQ(errorOf("OFF\n8 6 0\n" + v + "3 0 1 -1\n"),
              "t.off:11: face: expected a vertex index, got '-1'");
    EXPECT_EQ(errorOf("OFF\n8 6 0\n0 0 abc\n"), "t.off:3: vertex 0: expected a number for z, got 'abc'");
    EXPECT_EQ(errorOf("OFF\n8 6 0\n0 0 1e999\n"), "t.off:3: vertex 0: value '1e999' for z is out of range");
    EXPECT_EQ(errorOf("OFF\n8 x 0\n"),
              "t.off:2: expected the vertex, face and edge counts after 'OFF', got '8' 'x'");
    EXPECT_EQ(errorOf("OFF\n8 6 0 5\n"),
              "t.off:2: expected the vertex, face and edge counts after 'OFF', got '5'");
    EXPECT_EQ(errorOf("OFF\n1 0 0\n0 0 0\n"), "t.off: no triangles (the file has 1 vertices but no faces)");
    EXPECT_EQ(errorOf(""), "t.off: no triangles (the file is empty)");
    EXPECT_EQ(errorOf("PLY\n"), "t.off:1: not an OFF file (it does not start with 'OFF')");
    EXPECT_EQ(errorOf("XOFF\n"), "t.off:1: unknown OFF variant 'XOFF'");
    EXPECT_EQ(errorOf("OFF\n8 6 0\n0 0\x01 0\n"),
              "t.off:3: unexpected binary data (byte 0x01); this is not an OFF text file");
    EXPECT_EQ(errorOf("4OFF\n8 6 0\n0 0 0 0\n"), "t.off:3: vertex 0: w is 0 (a point at infinity)");
    const auto bin = parseOff("OFF BINARY\n", "b.off");
    ASSERT_FALSE(bin);
    EXPECT_EQ(bin.error().code, ErrorCode::Unsupported);
    const auto dim = parseOff("nOFF 4 8 6 0\n", "d.off");
    ASSERT_FALSE(dim);
    EXPECT_EQ(dim.error().code, ErrorCode::Unsupported);
    EXPECT_EQ(dim.error().message, "d.off:1: only 3-dimensional OFF files are supported (dimension '4')");
}

TEST(OffReader, ReadMeshUsesIt) {
    const auto dir = test::tempDir("OffReader");
    test::writeFile(dir / "prism.off", prism(12));
    const auto r = readMesh(dir / "prism.off");
    ASSERT_TRUE(r.isOk()) << r.error().message;
    EXPECT_TRUE(checkMesh(r.value()).valid());
    EXPECT_NEAR(checkMesh(r.value()).volume, prismVolume(prism(12)), 0);
    // The size claim check still runs first.
    const auto huge = readMesh(test::sourceDir() / "tests/data/meshes/huge_claim.off");
    ASSERT_FALSE(huge);
    EXPECT_NE(huge.error().message.find("huge_claim.off:2: header claims 2000000000 vertices"),
              std::string::npos)
        << huge.error().message;
    test::writeFile(dir / "trunc.off",
                    "OFF\n8 6 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n4 0 3 2\n");
    EXPECT_EQ(readMesh(dir / "trunc.off").error().message,
              (dir / "trunc.off").string() + ":11: face declares 4 corners but lists 3 numbers");
}
