#include <gtest/gtest.h>

#include <algorithm>

#include "rubble/Islands.hpp"
#include "rubble/MassProperties.hpp"
#include "rubble/MeshCheck.hpp"

using namespace rubble;

namespace {
Mesh inverted(Mesh m) {
    for (Triangle& t : m.triangles)
        std::swap(t[1], t[2]);
    return m;
}

std::vector<double> volumesOf(const std::vector<Mesh>& islands) {
    std::vector<double> v;
    for (const Mesh& m : islands)
        v.push_back(signedVolume(m));
    return v;
}
} // namespace

TEST(Islands, TwoSeparateBoxesAreTwoIslands) {
    Mesh m = makeBox({0, 0, 0}, {1, 1, 1});
    m.append(makeBox({3, 0, 0}, {5, 2, 2}));
    std::vector<std::uint32_t> shell;
    EXPECT_EQ(labelShells(m, shell), 2u);
    ASSERT_EQ(shell.size(), m.triangleCount());
    EXPECT_EQ(shell.front(), 0u);
    EXPECT_EQ(shell.back(), 1u);

    const auto islands = splitIntoIslands(m);
    ASSERT_EQ(islands.size(), 2u);
    const auto v = volumesOf(islands);
    EXPECT_NEAR(v[0], 1.0, 1e-12); // deterministic order: lowest triangle index first
    EXPECT_NEAR(v[1], 8.0, 1e-12);
    for (const Mesh& island : islands) {
        EXPECT_EQ(island.vertexCount(), 8u); // unreferenced vertices dropped
        EXPECT_TRUE(checkMesh(island).valid());
    }
}

TEST(Islands, BoxWithCavityIsOneIslandWithOuterMinusInnerVolume) {
    Mesh m = makeBox({0, 0, 0}, {4, 4, 4});
    m.append(inverted(makeBox({1, 1, 1}, {2, 3, 2})));
    const auto islands = splitIntoIslands(m);
    ASSERT_EQ(islands.size(), 1u);
    EXPECT_NEAR(signedVolume(islands[0]), 64.0 - 2.0, 1e-12);
    EXPECT_EQ(islands[0].triangleCount(), 24u);
    EXPECT_TRUE(checkMesh(islands[0]).valid());
}

TEST(Islands, CavityJoinsTheSmallestEnclosingShell) {
    // A big box with a cavity that holds a smaller solid box, which itself has a cavity; plus a separate box.
    Mesh m = makeBox({0, 0, 0}, {10, 10, 10});
    m.append(inverted(makeBox({1, 1, 1}, {9, 9, 9}))); // cavity of the big box
    m.append(makeBox({2, 2, 2}, {8, 8, 8}));           // solid floating in the cavity
    m.append(inverted(makeBox({4, 4, 4}, {5, 5, 5}))); // cavity of the floating solid
    m.append(makeBox({20, 0, 0}, {21, 1, 1}));         // separate
    const auto islands = splitIntoIslands(m);
    ASSERT_EQ(islands.size(), 3u);
    const auto v = volumesOf(islands);
    EXPECT_NEAR(v[0], 1000.0 - 512.0, 1e-9);
    EXPECT_NEAR(v[1], 216.0 - 1.0, 1e-9);
    EXPECT_NEAR(v[2], 1.0, 1e-12);
    double total = 0;
    for (double x : v)
        total += x;
    EXPECT_NEAR(total, signedVolume(m), 1e-9);
}

TEST(Islands, AttributesStayWithTheirTriangles) {
    Mesh a = makeBox({0, 0, 0}, {1, 1, 1});
    a.materials.assign(a.triangleCount(), 3);
    Mesh b = makeBox({2, 0, 0}, {3, 1, 1});
    b.materials.assign(b.triangleCount(), kInteriorMaterial);
    Mesh m = a;
    m.append(b);
    m.computeFlatNormals();
    m.uvs.assign(3 * m.triangleCount(), Vec2{0.25, 0.75});
    m.materialNames = {"zero", "one", "two", "three"};
    const auto islands = splitIntoIslands(m);
    ASSERT_EQ(islands.size(), 2u);
    for (const Mesh& island : islands) {
        EXPECT_TRUE(island.validate().isOk()) << island.validate().message();
        EXPECT_EQ(island.normals.size(), 3 * island.triangleCount());
        EXPECT_EQ(island.uvs.size(), 3 * island.triangleCount());
        EXPECT_EQ(island.materialNames, m.materialNames);
    }
    EXPECT_TRUE(std::all_of(islands[0].materials.begin(), islands[0].materials.end(),
                            [](std::uint32_t x) { return x == 3; }));
    EXPECT_TRUE(std::all_of(islands[1].materials.begin(), islands[1].materials.end(),
                            [](std::uint32_t x) { return x == kInteriorMaterial; }));
}

TEST(Islands, EmptyAndSingleShellMeshes) {
    EXPECT_TRUE(splitIntoIslands(Mesh{}).empty());
    const Mesh box = makeBox({0, 0, 0}, {1, 1, 1});
    const auto one = splitIntoIslands(box);
    ASSERT_EQ(one.size(), 1u);
    EXPECT_EQ(one[0], box);
}

TEST(Islands, ShellsTouchingAtAVertexOnlyAreSeparate) {
    Mesh m = makeBox({0, 0, 0}, {1, 1, 1});
    Mesh other = makeBox({1, 1, 1}, {2, 2, 2});
    // Share the corner vertex (1,1,1) by index.
    const auto base = static_cast<std::uint32_t>(m.positions.size());
    m.append(other);
    const auto shared = static_cast<std::uint32_t>(
        std::find(m.positions.begin(), m.positions.begin() + base, Vec3{1, 1, 1}) - m.positions.begin());
    for (std::size_t t = 12; t < m.triangleCount(); ++t)
        for (std::uint32_t& v : m.triangles[t])
            if (m.positions[v] == Vec3{1, 1, 1})
                v = shared;
    std::vector<std::uint32_t> shell;
    EXPECT_EQ(labelShells(m, shell), 2u);
    EXPECT_EQ(splitIntoIslands(m).size(), 2u);
}
