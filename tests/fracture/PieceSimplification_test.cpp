#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>

#include "TestSupport.hpp"
#include "rubble/core/Random.hpp"
#include "rubble/fracture/Fracture.hpp"
#include "rubble/geometry/MassProperties.hpp"
#include "rubble/geometry/MeshCheck.hpp"
#include "rubble/geometry/MeshSimplify.hpp"

namespace rubble {
namespace {

TEST(PieceSimplification, IsIdempotentAndDeterministic) {
    const Mesh box = makeSubdividedBox({0, 0, 0}, {1, 1, 1}, 10);
    FractureParams p;
    p.simplifyPieces = false;
    auto r = fracture(box, Impact{{1, 0.5, 0.5}, {1, 0, 0}, 40}, p, 7);
    ASSERT_TRUE(r);
    for (const Piece& piece : r->pieces) {
        const Mesh a = simplifyPlanarRegions(piece.mesh);
        test::expectSameSolid(piece.mesh, a);
        EXPECT_LE(a.triangleCount(), piece.mesh.triangleCount());
        EXPECT_EQ(simplifyPlanarRegions(piece.mesh).hash(), a.hash());
        EXPECT_EQ(simplifyPlanarRegions(a).triangleCount(), a.triangleCount());
    }
}

/// The reason it exists: the same spot hit again and again. Without simplification every crater leaves the
/// cut triangles' pieces behind; with it the remainder's size follows its shape.
TEST(PieceSimplification, RepeatedHitsKeepTheRemainderSmall) {
    for (const bool simplify : {false, true}) {
        Mesh m = makeBox({-2, -2, -2}, {2, 2, 2});
        FractureParams p;
        p.simplifyPieces = simplify;
        std::size_t peak = 0;
        for (int i = 0; i < 40; ++i) {
            const double y = -1.5 + 3.0 * ((i * 7) % 10) / 10.0, z = -1.5 + 3.0 * ((i * 3) % 10) / 10.0;
            auto r = fracture(m, Impact{{2, y, z}, {1, 0, 0}, 5}, p, static_cast<std::uint64_t>(100 + i));
            if (!r)
                continue;
            ASSERT_FALSE(r->pieces.empty());
            ASSERT_EQ(r->pieces[0].cell, -1);
            std::size_t best = 0;
            for (std::size_t k = 0; k < r->pieces.size(); ++k)
                if (r->pieces[k].cell == -1 && r->pieces[k].mass.volume > r->pieces[best].mass.volume)
                    best = k;
            m = r->pieces[best].mesh;
            peak = std::max(peak, m.triangleCount());
            const MeshReport rep = checkMesh(m);
            ASSERT_TRUE(rep.closed && rep.oriented) << "impact " << i;
        }
        RecordProperty(simplify ? "peak_simplified" : "peak_plain", static_cast<int>(peak));
        std::printf("40 hits on one face, simplify %d: remainder %zu triangles (peak %zu)\n",
                    simplify ? 1 : 0, m.triangleCount(), peak);
        if (simplify) {
            EXPECT_LT(peak, 2500u);
        }
    }
}

/// Texture coordinates of a crater's faces stay when the piece is hit elsewhere later (they used to be
/// re-projected onto whichever plane of the new cells was nearest).
TEST(PieceSimplification, AnEarlierCratersTextureStays) {
    const Mesh box = makeBox({-2, -1, -1}, {2, 1, 1});
    FractureParams p;
    auto first = fracture(box, Impact{{-2, 0, 0}, {-1, 0, 0}, 20}, p, 3);
    ASSERT_TRUE(first);
    const Mesh& r1 = first->pieces[0].mesh;
    auto second = fracture(r1, Impact{{2, 0, 0}, {1, 0, 0}, 20}, p, 4);
    ASSERT_TRUE(second);
    const Mesh& r2 = second->pieces[0].mesh;
    std::map<std::array<double, 9>, std::array<double, 6>> before;
    auto key = [](const Mesh& m, std::size_t t) {
        const auto c = m.corners(t);
        return std::array<double, 9>{c[0].x, c[0].y, c[0].z, c[1].x, c[1].y, c[1].z, c[2].x, c[2].y, c[2].z};
    };
    auto uv = [](const Mesh& m, std::size_t t) {
        return std::array<double, 6>{m.uvs[3 * t].x,     m.uvs[3 * t].y,     m.uvs[3 * t + 1].x,
                                     m.uvs[3 * t + 1].y, m.uvs[3 * t + 2].x, m.uvs[3 * t + 2].y};
    };
    for (std::size_t t = 0; t < r1.triangleCount(); ++t)
        if (r1.material(t) == kInteriorMaterial)
            before[key(r1, t)] = uv(r1, t);
    ASSERT_FALSE(before.empty());
    std::size_t same = 0;
    for (std::size_t t = 0; t < r2.triangleCount(); ++t) {
        const auto it = before.find(key(r2, t));
        if (r2.material(t) != kInteriorMaterial || it == before.end())
            continue;
        ++same;
        EXPECT_EQ(uv(r2, t), it->second) << "triangle " << t;
    }
    EXPECT_GT(same, 0u); // the first crater is still there
}

/// Simplifying a mesh given by value (written over it when the new triangles fit) gives what simplifying a
/// copy gives: the same mesh, report and integrals change, over the pieces of random hits with attributes.
TEST(PieceSimplification, InPlaceEqualsCopy) {
    Mesh box = makeSubdividedBox({0, 0, 0}, {2, 1, 1}, 12);
    box.computeFlatNormals();
    box.uvs.resize(3 * box.triangleCount());
    for (std::size_t c = 0; c < box.uvs.size(); ++c) {
        const Vec3& p = box.positions[box.triangles[c / 3][c % 3]];
        box.uvs[c] = {p.x + 0.5 * p.z, p.y - 0.25 * p.z};
    }
    Rng rng(0x1F1ACE);
    int changed = 0;
    for (const Mesh& mesh : {box, makeSphere({0, 0, 0}, 1, 40, 20)}) {
        for (int i = 0; i < 12; ++i) {
            FractureParams p;
            p.simplifyPieces = false;
            p.pattern = i % 3 == 0 ? CellPattern::Shatter : CellPattern::SingleCell;
            p.cells = 5;
            const Vec3 at = test::surfacePoint(mesh, rng);
            auto r = fracture(mesh, Impact{at, normalized(at - mesh.bounds().center()), 60}, p, rng.next());
            ASSERT_TRUE(r);
            for (const Piece& piece : r->pieces) {
                PlanarSimplifyParams sp;
                sp.integralsReference = {0.1, 0.2, 0.3};
                PlanarSimplifyReport copied, moved;
                const Mesh a = simplifyPlanarRegions(piece.mesh, sp, &copied);
                const Mesh b = simplifyPlanarRegions(Mesh(piece.mesh), sp, &moved);
                EXPECT_EQ(a, b);
                EXPECT_EQ(copied.trianglesAfter, moved.trianglesAfter);
                EXPECT_EQ(copied.verticesRemoved, moved.verticesRemoved);
                EXPECT_EQ(copied.regionsRetriangulated, moved.regionsRetriangulated);
                EXPECT_EQ(copied.integralsChange.volume, moved.integralsChange.volume);
                EXPECT_EQ(copied.integralsChange.cov[0][1], moved.integralsChange.cov[0][1]);
                changed += copied.unchanged ? 0 : 1;
            }
        }
    }
    EXPECT_GE(changed, 20);
}

} // namespace
} // namespace rubble
