#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "TestSupport.hpp"
#include "rubble/core/Random.hpp"
#include "rubble/geometry/MassProperties.hpp"
#include "rubble/geometry/MeshCheck.hpp"

using namespace rubble;

TEST(MeshCheck, ClosedShapesAreValid) {
    for (const Mesh& m : {makeBox({0, 0, 0}, {1, 2, 3}), makeSubdividedBox({-1, -1, -1}, {1, 1, 1}, 4),
                          makeSphere({1, 2, 3}, 2, 24, 12), makeTorus({0, 0, 0}, 3, 1, 24, 12)}) {
        const MeshReport r = checkMesh(m);
        EXPECT_TRUE(r.valid()) << test::joinLines(r.problems);
        EXPECT_TRUE(r.closed);
        EXPECT_TRUE(r.edgeManifold);
        EXPECT_TRUE(r.oriented);
        EXPECT_TRUE(r.outward);
        EXPECT_TRUE(r.selfIntersectionsChecked) << r.selfIntersectionNote;
        EXPECT_EQ(r.selfIntersections, 0u);
        EXPECT_TRUE(r.problems.empty());
        EXPECT_EQ(r.vertices, m.vertexCount());
        EXPECT_EQ(r.triangles, m.triangleCount());
        EXPECT_EQ(r.shells, 1u);
        EXPECT_NEAR(r.volume, signedVolume(m), 1e-9 * std::abs(r.volume));
    }
}

TEST(MeshCheck, BoxFarFromOriginReportsExactGeometry) {
    const Mesh m = makeBox({1e6, 1e6, 1e6}, {1e6 + 2, 1e6 + 4, 1e6 + 6});
    const MeshReport r = checkMesh(m);
    EXPECT_TRUE(r.valid()) << test::joinLines(r.problems);
    EXPECT_NEAR(r.volume, 48.0, 1e-6);
    EXPECT_NEAR(r.centerOfMass.x, 1e6 + 1, 1e-6);
    EXPECT_NEAR(r.centerOfMass.y, 1e6 + 2, 1e-6);
    EXPECT_NEAR(r.centerOfMass.z, 1e6 + 3, 1e-6);
    EXPECT_EQ(r.bounds.lo.x, 1e6);
    EXPECT_EQ(r.bounds.hi.z, 1e6 + 6);
}

TEST(MeshCheck, OpenCubeIsNotClosed) {
    Mesh m = makeBox({0, 0, 0}, {1, 1, 1});
    m.triangles.pop_back();
    const MeshReport r = checkMesh(m);
    EXPECT_FALSE(r.valid());
    EXPECT_FALSE(r.closed);
    EXPECT_TRUE(r.edgeManifold);
    EXPECT_TRUE(r.oriented);
    EXPECT_EQ(r.boundaryEdges, 3u);
    EXPECT_TRUE(test::mentions(r.problems, "not closed (holes): 3 edges are used by only one triangle"))
        << test::joinLines(r.problems);
}

TEST(MeshCheck, OneFlippedFaceIsNotOriented) {
    Mesh m = makeBox({0, 0, 0}, {1, 1, 1});
    std::swap(m.triangles[4][1], m.triangles[4][2]);
    const MeshReport r = checkMesh(m);
    EXPECT_FALSE(r.valid());
    EXPECT_TRUE(r.closed);
    EXPECT_FALSE(r.oriented);
    EXPECT_EQ(r.misorientedEdges, 3u);
    EXPECT_TRUE(test::mentions(r.problems, "not consistently oriented")) << test::joinLines(r.problems);
}

TEST(MeshCheck, InvertedCubeIsInsideOut) {
    Mesh m = makeBox({0, 0, 0}, {1, 1, 1});
    for (Triangle& t : m.triangles)
        std::swap(t[1], t[2]);
    const MeshReport r = checkMesh(m);
    EXPECT_FALSE(r.valid());
    EXPECT_TRUE(r.closed);
    EXPECT_TRUE(r.oriented);
    EXPECT_FALSE(r.outward);
    EXPECT_NEAR(r.volume, -1.0, 1e-12);
    EXPECT_TRUE(test::mentions(r.problems, "inside out")) << test::joinLines(r.problems);
}

TEST(MeshCheck, DuplicatedVerticesLeaveEveryEdgeOpen) {
    const Mesh m = test::unwelded(makeBox({0, 0, 0}, {1, 1, 1}));
    const MeshReport r = checkMesh(m);
    EXPECT_FALSE(r.valid());
    EXPECT_FALSE(r.closed);
    EXPECT_EQ(r.boundaryEdges, 36u);
    EXPECT_EQ(r.shells, 12u);
    EXPECT_NEAR(r.volume, 1.0, 1e-12); // the volume integral does not need shared vertices
}

TEST(MeshCheck, ThreeTrianglesOnAnEdgeAreNonManifold) {
    Mesh m = makeBox({0, 0, 0}, {1, 1, 1});
    // A fin sticking out of the edge between vertex 0 and the next corner of triangle 0.
    const Triangle t0 = m.triangles[0];
    m.positions.push_back({-1, -1, -1});
    m.triangles.push_back({t0[0], t0[1], static_cast<std::uint32_t>(m.positions.size() - 1)});
    const MeshReport r = checkMesh(m);
    EXPECT_FALSE(r.valid());
    EXPECT_FALSE(r.edgeManifold);
    EXPECT_FALSE(r.closed);
    EXPECT_EQ(r.nonManifoldEdges, 1u);
    EXPECT_FALSE(r.selfIntersectionsChecked);
    EXPECT_NE(r.selfIntersectionNote.find("non-manifold"), std::string::npos);
    EXPECT_TRUE(test::mentions(r.problems, "has 3 triangles")) << test::joinLines(r.problems);
}

TEST(MeshCheck, NonFiniteCoordinatesAreReportedNotComputedWith) {
    for (double bad : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
        Mesh m = makeBox({0, 0, 0}, {1, 1, 1});
        m.positions[3].y = bad;
        const MeshReport r = checkMesh(m);
        EXPECT_FALSE(r.valid());
        EXPECT_EQ(r.nonFiniteVertices, 1u);
        EXPECT_EQ(r.volume, 0.0);
        EXPECT_FALSE(r.selfIntersectionsChecked);
        EXPECT_TRUE(
            test::mentions(r.problems, "1 vertex has a non-finite coordinate (NaN or infinity) (vertex 3)"))
            << test::joinLines(r.problems);
        EXPECT_TRUE(isFinite(r.bounds.lo) && isFinite(r.bounds.hi));
    }
}

TEST(MeshCheck, OutOfRangeIndicesAreReportedWithoutCrashing) {
    Mesh m = makeBox({0, 0, 0}, {1, 1, 1});
    m.triangles[2][1] = 100;
    const MeshReport r = checkMesh(m);
    EXPECT_FALSE(r.valid());
    EXPECT_EQ(r.badIndices, 1u);
    EXPECT_TRUE(test::mentions(r.problems, "triangle 2 refers to vertex 100 of 8"))
        << test::joinLines(r.problems);
}

TEST(MeshCheck, DegenerateAndDuplicateTriangles) {
    Mesh m = makeBox({0, 0, 0}, {1, 1, 1});
    m.triangles.push_back({0, 0, 1}); // repeated index
    m.positions.push_back({0.5, 0, 0});
    m.triangles.push_back({0, 1, 8}); // three collinear points? only if 0,1,8 are collinear
    const Triangle first = m.triangles[0];
    m.triangles.push_back(first); // exact duplicate
    const MeshReport r = checkMesh(m);
    EXPECT_FALSE(r.valid());
    EXPECT_GE(r.degenerateTriangles, 1u);
    EXPECT_EQ(r.duplicateTriangles, 1u);
    EXPECT_TRUE(test::mentions(r.problems, "degenerate")) << test::joinLines(r.problems);
    EXPECT_TRUE(test::mentions(r.problems, "duplicates an earlier triangle")) << test::joinLines(r.problems);
}

TEST(MeshCheck, CollinearTriangleIsDegenerate) {
    EXPECT_TRUE(isDegenerateTriangle({0, 0, 0}, {1, 1, 1}, {2, 2, 2}));
    EXPECT_TRUE(isDegenerateTriangle({1, 2, 3}, {1, 2, 3}, {1, 2, 3}));
    EXPECT_FALSE(isDegenerateTriangle({0, 0, 0}, {1, 0, 0}, {0, 1e-6, 0}));
}

TEST(MeshCheck, OverlappingBoxesSelfIntersect) {
    Mesh m = makeBox({0, 0, 0}, {2, 2, 2});
    m.append(makeBox({1, 1, 1}, {3, 3, 3}));
    const MeshReport r = checkMesh(m);
    EXPECT_TRUE(r.closed);
    EXPECT_TRUE(r.oriented);
    EXPECT_TRUE(r.selfIntersectionsChecked) << r.selfIntersectionNote;
    EXPECT_GT(r.selfIntersections, 0u);
    EXPECT_FALSE(r.valid());
    EXPECT_TRUE(test::mentions(r.problems, "intersect")) << test::joinLines(r.problems);

    CheckOptions skip;
    skip.selfIntersections = false;
    const MeshReport fast = checkMesh(m, skip);
    EXPECT_FALSE(fast.selfIntersectionsChecked);
    EXPECT_TRUE(fast.valid()); // without the test, two overlapping closed boxes look fine
}

TEST(MeshCheck, SelfIntersectionCountCanBeCapped) {
    Mesh m = makeSubdividedBox({0, 0, 0}, {2, 2, 2}, 3);
    m.append(makeSubdividedBox({1, 1, 1}, {3, 3, 3}, 3));
    CheckOptions capped;
    capped.maxSelfIntersections = 2;
    const MeshReport r = checkMesh(m, capped);
    EXPECT_TRUE(r.selfIntersectionsCapped);
    EXPECT_GE(r.selfIntersections, 1u);
    EXPECT_TRUE(test::mentions(r.problems, "at least")) << test::joinLines(r.problems);
}

TEST(MeshCheck, SeparateBoxesDoNotIntersect) {
    Mesh m = makeBox({0, 0, 0}, {1, 1, 1});
    m.append(makeBox({2, 0, 0}, {3, 1, 1}));
    const MeshReport r = checkMesh(m);
    EXPECT_TRUE(r.valid()) << test::joinLines(r.problems);
    EXPECT_EQ(r.shells, 2u);
    EXPECT_NEAR(r.volume, 2.0, 1e-12);
}

TEST(MeshCheck, MisorientedMeshStillGetsSelfIntersectionVerdict) {
    Mesh m = makeBox({0, 0, 0}, {1, 1, 1});
    std::swap(m.triangles[0][1], m.triangles[0][2]);
    const MeshReport r = checkMesh(m);
    EXPECT_TRUE(r.selfIntersectionsChecked) << r.selfIntersectionNote;
    EXPECT_EQ(r.selfIntersections, 0u);
}

TEST(MeshCheck, EmptyMeshIsInvalid) {
    const MeshReport r = checkMesh(Mesh{});
    EXPECT_FALSE(r.valid());
    EXPECT_TRUE(test::mentions(r.problems, "no triangles"));
    EXPECT_TRUE(r.bounds.empty());
}

TEST(MeshCheck, RandomIndexSoupsNeverCrash) {
    Rng rng(42);
    for (int iter = 0; iter < 200; ++iter) {
        Mesh m;
        const std::size_t nv = 1 + rng.below(12), nt = rng.below(20);
        for (std::size_t i = 0; i < nv; ++i)
            m.positions.push_back(rng.inBox({-1, -1, -1}, {1, 1, 1}));
        if (rng.below(4) == 0)
            m.positions[rng.below(nv)].x = std::numeric_limits<double>::quiet_NaN();
        for (std::size_t t = 0; t < nt; ++t)
            m.triangles.push_back({static_cast<std::uint32_t>(rng.below(nv + 1)),
                                   static_cast<std::uint32_t>(rng.below(nv)),
                                   static_cast<std::uint32_t>(rng.below(nv))});
        const MeshReport r = checkMesh(m);
        EXPECT_EQ(r.triangles, nt);
        if (nt > 0 && !r.valid()) {
            EXPECT_FALSE(r.problems.empty());
        }
    }
}

TEST(MeshCheck, SolidsTouchingAtOneVertexAreNotManifold) {
    // Two tetrahedra sharing only vertex 0 (by index): every edge has two triangles, but vertex 0 is pinched.
    Mesh m;
    m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {-1, 0, 0}, {0, -1, 0}, {0, 0, -1}};
    m.triangles = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}, {0, 4, 5}, {0, 6, 4}, {4, 6, 5}, {5, 6, 0}};
    ASSERT_GT(signedVolume(m), 0);
    const MeshReport r = checkMesh(m);
    EXPECT_TRUE(r.closed);
    EXPECT_TRUE(r.edgeManifold);
    EXPECT_TRUE(r.oriented);
    EXPECT_FALSE(r.vertexManifold);
    EXPECT_FALSE(r.manifold());
    EXPECT_EQ(r.nonManifoldVertices, 1u);
    EXPECT_FALSE(r.valid());
    EXPECT_FALSE(r.selfIntersectionsChecked);
    EXPECT_EQ(r.selfIntersectionNote, "skipped: the mesh has non-manifold vertices");
    EXPECT_TRUE(
        test::mentions(r.problems, "1 vertex joins parts that share no edge there (pinched) (vertex 0)"))
        << test::joinLines(r.problems);

    // Valid meshes have manifold vertices, including open ones with one boundary fan per vertex.
    EXPECT_TRUE(checkMesh(makeTorus({0, 0, 0}, 2, 1, 12, 8)).vertexManifold);
    Mesh open = makeBox({0, 0, 0}, {1, 1, 1});
    open.triangles.pop_back();
    EXPECT_TRUE(checkMesh(open).vertexManifold);
}

TEST(MeshCheck, AttributeArraysOfTheWrongSizeAreReported) {
    Mesh m = makeBox({0, 0, 0}, {1, 1, 1});
    m.normals.assign(5, Vec3f{0, 0, 1});
    m.materials.assign(3, 0);
    const MeshReport r = checkMesh(m);
    EXPECT_FALSE(r.valid());
    EXPECT_EQ(r.badAttributeArrays, 2u);
    EXPECT_TRUE(test::mentions(r.problems, "normals have 5 entries but 36 are needed (3 per triangle)"))
        << test::joinLines(r.problems);
    EXPECT_TRUE(test::mentions(r.problems, "material ids have 3 entries but 12 are needed (1 per triangle)"))
        << test::joinLines(r.problems);
}

TEST(MeshCheck, SelfIntersectionTestIsSkippedAroundVeryHighValenceVertices) {
    // CGAL's test is quadratic (and worse) around a shared vertex: a 60k-triangle fan did not finish in 8
    // min.
    auto cone = [](std::uint32_t n) {
        Mesh m;
        for (std::uint32_t i = 0; i < n; ++i)
            m.positions.push_back(
                {std::cos(2 * 3.141592653589793 * i / n), std::sin(2 * 3.141592653589793 * i / n), 0});
        m.positions.push_back({0, 0, 1});
        m.positions.push_back({0, 0, 0});
        for (std::uint32_t i = 0; i < n; ++i) {
            m.triangles.push_back({i, (i + 1) % n, n});
            m.triangles.push_back({(i + 1) % n, i, n + 1});
        }
        return m;
    };
    const MeshReport big = checkMesh(cone(60000));
    EXPECT_FALSE(big.selfIntersectionsChecked);
    EXPECT_EQ(big.selfIntersectionNote,
              "skipped: vertex 60000 is shared by 60000 triangles, more than 2048 (the test "
              "takes quadratic time around such a vertex)");
    EXPECT_TRUE(big.valid()); // the other checks still ran
    EXPECT_TRUE(big.closed && big.manifold() && big.oriented);
    const MeshReport small = checkMesh(cone(500));
    EXPECT_TRUE(small.selfIntersectionsChecked);
    EXPECT_EQ(small.selfIntersections, 0u);
}

TEST(MeshCheck, HugeAndTinyMeshesAreJudgedWithoutOverflow) {
    // A cube scaled by 1e300 was reported "encloses no volume" (and its triangles degenerate): it overflowed.
    const MeshReport huge = checkMesh(makeBox({0, 0, 0}, {1e300, 1e300, 1e300}));
    EXPECT_FALSE(huge.valid());
    EXPECT_EQ(huge.degenerateTriangles, 0u);
    EXPECT_EQ(huge.hugeVertices, 7u);
    ASSERT_EQ(huge.problems.size(), 1u) << test::joinLines(huge.problems);
    EXPECT_EQ(huge.problems[0].rfind("7 vertices have a coordinate beyond ±1e+50, the bound that keeps the "
                                     "volume integrals finite (e.g. vertex 1 at 1e+300",
                                     0),
              0u)
        << huge.problems[0];
    // 1e-100: the squared areas (1e-400) underflowed and every triangle was called degenerate.
    const MeshReport tiny = checkMesh(makeBox({0, 0, 0}, {1e-100, 1e-100, 1e-100}));
    EXPECT_TRUE(tiny.valid()) << test::joinLines(tiny.problems);
    EXPECT_EQ(tiny.degenerateTriangles, 0u);
    // Scaling by powers of two changes nothing for ordinary triangles.
    EXPECT_TRUE(isDegenerateTriangle({0, 0, 0}, {1, 0, 0}, {2, 1e-13, 0}));
    EXPECT_FALSE(isDegenerateTriangle({0, 0, 0}, {1, 0, 0}, {2, 1e-11, 0}));
    EXPECT_TRUE(isDegenerateTriangle({5, 5, 5}, {5, 5, 5}, {1, 2, 3}));
}

TEST(MeshCheck, ElementNumbersCountFromZero) {
    // Every message numbers vertices, triangles and edge ends as the indices of Mesh::positions and
    // triangles.
    Mesh nan = makeBox({0, 0, 0}, {1, 1, 1});
    nan.positions[0].x = std::numeric_limits<double>::quiet_NaN();
    EXPECT_TRUE(test::mentions(checkMesh(nan).problems, "(vertex 0)"))
        << test::joinLines(checkMesh(nan).problems);
    EXPECT_EQ(nan.validate().message(), "vertex 0 has a non-finite coordinate");

    Mesh open = makeBox({0, 0, 0}, {1, 1, 1});
    const Triangle removed = open.triangles.back();
    open.triangles.pop_back();
    const std::vector<std::string> problems = checkMesh(open).problems;
    bool named = false;
    for (int c = 0; c < 3; ++c) {
        const std::uint32_t a = std::min(removed[c], removed[(c + 1) % 3]);
        const std::uint32_t b = std::max(removed[c], removed[(c + 1) % 3]);
        named = named || test::mentions(problems, "edge " + std::to_string(a) + "-" + std::to_string(b));
    }
    EXPECT_TRUE(named) << test::joinLines(problems);

    Mesh bad = makeBox({0, 0, 0}, {1, 1, 1});
    bad.triangles[0][2] = 8;
    EXPECT_EQ(bad.validate().message(), "triangle 0 refers to vertex 8 of 8");
}

// Round 3, defect 10: a cube of half-size 1e150 was valid with an infinite volume, and from 1e78 to 1e102 its
// centre of mass was NaN; coordinates beyond ±kMaxCoordinate are invalid input, within it the integrals are
// finite.
TEST(MeshCheck, CoordinatesBeyondTheBoundAreInvalid) {
    for (double h : {1e150, 1e90, 1e60}) {
        const Mesh m = makeBox({-h, -h, -h}, {h, h, h});
        const MeshReport r = checkMesh(m);
        EXPECT_FALSE(r.valid()) << h;
        EXPECT_EQ(r.hugeVertices, 8u) << h;
        ASSERT_FALSE(r.problems.empty());
        EXPECT_NE(r.problems[0].find("beyond ±1e+50"), std::string::npos) << r.problems[0];
        const Status s = checkCoordinateRange(m, "m");
        ASSERT_FALSE(s.isOk());
        EXPECT_EQ(s.error().code, ErrorCode::InvalidInput);
        EXPECT_NE(s.message().find("m: vertex 0 has a coordinate of"), std::string::npos) << s.message();
    }
    const Mesh edge = makeBox({-kMaxCoordinate, -kMaxCoordinate, -kMaxCoordinate},
                              {kMaxCoordinate, kMaxCoordinate, kMaxCoordinate});
    const MeshReport r = checkMesh(edge);
    EXPECT_TRUE(r.valid()) << test::joinLines(r.problems);
    EXPECT_TRUE(std::isfinite(r.volume));
    EXPECT_TRUE(isFinite(r.centerOfMass));
    const MassProperties mp = computeMassProperties(edge);
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            EXPECT_TRUE(std::isfinite(mp.inertia.m[i][j])) << i << j;
    EXPECT_TRUE(checkCoordinateRange(edge, "m").isOk());
}

namespace {
Mesh inverted(Mesh m) {
    for (Triangle& t : m.triangles)
        std::swap(t[1], t[2]);
    return m;
}
} // namespace

// Round 3, defect 6: two nested cubes both facing outward were a valid solid of volume 9 (8 enclosed).
TEST(MeshCheck, AnInnerShellMustFaceInward) {
    Mesh nested = makeBox({-1, -1, -1}, {1, 1, 1});
    nested.append(makeBox({-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5}));
    const MeshReport bad = checkMesh(nested);
    EXPECT_FALSE(bad.valid());
    EXPECT_EQ(bad.shells, 2u);
    EXPECT_EQ(bad.misnestedShells, 1u);
    EXPECT_TRUE(test::mentions(bad.problems, "1 shell faces the wrong way for its nesting"))
        << test::joinLines(bad.problems);
    EXPECT_TRUE(
        test::mentions(bad.problems, "the shell of triangle 12 lies inside 1 other shell and faces outward"))
        << test::joinLines(bad.problems);

    // The inner shell facing inward is a cavity: valid, volume 8 - 1.
    Mesh hollow = makeBox({-1, -1, -1}, {1, 1, 1});
    hollow.append(inverted(makeBox({-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5})));
    const MeshReport cavity = checkMesh(hollow);
    EXPECT_TRUE(cavity.valid()) << test::joinLines(cavity.problems);
    EXPECT_NEAR(cavity.volume, 7.0, 1e-12);

    // A solid inside the cavity faces outward again (depth 2); a lone shell facing inward next to another is
    // wrong although the total volume is positive.
    Mesh island = hollow;
    island.append(makeBox({-0.1, -0.1, -0.1}, {0.1, 0.1, 0.1}));
    EXPECT_TRUE(checkMesh(island).valid()) << test::joinLines(checkMesh(island).problems);
    Mesh apart = makeBox({0, 0, 0}, {2, 2, 2});
    apart.append(inverted(makeBox({5, 0, 0}, {6, 1, 1})));
    const MeshReport lone = checkMesh(apart);
    EXPECT_FALSE(lone.valid());
    EXPECT_EQ(lone.misnestedShells, 1u);
    EXPECT_TRUE(test::mentions(lone.problems, "lies inside 0 other shells and faces inward"))
        << test::joinLines(lone.problems);
}
