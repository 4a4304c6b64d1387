#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "rubble/Fracture.hpp"
#include "rubble/MassProperties.hpp"
#include "rubble/MeshCheck.hpp"
#include "rubble/MeshSimplify.hpp"

namespace rubble {
namespace {

void expectClosedSameVolume(const Mesh& before, const Mesh& after) {
    const MeshReport r = checkMesh(after);
    EXPECT_TRUE(r.closed);
    EXPECT_TRUE(r.oriented);
    EXPECT_EQ(r.degenerateTriangles, 0u);
    EXPECT_NEAR(signedVolume(after), signedVolume(before), 1e-9 * std::abs(signedVolume(before)));
}

TEST(PieceSimplification, IsIdempotentAndDeterministic) {
    const Mesh box = makeSubdividedBox({0, 0, 0}, {1, 1, 1}, 10);
    FractureParams p;
    p.simplifyPieces = false;
    auto r = fracture(box, Impact{{1, 0.5, 0.5}, {1, 0, 0}, 40}, p, 7);
    ASSERT_TRUE(r);
    for (const Piece& piece : r->pieces) {
        const Mesh a = simplifyPlanarRegions(piece.mesh);
        expectClosedSameVolume(piece.mesh, a);
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

} // namespace
} // namespace rubble
