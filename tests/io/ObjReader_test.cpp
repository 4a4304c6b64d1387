#include <gtest/gtest.h>

#include <cmath>

#include "TestSupport.hpp"
#include "rubble/core/Random.hpp"
#include "rubble/geometry/MassProperties.hpp"
#include "rubble/geometry/MeshCheck.hpp"
#include "rubble/io/MeshIO.hpp"

using namespace rubble;

namespace {
const char* kCubeVertices = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n";

std::string problemsOf(const MeshReport& r) {
    std::string s;
    for (const std::string& p : r.problems)
        s += p + "\n";
    return s;
}

std::string errorOf(const std::string& text, const std::string& name = "t.obj") {
    const auto r = parseObj(text, name);
    EXPECT_FALSE(r.isOk()) << "expected an error for:\n" << text;
    return r.isOk() ? std::string() : r.error().message;
}
} // namespace

TEST(ObjReader, QuadCubeFileIsAValidClosedCube) {
    const auto r = readObj(test::sourceDir() / "tests/data/meshes/cube.obj");
    ASSERT_TRUE(r.isOk()) << r.error().message;
    EXPECT_EQ(r->vertexCount(), 8u);
    EXPECT_EQ(r->triangleCount(), 12u);
    EXPECT_FALSE(r->hasNormals());
    EXPECT_FALSE(r->hasUvs());
    EXPECT_FALSE(r->hasMaterials());
    const MeshReport rep = checkMesh(r.value());
    EXPECT_TRUE(rep.valid()) << problemsOf(rep);
    EXPECT_NEAR(rep.volume, 1.0, 1e-15);
}

TEST(ObjReader, NegativeIndicesAndCornerForms) {
    const std::string text = std::string(kCubeVertices) +
                             "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                             "vn 0 0 -1\nvn 0 0 1\nvn 0 -1 0\nvn 0 1 0\nvn -1 0 0\nvn 1 0 0\n"
                             "f -8/-4/-6 -5/-1/-6 -6/-2/-6 -7/-3/-6\n" // bottom, relative
                             "f 5/1/2 6/2/2 7/3/2 8/4/2\n"             // v/vt/vn
                             "f 1//3 2//3 6//3 5//3\n"                 // v//vn
                             "f 4/1 8/2 7/3 3/4\n"                     // v/vt
                             "f 1 5 8 4\n"                             // v
                             "f +2 3 7 6\n";                           // explicit sign
    const auto r = parseObj(text, "forms.obj");
    ASSERT_TRUE(r.isOk()) << r.error().message;
    EXPECT_EQ(r->triangleCount(), 12u);
    ASSERT_TRUE(r->hasNormals());
    ASSERT_TRUE(r->hasUvs());
    EXPECT_TRUE(r->validate().isOk());
    EXPECT_EQ(r->normals[0], (Vec3{0, 0, -1}));
    EXPECT_EQ(r->uvs[3 * 2 + 0], (Vec2f{0, 0})); // first corner of the v/vt/vn quad
    // Corners without a normal get the flat face normal, so every normal points out of its face.
    for (std::size_t t = 0; t < r->triangleCount(); ++t)
        for (int c = 0; c < 3; ++c)
            EXPECT_GT(dot(r->normals[3 * t + c], r->triangleNormal(t)), 0) << t;
    const MeshReport rep = checkMesh(r.value());
    EXPECT_TRUE(rep.valid()) << problemsOf(rep);
}

TEST(ObjReader, ConvexNGonIsFannedAndConcaveNGonEarClipped) {
    // A regular octagon (convex) and an L-shaped hexagon (concave), both in the z=0 plane, facing +z.
    std::string text;
    for (int i = 0; i < 8; ++i) {
        const double a = 2 * 3.14159265358979323846 * i / 8;
        text += "v " + std::to_string(std::cos(a)) + " " + std::to_string(std::sin(a)) + " 0\n";
    }
    text += "f 1 2 3 4 5 6 7 8\n";
    text += "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\n";
    text += "f 9 10 11 12 13 14\n";
    const auto r = parseObj(text, "ngon.obj");
    ASSERT_TRUE(r.isOk()) << r.error().message;
    ASSERT_EQ(r->triangleCount(), 6u + 4u);
    double octagonArea = 0, lArea = 0;
    for (std::size_t t = 0; t < r->triangleCount(); ++t) {
        const Vec3 n = r->triangleNormal(t);
        EXPECT_GT(n.z, 0) << "triangle " << t << " keeps the polygon's winding";
        (t < 6 ? octagonArea : lArea) += 0.5 * length(n);
    }
    EXPECT_NEAR(octagonArea, 2 * std::sqrt(2.0), 1e-5);
    EXPECT_NEAR(lArea, 3.0, 1e-12); // fan from a reflex corner would overlap and give a different sum
}

TEST(ObjReader, ConcavePolygonInATiltedPlane) {
    // An L-shaped hexagon rotated into a general plane: the ear clipper works in the best-fit plane.
    Rng rng(3);
    const Mat3 rot = rng.rotation();
    const Vec3 pts[6] = {{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {1, 1, 0}, {1, 2, 0}, {0, 2, 0}};
    std::string text;
    char buf[128];
    for (const Vec3& p : pts) {
        const Vec3 q = rot * p + Vec3{5, -3, 2};
        std::snprintf(buf, sizeof buf, "v %.17g %.17g %.17g\n", q.x, q.y, q.z);
        text += buf;
    }
    text += "f 1 2 3 4 5 6\n";
    const auto r = parseObj(text, "tilted.obj");
    ASSERT_TRUE(r.isOk()) << r.error().message;
    ASSERT_EQ(r->triangleCount(), 4u);
    const Vec3 up = rot * Vec3{0, 0, 1};
    double area = 0;
    for (std::size_t t = 0; t < 4; ++t) {
        EXPECT_GT(dot(r->triangleNormal(t), up), 0);
        area += 0.5 * length(r->triangleNormal(t));
    }
    EXPECT_NEAR(area, 3.0, 1e-9);
}

TEST(ObjReader, MultiObjectFileMergedOrKeptApart) {
    const std::string text =
        "o first\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n"
        "o second\nv 5 0 0\nv 6 0 0\nv 5 1 0\nv 5 0 1\nf 5 7 6\nf 5 6 8\nf 6 7 8\nf 7 5 8\n"
        "o no faces\nv 9 9 9\n";
    const auto merged = parseObj(text, "two.obj");
    ASSERT_TRUE(merged.isOk()) << merged.error().message;
    EXPECT_EQ(merged->triangleCount(), 8u);
    EXPECT_EQ(merged->vertexCount(), 8u); // the unreferenced vertex is dropped
    EXPECT_NEAR(signedVolume(merged.value()), 2.0 / 6.0, 1e-15);

    const auto objects = parseObjObjects(text, "two.obj");
    ASSERT_TRUE(objects.isOk()) << objects.error().message;
    ASSERT_EQ(objects->size(), 2u);
    EXPECT_EQ((*objects)[0].name, "first");
    EXPECT_EQ((*objects)[1].name, "second");
    for (const NamedMesh& o : objects.value()) {
        EXPECT_EQ(o.mesh.vertexCount(), 4u);
        EXPECT_TRUE(checkMesh(o.mesh).valid()) << o.name;
    }
    EXPECT_EQ((*objects)[1].mesh.positions[0], (Vec3{5, 0, 0}));
}

TEST(ObjReader, GroupsSplitObjectsWhenThereIsNoO) {
    const std::string text = "v 0 0 0\nv 1 0 0\nv 0 1 0\ng alpha\nf 1 2 3\ng beta gamma\nf 3 2 1\n";
    const auto objects = parseObjObjects(text, "g.obj");
    ASSERT_TRUE(objects.isOk()) << objects.error().message;
    ASSERT_EQ(objects->size(), 2u);
    EXPECT_EQ((*objects)[0].name, "alpha");
    EXPECT_EQ((*objects)[1].name, "beta gamma");
}

TEST(ObjReader, MaterialsGetIdsInOrderOfFirstUse) {
    const std::string text =
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
        "f 1 3 2\nusemtl stone\nf 1 2 4\nusemtl interior\nf 2 3 4\nusemtl stone\nf 3 1 4\n";
    const auto r = parseObj(text, "mat.obj");
    ASSERT_TRUE(r.isOk()) << r.error().message;
    ASSERT_TRUE(r->hasMaterials());
    EXPECT_EQ(r->materialNames, (std::vector<std::string>{"stone", "default"}));
    EXPECT_EQ(r->materials, (std::vector<std::uint32_t>{1, 0, kInteriorMaterial, 0}));
}

TEST(ObjReader, ErrorsNameFileLineAndWhat) {
    const std::string v = kCubeVertices;
    EXPECT_EQ(errorOf(v + "\n\n\n\n\n\n\n\nf 1 2 9\n", "cube.obj"),
              "cube.obj:17: face refers to vertex 9 (OBJ counts from 1) but only 8 are defined");
    EXPECT_EQ(errorOf(v + "f 1 2 -9\n"),
              "t.obj:9: face refers to vertex -9 (OBJ counts from 1) but only 8 are defined");
    EXPECT_EQ(errorOf(v + "f 0 1 2\n"), "t.obj:9: face refers to vertex 0, but OBJ indices start at 1");
    EXPECT_EQ(errorOf(v + "f 1/1 2/1 3/1\n"),
              "t.obj:9: face refers to texture coordinate 1 (OBJ counts from 1) but only 0 are defined");
    EXPECT_EQ(errorOf(v + "vn 0 0 1\nf 1//2 2//1 3//1\n"),
              "t.obj:10: face refers to normal 2 (OBJ counts from 1) but only 1 is defined");
    EXPECT_EQ(errorOf(v + "f 1 2\n"), "t.obj:9: face has 2 corners; at least 3 are needed");
    EXPECT_EQ(errorOf(v + "f 1 2 x\n"), "t.obj:9: face corner 'x': expected a vertex index, got 'x'");
    EXPECT_EQ(errorOf(v + "f 1/2/3/4 2 3\n"),
              "t.obj:9: face corner '1/2/3/4': expected v, v/vt, v//vn or v/vt/vn");
    EXPECT_EQ(errorOf("v 1 2\n"), "t.obj:1: vertex needs 3 numbers, got 2");
    EXPECT_EQ(errorOf("v 1 abc 3\n"), "t.obj:1: vertex: expected a number for y, got 'abc'");
    EXPECT_EQ(errorOf("v 1 2 1e999\n"), "t.obj:1: vertex: value '1e999' for z is out of range");
    EXPECT_EQ(errorOf("vn 1 2\n"), "t.obj:1: normal needs 3 numbers, got 2");
    EXPECT_EQ(errorOf("vn 0 1e39 0\n"), "t.obj:1: normal: value '1e39' for y is beyond float's range");
    EXPECT_EQ(errorOf("vt 0.5 -4e38\n"),
              "t.obj:1: texture coordinate: value '-4e38' for v is beyond float's range");
    EXPECT_EQ(errorOf("vt\n"), "t.obj:1: texture coordinate needs 1 number, got 0");
    EXPECT_EQ(errorOf(v + "f 1 2 99999999999999999999999\n"),
              "t.obj:9: face corner '99999999999999999999999': expected a vertex index, got "
              "'99999999999999999999999'");
}

TEST(ObjReader, EmptyAndFacelessFilesHaveNoTriangles) {
    EXPECT_EQ(errorOf("", "empty.obj"), "empty.obj: no triangles (the file is empty)");
    EXPECT_EQ(errorOf("# just a comment\n\n", "c.obj"),
              "c.obj: no triangles (the file has no vertices or faces)");
    EXPECT_EQ(errorOf(kCubeVertices, "v.obj"), "v.obj: no triangles (the file has 8 vertices but no faces)");
    const auto r = readObj(test::sourceDir() / "tests/data/no-such-file.obj");
    ASSERT_FALSE(r.isOk());
    EXPECT_EQ(r.error().code, ErrorCode::IoError);
    EXPECT_NE(r.error().message.find("no-such-file.obj: cannot open"), std::string::npos)
        << r.error().message;
}

TEST(ObjReader, NonFiniteCoordinatesAreReadAndFlaggedByTheCheck) {
    const std::string text = "v 0 0 0\nv nan 0 0\nv 0 inf 0\nv 0 0 1e-320\nf 1 2 3\nf 1 3 4\n";
    const auto r = parseObj(text, "nan.obj");
    ASSERT_TRUE(r.isOk()) << r.error().message;
    EXPECT_TRUE(std::isnan(r->positions[1].x));
    EXPECT_TRUE(std::isinf(r->positions[2].y));
    const MeshReport rep = checkMesh(r.value());
    EXPECT_EQ(rep.nonFiniteVertices, 2u);
    EXPECT_FALSE(rep.valid());
}

TEST(ObjReader, CrlfCommentsAndUnknownStatementsAreFine) {
    const std::string text =
        "\xEF\xBB\xBF# header\r\nmtllib x.mtl\r\ns off\r\nv 0 0 0 # origin\r\nv 1 0 0\r\n"
        "v 0 1 0\r\nl 1 2\r\nvp 0.5\r\nf 1 2 3\r\n";
    const auto r = parseObj(text, "crlf.obj");
    ASSERT_TRUE(r.isOk()) << r.error().message;
    EXPECT_EQ(r->triangleCount(), 1u);
}

TEST(ObjReader, BinaryDataIsRejectedWithTheLine) {
    const std::string text = std::string("v 0 0 0\nv 1 0 0\nv 0 1\0 0\nf 1 2 3\n", 30);
    EXPECT_EQ(errorOf(text, "bin.obj"),
              "bin.obj:3: unexpected binary data (byte 0x00); this is not an OBJ text file");
    const auto garbage = readObj(test::sourceDir() / "tests/data/meshes/garbage.obj");
    ASSERT_FALSE(garbage.isOk());
    EXPECT_EQ(garbage.error().code, ErrorCode::ParseError);
    EXPECT_NE(garbage.error().message.find("garbage.obj:1:"), std::string::npos) << garbage.error().message;
}

TEST(ObjReader, RandomBytesAndMutatedFilesNeverCrash) {
    Rng rng(11);
    const std::string cube = std::string(kCubeVertices) + "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 4 8 7 3\n"
                                                          "f 1 5 8 4\nf 2 3 7 6\nvt 0.5 0.5\nvn 0 0 1\n";
    const std::string alphabet = "0123456789 -+./eEfvntgo#\n\tnaif";
    int parsed = 0;
    for (int i = 0; i < 3000; ++i) {
        std::string text;
        if (i % 3 == 0) { // raw bytes
            text.resize(rng.below(300));
            for (char& c : text)
                c = static_cast<char>(rng.below(256));
        } else if (i % 3 == 1) { // OBJ-like alphabet
            text.resize(rng.below(300));
            for (char& c : text)
                c = alphabet[rng.below(alphabet.size())];
        } else { // mutated valid cube: flips, truncation
            text = cube;
            for (int k = 0; k < 4; ++k)
                text[rng.below(text.size())] = alphabet[rng.below(alphabet.size())];
            text.resize(rng.below(text.size() + 1));
        }
        const auto r = parseObjObjects(text, "fuzz.obj");
        if (r.isOk()) {
            ++parsed;
            for (const NamedMesh& o : r.value()) {
                EXPECT_TRUE(o.mesh.validate().isOk() ||
                            o.mesh.validate().message().find("non-finite") != std::string::npos);
                (void)checkMesh(o.mesh);
            }
        } else {
            EXPECT_EQ(r.error().message.rfind("fuzz.obj:", 0), 0u) << r.error().message;
        }
    }
    EXPECT_GT(parsed, 10);
}

TEST(ObjReader, HugeFaceIsTriangulatedWithoutBlowingUp) {
    // A 5000-corner convex polygon (a disk) fans; a 2000-corner star-shaped concave polygon ear-clips.
    std::string text;
    char buf[128];
    const int n = 5000;
    for (int i = 0; i < n; ++i) {
        const double a = 2 * 3.14159265358979323846 * i / n;
        std::snprintf(buf, sizeof buf, "v %.17g %.17g 0\n", std::cos(a), std::sin(a));
        text += buf;
    }
    text += "f";
    for (int i = 1; i <= n; ++i) { // two appends: gcc 12 -O3 warns falsely (-Wrestrict) on " " + to_string
        text += ' ';
        text += std::to_string(i);
    }
    text += "\n";
    const int m = 1000;
    for (int i = 0; i < m; ++i) {
        const double a = 2 * 3.14159265358979323846 * i / m;
        const double rad = i % 2 ? 1.0 : 0.6;
        std::snprintf(buf, sizeof buf, "v %.17g %.17g 0\n", rad * std::cos(a), rad * std::sin(a));
        text += buf;
    }
    text += "f";
    for (int i = 1; i <= m; ++i) {
        text += ' ';
        text += std::to_string(n + i);
    }
    text += "\n";
    const auto r = parseObj(text, "big.obj");
    ASSERT_TRUE(r.isOk()) << r.error().message;
    EXPECT_EQ(r->triangleCount(), std::size_t(n - 2 + m - 2));
    for (std::size_t t = n - 2; t < r->triangleCount(); ++t)
        EXPECT_GE(r->triangleNormal(t).z, 0) << t;
}
