// High-poly meshes (issue #14), at sizes CI can afford: chained hits on a 100k-triangle torus keep mass
// properties equal to a recomputation, conserve volume and keep the collision parts bounded; a ring cut twice
// falls into two arcs far from the second impact.
#include <thread>

#include <gtest/gtest.h>

#include "SurfaceImpact.hpp"
#include "rubble/collision/ConvexDecomposition.hpp"
#include "rubble/core/Random.hpp"
#include "rubble/fracture/Fracture.hpp"
#include "rubble/geometry/MassProperties.hpp"

namespace rubble {
namespace {

void expectSameMass(const MassProperties& a, const MassProperties& b, double scale) {
    EXPECT_NEAR(a.volume, b.volume, 1e-12 * scale * scale * scale);
    EXPECT_NEAR(length(a.centerOfMass - b.centerOfMass), 0.0, 1e-12 * scale);
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            EXPECT_NEAR(a.inertia.m[i][j], b.inertia.m[i][j], 1e-9 * std::abs(b.inertia.m[i][i]) + 1e-15);
}

/// Some vertices of mesh (every stride-th) lie in a part.
void expectSampleCovered(const Mesh& mesh, const std::vector<ConvexPolytope>& parts, std::size_t stride) {
    const double eps = 1e-7 * mesh.bounds().diagonal();
    for (std::size_t v = 0; v < mesh.positions.size(); v += stride) {
        bool in = false;
        for (const ConvexPolytope& p : parts)
            in = in || p.contains(mesh.positions[v], eps);
        ASSERT_TRUE(in) << "vertex " << v << " is in no part";
    }
}

TEST(HighPoly, ChainedHitsOnA100kTorusKeepMassVolumeAndBoundedParts) {
    Mesh mesh = makeTorus({0, 0, 0}, 1.0, 0.3, 500, 100); // 100,000 triangles
    ASSERT_EQ(mesh.triangles.size(), 100000u);
    const DecompositionParams dp;
    auto d = decompose(mesh, dp);
    ASSERT_TRUE(d) << d.error().message;
    EXPECT_LE(d->excess(), 0.15);
    std::vector<ConvexPolytope> parts = d->parts;
    const double scale = mesh.bounds().diagonal();
    const Vec3 points[] = {
        {1.25, 0.1, 0.3}, {-0.2, -0.2, 1.2}, {-1.0, 0.25, -0.5}, {0.6, 0.0, -0.9}, {-1.2, -0.1, 0.2}};
    int hits = 0;
    for (int hit = 0; hit < 5; ++hit) {
        SCOPED_TRACE("hit " + std::to_string(hit));
        FractureParams fp;
        fp.sizeLaw.base = 0.5;
        fp.sizeLaw.scale = 0;
        auto fr = fracture(mesh, Impact{points[hit], normalized(points[hit]), 10}, fp, 40 + hit);
        if (!fr)
            continue; // the remainder may no longer reach this point
        ++hits;
        double volume = fr->droppedVolume;
        for (const Piece& p : fr->pieces) {
            expectSameMass(p.mass, computeMassProperties(p.mesh), scale);
            volume += p.mass.volume;
        }
        EXPECT_NEAR(volume, fr->inputVolume, 1e-7 * fr->inputVolume);
        const auto updated = updateDecomposition(parts, *fr, dp);
        ASSERT_EQ(updated.size(), fr->pieces.size());
        std::size_t largest = 0;
        for (std::size_t i = 0; i < updated.size(); ++i) {
            // The work of the next update is bounded whatever the hits: few parts of few faces.
            EXPECT_LE(updated[i].size(), static_cast<std::size_t>(dp.maxParts));
            for (const ConvexPolytope& p : updated[i])
                EXPECT_LE(p.faces().size(), dp.maxPartFaces);
            expectSampleCovered(fr->pieces[i].mesh, updated[i], 37);
            if (fr->pieces[i].mass.volume > fr->pieces[largest].mass.volume)
                largest = i;
        }
        mesh = fr->pieces[largest].mesh;
        parts = updated[largest];
    }
    EXPECT_GE(hits, 4);
}

/// One hit of a chain: the parts the update gave every piece.
struct ChainStep {
    FractureResult fracture;
    std::vector<std::vector<ConvexPolytope>> parts;
};

/// hits chained hits on a 100k-triangle torus (random surface points, seed-derived), each on the largest
/// piece of the previous one with the parts its update gave it.
std::vector<ChainStep> chainOnTorus(int hits, const DecompositionParams& dp) {
    Mesh mesh = makeTorus({0, 0, 0}, 1.0, 0.3, 500, 100);
    std::vector<ConvexPolytope> parts = decompose(mesh, dp).value().parts;
    MeshFacts facts = analyzeMesh(mesh).value();
    std::vector<ChainStep> steps;
    Rng rng(7);
    for (int hit = 0; hit < hits; ++hit) {
        FractureParams fp;
        fp.sizeLaw.base = 0.5;
        fp.sizeLaw.scale = 0;
        auto fr = fracture(mesh, test::randomSurfaceImpact(mesh, rng, 10), fp, 60 + hit, facts);
        if (!fr)
            continue;
        ChainStep step{std::move(fr).value(), {}};
        step.parts = updateDecomposition(parts, step.fracture, dp);
        std::size_t largest = 0;
        for (std::size_t i = 0; i < step.fracture.pieces.size(); ++i)
            if (step.fracture.pieces[i].mass.volume > step.fracture.pieces[largest].mass.volume)
                largest = i;
        mesh = step.fracture.pieces[largest].mesh;
        facts = step.fracture.pieces[largest].facts;
        parts = step.parts[largest];
        steps.push_back(std::move(step));
    }
    return steps;
}

TEST(HighPoly, ChainedUpdatesOnA100kTorusKeepConvexCoveringPartsWithinBudgetAndExcess) {
    const DecompositionParams dp;
    const std::vector<ChainStep> steps = chainOnTorus(8, dp);
    ASSERT_GE(steps.size(), 6u);
    Rng rng(5);
    for (std::size_t s = 0; s < steps.size(); ++s) {
        const FractureResult& fr = steps[s].fracture;
        ASSERT_EQ(steps[s].parts.size(), fr.pieces.size());
        double partVolume = 0, pieceVolume = 0;
        for (std::size_t i = 0; i < fr.pieces.size(); ++i) {
            SCOPED_TRACE("hit " + std::to_string(s) + " piece " + std::to_string(i));
            const Mesh& mesh = fr.pieces[i].mesh;
            const std::vector<ConvexPolytope>& parts = steps[s].parts[i];
            EXPECT_LE(parts.size(), static_cast<std::size_t>(dp.maxParts));
            const double eps = 1e-7 * mesh.bounds().diagonal();
            for (const ConvexPolytope& p : parts) {
                EXPECT_LE(p.faces().size(), dp.maxPartFaces);
                const std::vector<Vec3> corners = p.vertices();
                for (const PolytopeFaceView& f : p.faces()) // convex: every corner behind every face plane
                    for (const Vec3& v : corners)
                        ASSERT_LE(f.plane.signedDistance(v), eps);
                partVolume += p.volume();
            }
            pieceVolume += fr.pieces[i].mass.volume;
            // Points inside the solid (by winding number) lie in some part.
            const Aabb b = mesh.bounds();
            int inside = 0;
            for (int tries = 0; tries < 200 && inside < 16; ++tries) {
                const Vec3 q = rng.inBox(b.lo, b.hi);
                if (windingNumber(mesh, q) < 0.5)
                    continue;
                ++inside;
                bool covered = false;
                for (const ConvexPolytope& p : parts)
                    covered = covered || p.contains(q, eps);
                ASSERT_TRUE(covered) << "a point inside the piece is in no part";
            }
        }
        EXPECT_LE(partVolume / pieceVolume - 1, 0.15) << "hit " << s;
    }
}

TEST(HighPoly, ChainedUpdatesAreTheSameOnOneAndTwoThreads) {
    const DecompositionParams dp;
    const std::vector<ChainStep> alone = chainOnTorus(4, dp);
    std::vector<ChainStep> concurrent[2];
    std::thread a([&] { concurrent[0] = chainOnTorus(4, dp); });
    std::thread b([&] { concurrent[1] = chainOnTorus(4, dp); });
    a.join();
    b.join();
    for (const std::vector<ChainStep>& other : concurrent) {
        ASSERT_EQ(other.size(), alone.size());
        for (std::size_t s = 0; s < alone.size(); ++s) {
            ASSERT_EQ(other[s].parts.size(), alone[s].parts.size());
            for (std::size_t i = 0; i < alone[s].parts.size(); ++i) {
                ASSERT_EQ(other[s].parts[i].size(), alone[s].parts[i].size());
                for (std::size_t k = 0; k < alone[s].parts[i].size(); ++k)
                    EXPECT_EQ(other[s].parts[i][k].vertices(), alone[s].parts[i][k].vertices());
            }
        }
    }
}

TEST(HighPoly, AHitOnAHighPolySphereLeavesAnExactDentInTheRemaindersParts) {
    // Within the part budget the remainder's parts are the parent part minus the cell: the debris (inside the
    // cell) lies in none of them, so the two do not start interpenetrating.
    const Mesh sphere = makeSphere({0, 0, 0}, 1.0, 400, 126); // ~100k triangles
    ASSERT_GT(sphere.triangles.size(), 90000u);
    const DecompositionParams dp;
    auto d = decompose(sphere, dp);
    ASSERT_TRUE(d) << d.error().message;
    FractureParams fp;
    fp.sizeLaw.base = 0.5;
    fp.sizeLaw.scale = 0;
    auto fr = fracture(sphere, {{0.999, 0, 0}, {1, 0, 0}, 10}, fp, 3);
    ASSERT_TRUE(fr) << fr.error().message;
    const auto parts = updateDecomposition(d->parts, *fr, dp);
    int debris = 0, remainders = 0;
    for (std::size_t i = 0; i < fr->pieces.size(); ++i) {
        if (fr->pieces[i].cell < 0) {
            ++remainders;
            EXPECT_GT(parts[i].size(), 1u) << "the dent was filled";
            continue;
        }
        ++debris;
        const Vec3 c = fr->pieces[i].mass.centerOfMass;
        for (std::size_t r = 0; r < fr->pieces.size(); ++r) {
            if (fr->pieces[r].cell >= 0)
                continue;
            for (const ConvexPolytope& p : parts[r]) {
                EXPECT_FALSE(p.contains(c, -1e-6)) << "the debris lies inside a part of the remainder";
            }
        }
    }
    EXPECT_EQ(remainders, 1);
    EXPECT_GE(debris, 1);
}

TEST(HighPoly, ARingCutTwiceFallsIntoTwoArcs) {
    // The first cut opens the ring at +x; the second, at -x, disconnects the two arcs from each other far
    // from where it hit: each arc must come out as its own closed piece.
    const Mesh ring = makeTorus({0, 0, 0}, 1.0, 0.25, 96, 24);
    FractureParams fp;
    auto first = fractureWithCells(ring, {ConvexPolytope::fromAabb({{0.6, -1, -0.2}, {1.5, 1, 0.2}})}, fp);
    ASSERT_TRUE(first) << first.error().message;
    std::size_t open = first->pieces.size();
    for (std::size_t i = 0; i < first->pieces.size(); ++i)
        if (first->pieces[i].cell < 0)
            open = i;
    ASSERT_LT(open, first->pieces.size());
    const Mesh opened = first->pieces[open].mesh;
    auto second =
        fractureWithCells(opened, {ConvexPolytope::fromAabb({{-1.5, -1, -0.2}, {-0.6, 1, 0.2}})}, fp);
    ASSERT_TRUE(second) << second.error().message;
    std::vector<const Piece*> arcs;
    double volume = second->droppedVolume;
    for (const Piece& p : second->pieces) {
        volume += p.mass.volume;
        if (p.cell < 0)
            arcs.push_back(&p);
    }
    EXPECT_NEAR(volume, computeMassProperties(opened).volume, 1e-7 * volume);
    ASSERT_EQ(arcs.size(), 2u);
    // One arc on each side of z = 0, each a closed solid of about half the remaining volume.
    EXPECT_LT(arcs[0]->mass.centerOfMass.z * arcs[1]->mass.centerOfMass.z, 0.0);
    for (const Piece* a : arcs) {
        EXPECT_NEAR(a->mass.volume, arcs[0]->mass.volume, 1e-6 * a->mass.volume);
        const Aabb b = a->mesh.bounds();
        EXPECT_TRUE(b.lo.z > -1e-9 || b.hi.z < 1e-9) << "an arc crosses z = 0";
        expectSameMass(a->mass, computeMassProperties(a->mesh), 2.5);
    }
}

} // namespace
} // namespace rubble
