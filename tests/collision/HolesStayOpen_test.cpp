// The parts of fractured pieces match what broke: no part reaches into another piece of the same fracture
// (craters stay open) and every part stays inside its piece's convex hull, over random hits and chained hits.
#include <gtest/gtest.h>

#include <string>

#include "PartOverlap.hpp"
#include "RepositoryModels.hpp"
#include "TestSupport.hpp"
#include "rubble/collision/CollisionTolerance.hpp"
#include "rubble/collision/ConvexDecomposition.hpp"
#include "rubble/core/Random.hpp"
#include "rubble/fracture/Fracture.hpp"
#include "rubble/geometry/MassProperties.hpp"

namespace rubble {
namespace {

std::vector<Mesh> meshesOf(const FractureResult& fr) {
    std::vector<Mesh> out;
    for (const Piece& p : fr.pieces)
        out.push_back(p.mesh);
    return out;
}

/// Every piece's parts stay inside its hull and out of the other pieces.
void expectMatchesWhatBroke(const FractureResult& fr, const std::vector<std::vector<ConvexPolytope>>& parts) {
    ASSERT_EQ(parts.size(), fr.pieces.size());
    const std::vector<Mesh> pieces = meshesOf(fr);
    for (std::size_t i = 0; i < pieces.size(); ++i)
        EXPECT_LE(test::reachOutsideHull(pieces[i], parts[i]), kPartHullTolerance) << "piece " << i;
    const test::PieceOverlap worst = test::worstPieceOverlap(pieces, parts);
    EXPECT_LE(worst.fraction, kPartOverlapTolerance)
        << "the parts of piece " << worst.piece << " (cell " << fr.pieces[worst.piece].cell
        << ") reach into piece " << worst.other << " (cell " << fr.pieces[worst.other].cell << ")";
}

TEST(HolesStayOpen, AShatterOfTheCubeLeavesItsCraterOpen) {
    // The hit: a shatter takes a 1.8 % bite, below the 2 % concavity; the remainder used to keep the
    // cube's own hull, with every debris piece inside it.
    std::vector<test::NamedMesh> models;
    test::appendRepositoryModels(models, {"cube_588"});
    ASSERT_EQ(models.size(), 1u);
    const Mesh& cube = models[0].mesh;
    auto d = decompose(cube);
    ASSERT_TRUE(d) << d.error().message;
    ASSERT_EQ(d->parts.size(), 1u);
    for (int cells : {8, 20}) {
        SCOPED_TRACE(std::to_string(cells) + " cells");
        FractureParams fp;
        fp.pattern = CellPattern::Shatter;
        fp.cells = cells;
        auto fr = fracture(cube, {{0.3, 1, 0.2}, {0, 1, 0}, 40}, fp, 0);
        ASSERT_TRUE(fr) << fr.error().message;
        const auto parts = updateDecomposition(d->parts, *fr);
        ASSERT_EQ(fr->pieces[0].cell, -1);
        EXPECT_GT(parts[0].size(), 1u) << "the remainder is not its parent's hull";
        for (std::size_t i = 1; i < fr->pieces.size(); ++i)
            for (const ConvexPolytope& part : parts[0])
                EXPECT_FALSE(part.contains(fr->pieces[i].mass.centerOfMass))
                    << "piece " << i << " was born inside the remainder's parts";
        expectMatchesWhatBroke(*fr, parts);
    }
}

TEST(HolesStayOpen, RandomHitsSingleCellAndShatter) {
    std::vector<test::NamedMesh> shapes{{"box", makeSubdividedBox({-1, -1, -0.5}, {1, 1, 0.5}, 3)},
                                        {"sphere", makeSphere({0, 0, 0}, 1, 24, 12)}};
    test::appendRepositoryModels(shapes, {"column"});
    for (const test::NamedMesh& shape : shapes) {
        auto d = decompose(shape.mesh);
        ASSERT_TRUE(d) << shape.name << ": " << d.error().message;
        Rng rng(5);
        const Aabb b = shape.mesh.bounds();
        for (int hit = 0; hit < 6; ++hit) {
            FractureParams fp;
            fp.pattern = hit % 2 == 0 ? CellPattern::SingleCell : CellPattern::Shatter;
            fp.cells = hit % 3 == 0 ? 20 : 8;
            const Vec3 point = test::surfacePoint(shape.mesh, rng);
            SCOPED_TRACE(shape.name + " hit " + std::to_string(hit));
            auto fr = fracture(shape.mesh, {point, normalized(point - b.center()), 40}, fp, 10 + hit);
            if (!fr)
                continue; // the cells missed
            expectMatchesWhatBroke(*fr, updateDecomposition(d->parts, *fr));
        }
    }
}

TEST(HolesStayOpen, ChainedHitsKeepPartsInsideTheirPiece) {
    // Four hits in a row on the largest piece, whose parts are the previous update's: parts never reach out
    // of their piece's hull nor into the other pieces.
    Mesh mesh = makeSubdividedBox({-1, -1, -1}, {1, 1, 1}, 3);
    auto d = decompose(mesh);
    ASSERT_TRUE(d);
    std::vector<ConvexPolytope> parts = d->parts;
    Rng rng(9);
    for (int round = 0; round < 4; ++round) {
        SCOPED_TRACE("round " + std::to_string(round));
        FractureParams fp;
        fp.pattern = round % 2 == 0 ? CellPattern::Shatter : CellPattern::SingleCell;
        fp.cells = 8;
        const Vec3 point = test::surfacePoint(mesh, rng);
        auto fr = fracture(mesh, {point, normalized(point - mesh.bounds().center()), 60}, fp, 30 + round);
        if (!fr)
            continue;
        const auto updated = updateDecomposition(parts, *fr);
        expectMatchesWhatBroke(*fr, updated);
        std::size_t biggest = 0;
        for (std::size_t i = 0; i < fr->pieces.size(); ++i)
            if (fr->pieces[i].mass.volume > fr->pieces[biggest].mass.volume)
                biggest = i;
        mesh = fr->pieces[biggest].mesh;
        parts = updated[biggest];
    }
}

TEST(HolesStayOpen, FreshDecompositionsStayInsideTheirMeshsHull) {
    // Bounded hulls (a sphere of more faces than a part keeps) and the proxy of a high-poly mesh may reach
    // out of the exact hull: the parts are clipped back to it.
    DecompositionParams p;
    for (const Mesh& m : {makeSphere({0, 0, 0}, 1, 120, 60), makeTorus({0, 0, 0}, 1, 0.3, 200, 60)}) {
        auto d = decompose(m, p);
        ASSERT_TRUE(d) << d.error().message;
        EXPECT_LE(test::reachOutsideHull(m, d->parts), kPartHullTolerance);
        for (const ConvexPolytope& part : d->parts)
            EXPECT_LE(part.faces().size(), p.maxPartFaces + 0u);
    }
}

} // namespace
} // namespace rubble
