#include "rubble/geometry/MeshSimplify.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "TestSupport.hpp"
#include "rubble/geometry/MassProperties.hpp"
#include "rubble/geometry/MeshCheck.hpp"

namespace rubble {
namespace {

/// Area per material.
std::map<std::uint32_t, double> areaByMaterial(const Mesh& m) {
    std::map<std::uint32_t, double> a;
    for (std::size_t t = 0; t < m.triangles.size(); ++t)
        a[m.material(t)] += 0.5 * length(m.triangleNormal(t));
    return a;
}

TEST(MeshSimplify, SubdividedBoxBecomesTwelveTriangles) {
    const Mesh box = makeSubdividedBox({-1, -2, -3}, {1, 2, 3}, 7);
    ASSERT_EQ(box.triangleCount(), 12u * 49u);
    PlanarSimplifyReport rep;
    const Mesh s = simplifyPlanarRegions(box, {}, &rep);
    EXPECT_EQ(s.triangleCount(), 12u);
    EXPECT_EQ(s.vertexCount(), 8u);
    EXPECT_FALSE(rep.unchanged);
    EXPECT_EQ(rep.regionsRetriangulated, 6u);
    EXPECT_EQ(rep.trianglesAfter, 12u);
    test::expectSameSolid(box, s);
}

TEST(MeshSimplify, MaterialBoundariesAndTheirAreasStay) {
    Mesh box = makeSubdividedBox({0, 0, 0}, {4, 4, 4}, 8);
    box.materials.assign(box.triangleCount(), 0);
    for (std::size_t t = 0; t < box.triangleCount(); ++t) {
        const auto c = box.corners(t);
        if ((c[0].x + c[1].x + c[2].x) / 3 < 2) // the half x < 2 is another material
            box.materials[t] = 1;
    }
    const Mesh s = simplifyPlanarRegions(box);
    EXPECT_LT(s.triangleCount(), box.triangleCount() / 10);
    test::expectSameSolid(box, s);
    const auto a0 = areaByMaterial(box), a1 = areaByMaterial(s);
    ASSERT_EQ(a1.size(), 2u);
    for (const auto& [mat, area] : a0)
        EXPECT_NEAR(a1.at(mat), area, 1e-9 * area) << "material " << mat;
}

TEST(MeshSimplify, TextureCoordinatesStayOnTheAffineMap) {
    Mesh box = makeSubdividedBox({0, 0, 0}, {2, 3, 5}, 5);
    box.uvs.resize(3 * box.triangleCount());
    for (std::size_t t = 0; t < box.triangleCount(); ++t) // a different affine map per face direction
        for (std::size_t k = 0; k < 3; ++k) {
            const Vec3 p = box.positions[box.triangles[t][k]];
            const Vec3 n = normalized(box.triangleNormal(t));
            box.uvs[3 * t + k] = {0.3 * p.x + 0.7 * p.y - 0.2 * p.z + n.x,
                                  0.5 * p.z - 0.1 * p.x + 2 * n.y + n.z};
        }
    const Mesh s = simplifyPlanarRegions(box);
    EXPECT_EQ(s.triangleCount(), 12u);
    test::expectSameSolid(box, s);
    for (std::size_t t = 0; t < s.triangleCount(); ++t)
        for (std::size_t k = 0; k < 3; ++k) {
            const Vec3 p = s.positions[s.triangles[t][k]];
            const Vec3 n = normalized(s.triangleNormal(t));
            // kept corners' coordinates, rounded to float once (values up to 5)
            EXPECT_NEAR(s.uvs[3 * t + k].x, 0.3 * p.x + 0.7 * p.y - 0.2 * p.z + n.x, 1e-6);
            EXPECT_NEAR(s.uvs[3 * t + k].y, 0.5 * p.z - 0.1 * p.x + 2 * n.y + n.z, 1e-6);
        }
}

TEST(MeshSimplify, AVertexWhoseTextureBendsStays) {
    Mesh box = makeSubdividedBox({0, 0, 0}, {1, 1, 1}, 4);
    box.uvs.resize(3 * box.triangleCount());
    for (std::size_t t = 0; t < box.triangleCount(); ++t)
        for (std::size_t k = 0; k < 3; ++k) {
            const Vec3 p = box.positions[box.triangles[t][k]];
            box.uvs[3 * t + k] = {p.x + p.z, p.y};
        }
    // The face x = 1: move the texture at its centre vertex (1, 0.5, 0.5) — the map is no longer affine
    // there.
    std::uint32_t centre = 0;
    for (std::uint32_t v = 0; v < box.positions.size(); ++v)
        if (length(box.positions[v] - Vec3{1, 0.5, 0.5}) < 1e-12)
            centre = v;
    for (std::size_t t = 0; t < box.triangleCount(); ++t)
        for (std::size_t k = 0; k < 3; ++k)
            if (box.triangles[t][k] == centre)
                box.uvs[3 * t + k].x += 0.25;
    const Mesh s = simplifyPlanarRegions(box);
    test::expectSameSolid(box, s);
    EXPECT_LT(s.triangleCount(), box.triangleCount());
    bool kept = false;
    for (const Vec3& p : s.positions)
        kept = kept || length(p - Vec3{1, 0.5, 0.5}) < 1e-12;
    EXPECT_TRUE(kept);
}

TEST(MeshSimplify, CurvedMeshesAreReturnedAsTheyAre) {
    const Mesh sphere = makeSphere({0, 0, 0}, 1, 16, 8);
    PlanarSimplifyReport rep;
    EXPECT_EQ(simplifyPlanarRegions(sphere, {}, &rep), sphere);
    EXPECT_TRUE(rep.unchanged);
    EXPECT_EQ(rep.trianglesAfter, sphere.triangleCount());
}

TEST(MeshSimplify, AnOpenMeshKeepsItsHole) {
    Mesh open = makeSubdividedBox({0, 0, 0}, {1, 1, 1}, 4);
    open.triangles.erase(open.triangles.begin() + 5); // a hole in the first face
    const MeshReport before = checkMesh(open);
    ASSERT_EQ(before.boundaryEdges, 3u);
    const Mesh s = simplifyPlanarRegions(open);
    const MeshReport after = checkMesh(s);
    EXPECT_LT(s.triangleCount(), open.triangleCount() / 4);
    EXPECT_EQ(after.boundaryEdges, 3u);
    EXPECT_TRUE(after.oriented);
    EXPECT_EQ(after.degenerateTriangles, 0u);
}

TEST(MeshSimplify, OnlyTheFocusChanges) {
    const Mesh box = makeSubdividedBox({0, 0, 0}, {4, 4, 4}, 8);
    PlanarSimplifyParams p;
    p.focus = {{-1, -1, -1}, {1.2, 1.2, 1.2}}; // around the corner at the origin
    const Mesh s = simplifyPlanarRegions(box, p);
    test::expectSameSolid(box, s);
    EXPECT_LT(s.triangleCount(), box.triangleCount());
    // Every vertex outside the focus is still there.
    std::size_t outside = 0, kept = 0;
    for (const Vec3& q : box.positions)
        if (!p.focus.contains(q)) {
            ++outside;
            for (const Vec3& r : s.positions)
                if (r == q) {
                    ++kept;
                    break;
                }
        }
    EXPECT_GT(outside, 0u);
    EXPECT_EQ(kept, outside);
}

TEST(MeshSimplify, BoxesTouchingAlongAnEdgeStayValid) {
    Mesh m = makeSubdividedBox({0, 0, 0}, {1, 1, 1}, 3);
    m.append(makeSubdividedBox({1, 1, 0}, {2, 2, 1}, 3)); // shares the edge x = y = 1 (not welded)
    const Mesh s = simplifyPlanarRegions(m);
    test::expectSameSolid(m, s);
    EXPECT_EQ(s.triangleCount(), 24u);
}

} // namespace
} // namespace rubble
