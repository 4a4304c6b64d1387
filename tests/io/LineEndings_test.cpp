// Text meshes whose lines end in CR only (classic Mac OS) read like their LF versions, with the same line
// numbers in errors; a PLY header longer than its limit says so instead of "no end_header".
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "TestSupport.hpp"
#include "rubble/geometry/MassProperties.hpp"
#include "rubble/io/MeshIO.hpp"

using namespace rubble;

namespace {

std::string crOnly(std::string text) {
    std::replace(text.begin(), text.end(), '\n', '\r');
    return text;
}

const std::string kTetraObj =
    "# tetrahedron\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
const std::string kTetraOff = "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
const std::string kTetraPly = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                              "property float z\nelement face 4\nproperty list uchar int vertex_indices\n"
                              "end_header\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
const std::string kTetraStl =
    "solid t\n"
    "facet normal 0 0 -1\nouter loop\nvertex 0 0 0\nvertex 0 1 0\nvertex 1 0 0\nendloop\n"
    "endfacet\nfacet normal 0 -1 0\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 0 1\n"
    "endloop\nendfacet\nfacet normal -1 0 0\nouter loop\nvertex 0 0 0\nvertex 0 0 1\n"
    "vertex 0 1 0\nendloop\nendfacet\nfacet normal 1 1 1\nouter loop\nvertex 1 0 0\n"
    "vertex 0 1 0\nvertex 0 0 1\nendloop\nendfacet\nendsolid t\n";

Result<Mesh> readText(const std::string& file, const std::string& text) {
    return readMesh(test::writeFile(test::tempDir("LineEndings") / file, text));
}

} // namespace

TEST(LineEndings, CrOnlyFilesReadLikeTheirLfVersions) {
    for (const auto& [file, text] :
         {std::pair{"t.obj", kTetraObj}, {"t.off", kTetraOff}, {"t.ply", kTetraPly}, {"t.stl", kTetraStl}}) {
        const Result<Mesh> lf = readText(file, text);
        ASSERT_TRUE(lf) << file << ": " << lf.error().message;
        const Result<Mesh> cr = readText(file, crOnly(text));
        ASSERT_TRUE(cr) << file << " (CR only): " << cr.error().message;
        EXPECT_EQ(cr->triangles.size(), 4u) << file;
        EXPECT_NEAR(signedVolume(*cr), 1.0 / 6.0, 1e-12) << file;
        EXPECT_EQ(cr->positions, lf->positions) << file;
    }
}

TEST(LineEndings, ErrorsInCrOnlyFilesNameTheLine) {
    const std::string bad = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n";
    const Result<Mesh> lf = readText("bad.obj", bad);
    const Result<Mesh> cr = readText("bad.obj", crOnly(bad));
    ASSERT_FALSE(lf);
    ASSERT_FALSE(cr);
    EXPECT_NE(cr.error().message.find("bad.obj:4: face refers to vertex 9"), std::string::npos)
        << cr.error().message;
    EXPECT_EQ(cr.error().message, lf.error().message);
}

TEST(LineEndings, APlyHeaderOverItsLimitSaysSo) {
    std::string header = "ply\nformat ascii 1.0\n";
    while (header.size() < (1u << 20) + 100)
        header += "comment " + std::string(100, 'x') + "\n";
    header += "element vertex 0\nend_header\n";
    const Result<Mesh> r = readText("long.ply", header);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("PLY header is longer than the limit of 1048576 bytes"),
              std::string::npos)
        << r.error().message;
}
