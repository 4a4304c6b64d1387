#include "persist/CornerTable.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <map>
#include <random>
#include <tuple>

#include "TestSupport.hpp"

namespace rubble {
namespace {

// A sphere with smooth normals and a seam of texture coordinates (so vertices have one or two corners), then
// a flat-shaded box (three corners per box vertex), and a corner whose normal is -0 where another's is +0.
Mesh attributedMeshes() {
    Mesh m = makeSphere({0, 0, 0}, 1.0, 12, 8);
    for (const Triangle& t : m.triangles)
        for (std::uint32_t v : t) {
            const Vec3& p = m.positions[v];
            const Vec3 n = normalized(p);
            m.normals.push_back({static_cast<float>(n.x), static_cast<float>(n.y), static_cast<float>(n.z)});
            m.uvs.push_back({p.x > 0 && p.z >= 0 ? 1.0f : 0.0f, static_cast<float>(p.y)});
        }
    Mesh box = makeSubdividedBox({2, 0, 0}, {3, 1, 1}, 1);
    box.computeFlatNormals();
    for (std::size_t c = 0; c < 3 * box.triangles.size(); ++c)
        box.uvs.push_back({0.5f, 0.25f});
    const auto offset = static_cast<std::uint32_t>(m.positions.size());
    m.positions.insert(m.positions.end(), box.positions.begin(), box.positions.end());
    for (Triangle t : box.triangles) {
        for (auto& v : t)
            v += offset;
        m.triangles.push_back(t);
    }
    m.normals.insert(m.normals.end(), box.normals.begin(), box.normals.end());
    m.uvs.insert(m.uvs.end(), box.uvs.begin(), box.uvs.end());
    m.normals[0].x = 0.0f;
    m.normals[3].x = -0.0f;
    m.triangles[1][0] = m.triangles[0][0];
    return m;
}

using CornerKey =
    std::tuple<std::uint32_t, std::uint32_t, std::uint32_t, std::uint32_t, std::uint32_t, std::uint32_t>;
CornerKey keyOf(const Mesh& m, std::size_t c) {
    const Vec3f& n = m.normals[c];
    const Vec2f& u = m.uvs[c];
    return {m.triangles[c / 3][c % 3],         std::bit_cast<std::uint32_t>(n.x),
            std::bit_cast<std::uint32_t>(n.y), std::bit_cast<std::uint32_t>(n.z),
            std::bit_cast<std::uint32_t>(u.x), std::bit_cast<std::uint32_t>(u.y)};
}

TEST(CornerTable, KeepsEachDistinctCornerOnceAndExpandsToTheSameMeshBitForBit) {
    const Mesh m = attributedMeshes();
    std::map<CornerKey, std::size_t> distinct;
    for (std::size_t c = 0; c < 3 * m.triangles.size(); ++c)
        distinct.emplace(keyOf(m, c), distinct.size());
    const persist::CornerTable t = persist::cornerTable(m, true, true);
    EXPECT_EQ(t.vertex.size(), distinct.size());
    EXPECT_LT(t.vertex.size(), 3 * m.triangles.size() / 2) << "corners are shared";
    ASSERT_EQ(t.codes.size(), 3 * m.triangles.size());
    EXPECT_EQ(t.codes[0], 0u) << "the first corner is new";

    Mesh back;
    back.positions = m.positions;
    ASSERT_TRUE(persist::checkCornerVertices(t, back.positions.size()).what.empty());
    ASSERT_TRUE(persist::expandCorners(t, back.positions.size(), back).what.empty());
    EXPECT_EQ(back.triangles, m.triangles);
    ASSERT_EQ(back.normals.size(), m.normals.size());
    for (std::size_t c = 0; c < m.normals.size(); ++c)
        ASSERT_EQ(keyOf(back, c), keyOf(m, c)) << "corner " << c;
    EXPECT_TRUE(std::signbit(back.normals[3].x)) << "-0 stays -0";
    EXPECT_FALSE(std::signbit(back.normals[0].x));
}

TEST(CornerTable, WithoutAnAttributeTheCornersAreTheVerticesTheTrianglesUse) {
    Mesh m = attributedMeshes();
    const persist::CornerTable t = persist::cornerTable(m, false, true);
    EXPECT_TRUE(t.normals.empty());
    Mesh back;
    ASSERT_TRUE(persist::expandCorners(t, m.positions.size(), back).what.empty());
    EXPECT_EQ(back.triangles, m.triangles);
    EXPECT_EQ(back.uvs, m.uvs);
    EXPECT_TRUE(back.normals.empty());
}

TEST(CornerTable, ACodeNamingNoCornerAndAVertexOutOfRangeAreNamedByIndex) {
    const Mesh m = attributedMeshes();
    persist::CornerTable t = persist::cornerTable(m, true, true);
    persist::CornerTable bad = t;
    bad.codes[5] = 6; // five corners at most were used before it
    Mesh out;
    persist::CornerError e = persist::expandCorners(bad, m.positions.size(), out);
    EXPECT_EQ(e.index, 5u);
    EXPECT_NE(e.what.find("names no corner"), std::string::npos) << e.what;
    bad = t;
    bad.vertex.resize(bad.vertex.size() - 1); // the last corner's first use is now past the table
    bad.normals.resize(bad.vertex.size());
    bad.uvs.resize(bad.vertex.size());
    e = persist::expandCorners(bad, m.positions.size(), out);
    EXPECT_FALSE(e.what.empty());
    bad = t;
    bad.vertex[7] = static_cast<std::uint32_t>(m.positions.size());
    e = persist::checkCornerVertices(bad, m.positions.size());
    EXPECT_EQ(e.index, 7u);
    EXPECT_NE(e.what.find("out of range"), std::string::npos) << e.what;
    bad = t;
    bad.vertex.push_back(0);
    bad.normals.push_back({});
    bad.uvs.push_back({});
    e = persist::expandCorners(bad, m.positions.size(), out);
    EXPECT_EQ(e.index, bad.codes.size());
    EXPECT_NE(e.what.find("1 corners are never used"), std::string::npos) << e.what;
    bad = t;
    bad.uvs.pop_back();
    EXPECT_NE(persist::expandCorners(bad, m.positions.size(), out).what.find("texture coordinates"),
              std::string::npos);
}

// Only the table cornerTable makes is read: one corner twice would be written back as one.
TEST(CornerTable, ACornerEqualToAnEarlierOneIsRefused) {
    persist::CornerTable t;
    t.vertex = {0, 0, 1};
    t.uvs = {{0.5f, 0.5f}, {0.5f, 0.5f}, {0, 0}};
    t.codes = {0, 0, 0};
    Mesh out;
    const persist::CornerError e = persist::expandCorners(t, 2, out);
    EXPECT_EQ(e.index, 1u);
    EXPECT_NE(e.what.find("corner 1 repeats corner 0"), std::string::npos) << e.what;
    t.uvs[1].y = -0.5f;
    EXPECT_TRUE(persist::expandCorners(t, 2, out).what.empty());
}

} // namespace
} // namespace rubble
