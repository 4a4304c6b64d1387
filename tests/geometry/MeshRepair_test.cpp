#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "TestSupport.hpp"
#include "rubble/core/Random.hpp"
#include "rubble/geometry/MassProperties.hpp"
#include "rubble/geometry/MeshRepair.hpp"

using namespace rubble;

namespace {
void flip(Mesh& m, std::size_t t) {
    std::swap(m.triangles[t][1], m.triangles[t][2]);
    if (m.hasNormals())
        std::swap(m.normals[3 * t + 1], m.normals[3 * t + 2]);
    if (m.hasUvs())
        std::swap(m.uvs[3 * t + 1], m.uvs[3 * t + 2]);
}

// Normals agree with the faces they belong to.
void expectNormalsAgreeWithFaces(const Mesh& m) {
    ASSERT_EQ(m.normals.size(), 3 * m.triangles.size());
    for (std::size_t t = 0; t < m.triangles.size(); ++t)
        for (int c = 0; c < 3; ++c)
            EXPECT_GT(dot(m.normals[3 * t + c], m.triangleNormal(t)), 0) << "triangle " << t;
}
} // namespace

TEST(MeshRepair, InvertedCubeBecomesValidWithSameVolume) {
    Mesh m = makeBox({0, 0, 0}, {2, 3, 4});
    for (std::size_t t = 0; t < m.triangles.size(); ++t)
        flip(m, t);
    const RepairReport r = repairMesh(m);
    EXPECT_TRUE(r.valid()) << test::joinLines(r.unrepaired);
    EXPECT_EQ(r.invertedShells, 1u);
    EXPECT_EQ(r.flippedTriangles, 0u);
    EXPECT_NEAR(r.after.volume, 24.0, 1e-12);
    EXPECT_TRUE(test::mentions(r.fixed, "reversed 1 inside-out shell")) << test::joinLines(r.fixed);
}

TEST(MeshRepair, OneFlippedFaceIsFlippedBack) {
    Mesh m = makeBox({0, 0, 0}, {1, 1, 1});
    flip(m, 7);
    const RepairReport r = repairMesh(m);
    EXPECT_TRUE(r.valid()) << test::joinLines(r.unrepaired);
    EXPECT_EQ(r.flippedTriangles + r.invertedShells, 1u);
    EXPECT_EQ(m, makeBox({0, 0, 0}, {1, 1, 1}));
}

TEST(MeshRepair, DuplicatedVerticesAreWeldedAndAttributesFollow) {
    const Mesh original = makeBox({-1, -1, -1}, {1, 1, 1});
    Mesh m = test::unwelded(original, true);
    // Also flip two faces and invert nothing else: orientation must be repaired after welding.
    flip(m, 0);
    flip(m, 5);
    const RepairReport r = repairMesh(m);
    EXPECT_TRUE(r.valid()) << test::joinLines(r.unrepaired);
    EXPECT_EQ(r.weldedVertices, 36u - 8u);
    EXPECT_EQ(r.removedUnreferencedVertices, 28u);
    EXPECT_EQ(m.vertexCount(), 8u);
    EXPECT_EQ(m.triangleCount(), 12u);
    EXPECT_NEAR(r.after.volume, 8.0, 1e-12);
    EXPECT_TRUE(m.validate().isOk()) << m.validate().message();
    EXPECT_EQ(m.materials.size(), 12u);
    expectNormalsAgreeWithFaces(m);
    // UVs travel with their corners: each corner's uv is still (x, y) of its position.
    for (std::size_t t = 0; t < m.triangles.size(); ++t)
        for (int c = 0; c < 3; ++c) {
            EXPECT_EQ(m.uvs[3 * t + c].x, m.positions[m.triangles[t][c]].x);
            EXPECT_EQ(m.uvs[3 * t + c].y, m.positions[m.triangles[t][c]].y);
        }
}

TEST(MeshRepair, InvertedFlippedDuplicatedCubeBecomesValidCube) {
    Mesh m = test::unwelded(makeBox({0, 0, 0}, {3, 3, 3}), true);
    for (std::size_t t = 0; t < m.triangles.size(); ++t)
        if (t != 4)
            flip(m, t); // inverted except one face
    const RepairReport r = repairMesh(m);
    EXPECT_TRUE(r.valid()) << test::joinLines(r.unrepaired);
    EXPECT_NEAR(r.after.volume, 27.0, 1e-12);
    EXPECT_EQ(m.vertexCount(), 8u);
    expectNormalsAgreeWithFaces(m);
}

TEST(MeshRepair, WeldToleranceIsRelativeToTheBoundingBox) {
    Mesh near = test::unwelded(makeBox({0, 0, 0}, {1000, 1000, 1000}), true);
    near.positions[5].x += 1e-7; // 1e-10 of the diagonal: welded
    RepairReport r = repairMesh(near);
    EXPECT_TRUE(r.valid()) << test::joinLines(r.unrepaired);

    Mesh far = test::unwelded(makeBox({0, 0, 0}, {1000, 1000, 1000}), true);
    far.positions[5].x += 1e-3; // 5.8e-7 of the diagonal: kept apart, so the cube stays open
    r = repairMesh(far);
    EXPECT_FALSE(r.valid());
    EXPECT_TRUE(test::mentions(r.unrepaired, "not closed")) << test::joinLines(r.unrepaired);

    RepairOptions loose;
    loose.weldTolerance = 1e-5;
    Mesh far2 = test::unwelded(makeBox({0, 0, 0}, {1000, 1000, 1000}), true);
    far2.positions[5].x += 1e-3;
    r = repairMesh(far2, loose);
    EXPECT_TRUE(r.valid()) << test::joinLines(r.unrepaired);
}

TEST(MeshRepair, DegenerateAndDuplicateTrianglesAreRemoved) {
    Mesh m = makeBox({0, 0, 0}, {1, 1, 1});
    m.computeFlatNormals();
    m.triangles.push_back({1, 1, 2});
    m.triangles.push_back(m.triangles[3]);
    m.triangles.push_back({m.triangles[5][0], m.triangles[5][2], m.triangles[5][1]}); // reversed duplicate
    for (int i = 0; i < 9; ++i)
        m.normals.push_back({0, 0, 1});
    const RepairReport r = repairMesh(m);
    EXPECT_TRUE(r.valid()) << test::joinLines(r.unrepaired);
    EXPECT_EQ(r.removedDegenerate, 1u);
    EXPECT_EQ(r.removedDuplicates, 2u);
    EXPECT_EQ(m.triangleCount(), 12u);
    EXPECT_EQ(m.normals.size(), 36u);
}

TEST(MeshRepair, NaNVertexRemovesItsTrianglesAndReportsTheHole) {
    Mesh m = makeBox({0, 0, 0}, {1, 1, 1});
    m.positions[0].z = std::numeric_limits<double>::quiet_NaN();
    const RepairReport r = repairMesh(m);
    EXPECT_FALSE(r.valid());
    EXPECT_GT(r.removedNonFiniteTriangles, 0u);
    EXPECT_EQ(r.after.nonFiniteVertices, 0u);
    EXPECT_TRUE(test::mentions(r.fixed, "non-finite")) << test::joinLines(r.fixed);
    EXPECT_TRUE(test::mentions(r.unrepaired, "not closed")) << test::joinLines(r.unrepaired);
    EXPECT_TRUE(m.validate().isOk());
}

TEST(MeshRepair, OutOfRangeIndicesAreRemoved) {
    Mesh m = makeBox({0, 0, 0}, {1, 1, 1});
    m.triangles.push_back({0, 1, 99});
    const RepairReport r = repairMesh(m);
    EXPECT_TRUE(r.valid()) << test::joinLines(r.unrepaired);
    EXPECT_EQ(r.removedBadIndexTriangles, 1u);
}

TEST(MeshRepair, HolesThatAreNotPlanarAndNonManifoldEdgesAreReportedNotHidden) {
    // Two adjacent faces missing: one hole bent at a right angle, left open with what the user can do.
    Mesh open = makeBox({0, 0, 0}, {1, 1, 1});
    std::erase_if(open.triangles, [&](const Triangle& t) {
        return (open.positions[t[0]].z == 1 && open.positions[t[1]].z == 1 && open.positions[t[2]].z == 1) ||
               (open.positions[t[0]].y == 0 && open.positions[t[1]].y == 0 && open.positions[t[2]].y == 0);
    });
    ASSERT_EQ(open.triangles.size(), 8u);
    RepairOptions noFill;
    noFill.fillHoles = false;
    Mesh kept = open;
    EXPECT_FALSE(repairMesh(kept, noFill).valid());
    RepairReport r = repairMesh(open);
    EXPECT_FALSE(r.valid());
    EXPECT_FALSE(r.changed());
    EXPECT_EQ(r.filledHoles, 0u);
    EXPECT_EQ(r.openHoles, 1u);
    EXPECT_TRUE(test::mentions(r.unrepaired, "not closed")) << test::joinLines(r.unrepaired);
    EXPECT_TRUE(test::mentions(r.unrepaired, "not planar")) << test::joinLines(r.unrepaired);
    EXPECT_TRUE(test::mentions(r.unrepaired, "Remesh modifier")) << test::joinLines(r.unrepaired);
    EXPECT_EQ(open.triangles.size(), 8u);

    Mesh fin = makeBox({0, 0, 0}, {1, 1, 1});
    fin.positions.push_back({-1, -1, -1});
    fin.triangles.push_back({fin.triangles[0][0], fin.triangles[0][1], 8});
    r = repairMesh(fin);
    EXPECT_FALSE(r.valid());
    EXPECT_TRUE(test::mentions(r.unrepaired, "not manifold")) << test::joinLines(r.unrepaired);
}

TEST(MeshRepair, SelfIntersectionsAreReportedAsUnrepaired) {
    Mesh m = makeBox({0, 0, 0}, {2, 2, 2});
    m.append(makeBox({1, 1, 1}, {3, 3, 3}));
    const RepairReport r = repairMesh(m);
    EXPECT_FALSE(r.valid());
    EXPECT_TRUE(test::mentions(r.unrepaired, "intersect")) << test::joinLines(r.unrepaired);
}

TEST(MeshRepair, CavityIsOrientedInwardAndSubtracted) {
    // Outer box and an inner box, both written outward (a common modelling mistake for a hollow box).
    Mesh m = makeBox({0, 0, 0}, {4, 4, 4});
    m.append(makeBox({1, 1, 1}, {2, 2, 2}));
    const RepairReport r = repairMesh(m);
    EXPECT_TRUE(r.valid()) << test::joinLines(r.unrepaired);
    EXPECT_EQ(r.invertedShells, 1u);
    EXPECT_NEAR(r.after.volume, 64.0 - 1.0, 1e-12);

    // An already correct cavity is left alone.
    Mesh ok = m;
    const RepairReport again = repairMesh(ok);
    EXPECT_FALSE(again.changed()) << test::joinLines(again.fixed);
    EXPECT_EQ(ok, m);
}

TEST(MeshRepair, ValidMeshesAreUnchanged) {
    for (const Mesh& original : {makeSphere({0, 0, 0}, 1, 16, 8), makeTorus({1, 1, 1}, 2, 0.5, 16, 8)}) {
        Mesh m = original;
        m.computeFlatNormals();
        const Mesh before = m;
        const RepairReport r = repairMesh(m);
        EXPECT_TRUE(r.valid()) << test::joinLines(r.unrepaired);
        EXPECT_FALSE(r.changed()) << test::joinLines(r.fixed);
        EXPECT_EQ(m, before);
    }
}

TEST(MeshRepair, RandomFlipsOnASphereAreUndone) {
    const Mesh sphere = makeSphere({0.5, -2, 3}, 1.5, 20, 10);
    const double volume = signedVolume(sphere);
    Rng rng(7);
    for (int iter = 0; iter < 20; ++iter) {
        Mesh m = sphere;
        for (std::size_t t = 0; t < m.triangles.size(); ++t)
            if (rng.below(3) == 0)
                flip(m, t);
        const RepairReport r = repairMesh(m);
        EXPECT_TRUE(r.valid()) << test::joinLines(r.unrepaired);
        EXPECT_NEAR(r.after.volume, volume, 1e-9);
    }
}

TEST(MeshRepair, EmptyMeshStaysEmptyAndInvalid) {
    Mesh m;
    const RepairReport r = repairMesh(m);
    EXPECT_FALSE(r.valid());
    EXPECT_TRUE(test::mentions(r.unrepaired, "no triangles"));
}

TEST(MeshRepair, OverlappingShellsAreNotMistakenForCavities) {
    Mesh m = makeBox({0, 0, 0}, {2, 2, 2});
    m.append(makeBox({1, 1, 1}, {3, 3, 3}));
    const RepairReport r = repairMesh(m);
    EXPECT_EQ(r.invertedShells, 0u);
    EXPECT_NEAR(r.after.volume, 16.0, 1e-12);
}

TEST(MeshRepair, AttributeArraysOfTheWrongSizeAreDropped) {
    Mesh m = makeBox({0, 0, 0}, {1, 1, 1});
    m.uvs.assign(7, Vec2f{});
    const RepairReport r = repairMesh(m);
    EXPECT_TRUE(r.valid()) << test::joinLines(r.unrepaired);
    EXPECT_FALSE(m.hasUvs());
    EXPECT_TRUE(test::mentions(r.fixed, "dropped texture coordinates")) << test::joinLines(r.fixed);
    EXPECT_TRUE(m.validate().isOk());
}

namespace {
// Removes the triangles all of whose corners satisfy cut; returns how many.
template <class Cut>
std::size_t removeTriangles(Mesh& m, Cut cut) {
    const std::size_t before = m.triangles.size();
    std::erase_if(m.triangles, [&](const Triangle& t) {
        return cut(m.positions[t[0]]) && cut(m.positions[t[1]]) && cut(m.positions[t[2]]);
    });
    return before - m.triangles.size();
}

// Closed, consistently oriented, outward, and the expected volume to 1e-9 relative.
void expectClosedSolid(const Mesh& m, const RepairReport& r, double volume) {
    EXPECT_TRUE(r.valid()) << test::joinLines(r.unrepaired);
    EXPECT_TRUE(r.after.closed && r.after.oriented && r.after.outward);
    EXPECT_EQ(r.after.boundaryEdges, 0u);
    EXPECT_NEAR(signedVolume(m), volume, 1e-9 * std::abs(volume));
}
} // namespace

TEST(MeshRepair, ACubeWithAMissingFaceIsClosed) {
    Mesh m = makeBox({0, 0, 0}, {1, 1, 1});
    ASSERT_EQ(removeTriangles(m, [](const Vec3& p) { return p.z == 1; }), 2u);
    RepairOptions noFill;
    noFill.fillHoles = false;
    Mesh unfilled = m;
    EXPECT_FALSE(repairMesh(unfilled, noFill).valid()); // the mechanism below is what closes it
    const RepairReport r = repairMesh(m);
    EXPECT_EQ(r.filledHoles, 1u);
    EXPECT_TRUE(test::mentions(r.fixed, "closed 1 hole")) << test::joinLines(r.fixed);
    expectClosedSolid(m, r, 1.0);
    EXPECT_EQ(m.triangles.size(), 12u);
}

TEST(MeshRepair, ASphereWithItsCapCutOffIsClosedByAFlatDisc) {
    Mesh m = makeSphere({0, 0, 0}, 1.0, 24, 12); // poles on the y axis
    // The highest ring of vertices below the pole: the cut runs along it.
    double ring = -2;
    for (const Vec3& p : m.positions)
        if (p.y < 0.999 && p.y > ring)
            ring = p.y;
    ASSERT_EQ(removeTriangles(m, [&](const Vec3& p) { return p.y >= ring; }), 24u);
    // Expected: the open mesh's volume plus the flat disc's share, ring * area / 3 (divergence theorem with
    // the field p / 3; the disc faces +y), its area by the shoelace formula over the ring's vertices.
    std::vector<Vec3> rim;
    for (const Vec3& p : m.positions)
        if (p.y == ring)
            rim.push_back(p);
    ASSERT_EQ(rim.size(), 24u);
    std::sort(rim.begin(), rim.end(),
              [](const Vec3& a, const Vec3& b) { return std::atan2(a.z, a.x) < std::atan2(b.z, b.x); });
    double area = 0;
    for (std::size_t i = 0; i < rim.size(); ++i)
        area += rim[i].x * rim[(i + 1) % rim.size()].z - rim[(i + 1) % rim.size()].x * rim[i].z;
    const double expected = signedVolume(m) + ring * std::abs(area / 2) / 3;
    const RepairReport r = repairMesh(m);
    EXPECT_EQ(r.filledHoles, 1u);
    expectClosedSolid(m, r, expected);
    EXPECT_LT(expected, 4.0 / 3.0 * 3.14159265358979);
}

TEST(MeshRepair, AMeshWithTwoHolesIsClosed) {
    Mesh m = makeSubdividedBox({0, 0, 0}, {3, 3, 3}, 3);
    const auto middle = [](double v) { return v >= 1 && v <= 2; };
    ASSERT_EQ(removeTriangles(m, [&](const Vec3& p) { return p.z == 3 && middle(p.x) && middle(p.y); }), 2u);
    ASSERT_EQ(removeTriangles(m, [&](const Vec3& p) { return p.x == 0 && middle(p.y) && middle(p.z); }), 2u);
    const RepairReport r = repairMesh(m);
    EXPECT_EQ(r.filledHoles, 2u);
    EXPECT_EQ(r.openHoles, 0u);
    expectClosedSolid(m, r, 27.0);
}
