// Parts of pieces above DecompositionParams::proxyAboveTriangles stay near their piece's convex hull: chained
// hits on meshes just above a lowered threshold (the same path as a 100k mesh at the default one).
#include <gtest/gtest.h>

#include "PartOverlap.hpp"
#include "SurfaceImpact.hpp"
#include "collision/HullWitness.hpp"
#include "rubble/collision/CollisionTolerance.hpp"
#include "rubble/collision/ConvexDecomposition.hpp"
#include "rubble/core/Random.hpp"
#include "rubble/fracture/Fracture.hpp"

namespace rubble {
namespace {

/// Chained hits (random surface points, seed-derived), each on the largest piece of the previous one with the
/// parts its update gave it; the worst reach of any piece's parts out of its hull, over its diagonal.
double worstReachOverChain(Mesh mesh, const DecompositionParams& dp, int hits, std::uint64_t seed) {
    auto d = decompose(mesh, dp);
    EXPECT_TRUE(d) << d.error().message;
    if (!d)
        return 1;
    std::vector<ConvexPolytope> parts = d->parts;
    double worst = test::reachOutsideHull(mesh, parts);
    Rng rng(seed);
    for (int hit = 0; hit < hits; ++hit) {
        FractureParams fp;
        fp.sizeLaw.base = 0.45;
        fp.sizeLaw.scale = 0;
        auto fr = fracture(mesh, test::randomSurfaceImpact(mesh, rng, 10), fp, seed + hit);
        if (!fr)
            continue;
        const auto updated = updateDecomposition(parts, *fr, dp);
        EXPECT_EQ(updated.size(), fr->pieces.size());
        std::size_t largest = 0;
        for (std::size_t i = 0; i < fr->pieces.size() && i < updated.size(); ++i) {
            const Mesh& piece = fr->pieces[i].mesh;
            worst = std::max(worst, test::reachOutsideHull(piece, updated[i]));
            EXPECT_LE(updated[i].size(), static_cast<std::size_t>(kCraterBudgetFactor * dp.maxParts));
            // Every vertex (every 7th) stays in some part.
            const double eps = 1e-7 * piece.bounds().diagonal();
            for (std::size_t v = 0; v < piece.positions.size(); v += 7) {
                bool in = false;
                for (const ConvexPolytope& p : updated[i])
                    in = in || p.contains(piece.positions[v], eps);
                EXPECT_TRUE(in) << "hit " << hit << " piece " << i << ": vertex " << v << " is in no part";
            }
            if (fr->pieces[i].mass.volume > fr->pieces[largest].mass.volume)
                largest = i;
        }
        mesh = fr->pieces[largest].mesh;
        parts = updated[largest];
    }
    return worst;
}

TEST(HullReach, AWitnessedPointLiesWithinReachOfTheHull) {
    // Random points around a torus, a box with large faces and a piece with cut faces: every point the
    // witness calls near is within reach of the exact hull, and most points inside the solid are called near.
    const Mesh torus = makeTorus({0, 0, 0}, 1.0, 0.3, 40, 16);
    auto cut = fractureWithCells(torus, {ConvexPolytope::fromAabb({{0.5, -2, -1}, {2, 0.2, 1}})}, {});
    ASSERT_TRUE(cut) << cut.error().message;
    const Mesh meshes[] = {torus, makeBox({-1, -0.5, -0.2}, {1, 0.5, 0.2}), cut->pieces.front().mesh};
    Rng rng(9);
    for (const Mesh& mesh : meshes) {
        const ConvexPolytope hull = convexHull(mesh.positions).value();
        const double reach = 0.01 * mesh.bounds().diagonal();
        const detail::HullWitness witness(mesh, reach);
        Aabb box = mesh.bounds();
        box.lo -= Vec3{0.1, 0.1, 0.1};
        box.hi += Vec3{0.1, 0.1, 0.1};
        int near = 0, inside = 0, insideNear = 0;
        for (int i = 0; i < 1500; ++i) {
            const Vec3 p = rng.inBox(box.lo, box.hi);
            double out = -1e300;
            for (const PolytopeFaceView& f : hull.faces())
                out = std::max(out, f.plane.signedDistance(p));
            const bool in = windingNumber(mesh, p) > 0.5;
            const bool n = witness.near(p);
            inside += in;
            insideNear += in && n;
            near += n;
            if (n) {
                ASSERT_LE(out, reach * (1 + 1e-9))
                    << "a point called near lies " << out << " out of the hull";
            }
        }
        EXPECT_GT(near, 0);
        EXPECT_GE(insideNear, inside * 9 / 10) << "points inside the solid not called near";
    }
}

TEST(HullReach, ChainedHitsAboveTheHighPolyThresholdKeepPartsNearTheirPiecesHull) {
    DecompositionParams dp;
    dp.proxyAboveTriangles = 1500;
    const Mesh mesh = makeSphere({0, 0, 0}, 1.0, 48, 40);
    ASSERT_GT(mesh.triangles.size(), dp.proxyAboveTriangles);
    EXPECT_LE(worstReachOverChain(mesh, dp, 4, 3), kPartHullTolerance);
}

TEST(HullReach, AFirstDecompositionThroughAProxyKeepsItsPartsNearTheHull) {
    // Few faces per part make the proxy path's bounded hulls reach far out (the pushed-out planes of a few
    // extremes: 4.3 % of the diagonal here); the witness keeps every part near the torus's hull.
    DecompositionParams dp;
    dp.proxyAboveTriangles = 1000;
    dp.maxPartFaces = 16;
    dp.concavity = 0.005;
    const Mesh mesh = makeTorus({0, 0, 0}, 1.0, 0.35, 48, 24);
    ASSERT_GT(mesh.triangles.size(), dp.proxyAboveTriangles);
    auto d = decompose(mesh, dp);
    ASSERT_TRUE(d) << d.error().message;
    EXPECT_GT(d->parts.size(), 4u);
    EXPECT_LE(test::reachOutsideHull(mesh, d->parts), kPartHullTolerance);
}

TEST(HullReach, AWallCutFromAChannelLeavesNoPartOverTheOpenedSide) {
    // A channel (a box with a slot along y) decomposed into one part, its hull (the whole box); a cut then
    // takes one wall. The remainder's hull no longer covers the slot, which the part minus the cut still
    // does.
    DecompositionParams dp;
    dp.proxyAboveTriangles = 1500;
    const Mesh box = makeSubdividedBox({-1, -1, -1}, {1, 1, 1}, 16);
    ASSERT_GT(box.triangles.size(), dp.proxyAboveTriangles);
    const FractureParams fp;
    auto slot = fractureWithCells(box, {ConvexPolytope::fromAabb({{-0.4, -2, 0}, {0.4, 2, 2}})}, fp);
    ASSERT_TRUE(slot) << slot.error().message;
    const Mesh* channel = nullptr;
    for (const Piece& p : slot->pieces)
        if (p.cell < 0)
            channel = &p.mesh;
    ASSERT_NE(channel, nullptr);
    ASSERT_GT(channel->triangles.size(), dp.proxyAboveTriangles);
    DecompositionParams whole = dp;
    whole.maxParts = 1;
    auto d = decompose(*channel, whole);
    ASSERT_TRUE(d) << d.error().message;
    ASSERT_EQ(d->parts.size(), 1u);
    auto wall = fractureWithCells(*channel, {ConvexPolytope::fromAabb({{0.4, -2, 0}, {2, 2, 2}})}, fp);
    ASSERT_TRUE(wall) << wall.error().message;
    const auto parts = updateDecomposition(d->parts, *wall, dp);
    ASSERT_EQ(parts.size(), wall->pieces.size());
    bool highPoly = false;
    for (std::size_t i = 0; i < parts.size(); ++i) {
        const Mesh& piece = wall->pieces[i].mesh;
        highPoly = highPoly || piece.triangles.size() > dp.proxyAboveTriangles;
        EXPECT_LE(test::reachOutsideHull(piece, parts[i]), kPartHullTolerance) << "piece " << i;
        const double eps = 1e-7 * piece.bounds().diagonal();
        for (std::size_t v = 0; v < piece.positions.size(); ++v) {
            bool in = false;
            for (const ConvexPolytope& p : parts[i])
                in = in || p.contains(piece.positions[v], eps);
            ASSERT_TRUE(in) << "piece " << i << ": vertex " << v << " is in no part";
        }
    }
    EXPECT_TRUE(highPoly);
}

} // namespace
} // namespace rubble
