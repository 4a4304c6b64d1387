// fracture(FractureRequest), the one entry point: a request gives the same pieces, byte for byte, as the
// shorthand that says the same thing (a mesh lent or handed over, at an impact or by given cells), a mesh
// lent is left as it is, a mesh handed over with its topology is cut in place, and a malformed request is
// refused naming the field.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "PieceHash.hpp"
#include "rubble/fracture/Fracture.hpp"
#include "rubble/fracture/FractureRequest.hpp"

namespace rubble {
namespace {

/// EXPECTs that two fractures made the same pieces, byte for byte, from the same cells by the same path.
void expectSameFracture(const Result<FractureResult>& a, const Result<FractureResult>& b) {
    ASSERT_TRUE(a.isOk()) << a.error().message;
    ASSERT_TRUE(b.isOk()) << b.error().message;
    EXPECT_EQ(test::hashPieces(*a), test::hashPieces(*b));
    ASSERT_EQ(a->pieces.size(), b->pieces.size());
    for (std::size_t i = 0; i < a->pieces.size(); ++i) {
        EXPECT_EQ(a->pieces[i].cell, b->pieces[i].cell);
        EXPECT_EQ(a->pieces[i].mass.volume, b->pieces[i].mass.volume);
    }
    EXPECT_EQ(a->cells.size(), b->cells.size());
    EXPECT_EQ(a->inputVolume, b->inputVolume);
    EXPECT_EQ(a->droppedVolume, b->droppedVolume);
    EXPECT_EQ(a->stats.editedInPlace, b->stats.editedInPlace);
    EXPECT_EQ(a->stats.exactFallback, b->stats.exactFallback);
    EXPECT_EQ(a->stats.redraws, b->stats.redraws);
}

FractureParams shatter() {
    FractureParams params;
    params.pattern = CellPattern::Shatter;
    params.cells = 6;
    params.roughness.amplitude = 0.02; // the seed is mixed into the roughness's
    return params;
}

/// A request to cut at impact from seed with params; the mesh is the caller's to set.
FractureRequest atImpact(const Impact& impact, std::uint64_t seed, const FractureParams& params) {
    FractureRequest request;
    request.impact = impact;
    request.seed = seed;
    request.params = params;
    return request;
}

TEST(FractureRequest, ALentMeshGivesTheShorthandsPiecesAndIsLeftAsItIs) {
    const Mesh cube = makeSubdividedBox({-1, -1, -1}, {1, 1, 1}, 4);
    const std::uint64_t before = cube.hash();
    const Impact impact{{0.3, 1.0, 0.2}, {0, 1, 0}, 40};
    for (const FractureParams& params : {FractureParams{}, shatter()}) {
        FractureRequest request = atImpact(impact, 7, params);
        request.mesh = &cube;
        const auto viaRequest = fracture(request);
        expectSameFracture(viaRequest, fracture(cube, impact, params, 7));
        ASSERT_TRUE(viaRequest.isOk());
        EXPECT_GE(viaRequest->pieces.size(), 2u);
        EXPECT_EQ(cube.hash(), before);

        // Given cells: impact and seed unused, as fractureWithCells.
        request.cells = generateCells(cube.bounds(), impact, params, 11);
        request.impact = Impact{};
        expectSameFracture(fracture(request), fractureWithCells(cube, *request.cells, params));
        EXPECT_EQ(cube.hash(), before);
    }
}

TEST(FractureRequest, AMeshHandedOverWithItsTopologyIsCutInPlaceAsByTheConsumingShorthand) {
    const Mesh sphere = makeSphere({0, 0, 0}, 1, 160, 80);
    const MeshFacts facts = analyzeMesh(sphere).value();
    ASSERT_TRUE(facts.topology.fits(sphere));
    const std::uint64_t before = sphere.hash();
    const Impact impact{{0, 0.998, 0}, {0, 1, 0}, 100};
    FractureParams params;
    params.sizeLaw.base = 0.6;
    params.sizeLaw.scale = 0;

    Mesh handed = sphere;
    MeshFacts handedFacts = facts;
    FractureRequest request = atImpact(impact, 5, params);
    request.consumed = &handed;
    request.consumedFacts = &handedFacts;
    const auto inPlace = fracture(request);
    expectSameFracture(inPlace, fracture(Mesh(sphere), impact, params, 5, MeshFacts(facts)));
    ASSERT_TRUE(inPlace.isOk());
    EXPECT_TRUE(inPlace->stats.editedInPlace);

    // Lent with the same facts: a copy is cut in place, to the same bytes; the caller's mesh is untouched.
    FractureRequest lent = atImpact(impact, 5, params);
    lent.mesh = &sphere;
    lent.known = &facts;
    expectSameFracture(fracture(lent), inPlace);
    EXPECT_EQ(sphere.hash(), before);
}

TEST(FractureRequest, AMalformedRequestIsRefusedNamingTheField) {
    const Mesh cube = makeSubdividedBox({-1, -1, -1}, {1, 1, 1}, 2);
    Mesh handed = cube;
    MeshFacts facts = analyzeMesh(cube).value();
    auto refusal = [](const FractureRequest& request) {
        const auto r = fracture(request);
        EXPECT_FALSE(r.isOk());
        if (r.isOk())
            return std::string();
        EXPECT_EQ(r.error().code, ErrorCode::InvalidInput);
        return r.error().message;
    };
    FractureRequest request;
    request.impact = Impact{{0, 1, 0}, {0, 1, 0}, 20};
    EXPECT_NE(refusal(request).find("neither mesh nor consumed"), std::string::npos);
    request.mesh = &cube;
    request.consumed = &handed;
    EXPECT_NE(refusal(request).find("both mesh and consumed"), std::string::npos);
    EXPECT_EQ(handed.hash(), cube.hash()); // a refused request hands nothing over
    request.mesh = nullptr;
    request.known = &facts;
    EXPECT_NE(refusal(request).find("known without mesh"), std::string::npos);
    request.known = nullptr;
    request.consumed = nullptr;
    request.mesh = &cube;
    request.consumedFacts = &facts;
    EXPECT_NE(refusal(request).find("consumedFacts without consumed"), std::string::npos);
    request.consumedFacts = nullptr;
    EXPECT_TRUE(fracture(request).isOk()); // the same request, well formed
}

} // namespace
} // namespace rubble
