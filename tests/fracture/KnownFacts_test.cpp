// Fracturing with known facts (MeshFacts: validated once, volume integrals carried from piece to piece) gives
// the same piece meshes as fracturing without them, and mass properties equal to a full recomputation up to
// rounding (docs/megamesh.md states the bound), over random and chained hits.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "TestSupport.hpp"
#include "rubble/core/Random.hpp"
#include "rubble/fracture/Fracture.hpp"
#include "rubble/geometry/MassProperties.hpp"
#include "rubble/geometry/MeshSimplify.hpp"

namespace rubble {
namespace {

/// The relative tolerance of mass properties by difference against a full recomputation.
constexpr double kRelative = 1e-12;

using test::massError;

/// The facts every piece carries describe its mesh: counts, and integrals equal to a recomputation about
/// the same reference.
void expectFactsDescribe(const Piece& p) {
    ASSERT_TRUE(p.facts.fit(p.mesh));
    EXPECT_TRUE(test::closedAndOriented(p.mesh));
    const VolumeIntegrals full = volumeIntegrals(p.mesh, p.facts.integrals.reference);
    EXPECT_LE(std::abs(p.facts.integrals.volume - full.volume), kRelative * full.volume);
    EXPECT_LE(massError(p.mesh, massProperties(p.facts.integrals)), kRelative);
}

/// A random hit on the surface of mesh: single cell or a small shatter, of a size relative to the mesh.
struct Hit {
    Impact impact;
    FractureParams params;
};
Hit randomHit(const Mesh& mesh, Rng& rng) {
    Hit h;
    const Vec3 p = test::surfacePoint(mesh, rng);
    const Vec3 c = mesh.bounds().center();
    const Vec3 n = normalized(p - c);
    h.impact = {p - n * (1e-3 * mesh.bounds().diagonal()), n, 100};
    const Vec3 s = mesh.bounds().size();
    h.params.sizeLaw.base = (0.15 + 0.3 * rng.uniform()) * std::max({s.x, s.y, s.z});
    h.params.sizeLaw.scale = 0;
    if (rng.below(3) == 0) {
        h.params.pattern = CellPattern::Shatter;
        h.params.cells = 3 + static_cast<int>(rng.below(6));
    }
    return h;
}

/// Fractures mesh with and without its facts: the same meshes, cells and flags, and masses within
/// tolerance of a full recomputation. Returns the result with facts (nullopt when the hit missed).
std::optional<FractureResult> checkedHit(const Mesh& mesh, const MeshFacts& facts, const Hit& h,
                                         std::uint64_t seed, double& worst) {
    auto with = fracture(mesh, h.impact, h.params, seed, facts);
    auto without = fracture(mesh, h.impact, h.params, seed);
    EXPECT_EQ(bool(with), bool(without));
    if (!with || !without)
        return std::nullopt;
    EXPECT_EQ(with->stats.exactFallback, without->stats.exactFallback);
    EXPECT_EQ(with->stats.redraws, without->stats.redraws);
    EXPECT_EQ(with->pieces.size(), without->pieces.size());
    double volume = 0;
    for (std::size_t i = 0; i < std::min(with->pieces.size(), without->pieces.size()); ++i) {
        const Piece &a = with->pieces[i], &b = without->pieces[i];
        EXPECT_EQ(a.mesh.hash(), b.mesh.hash()) << "piece " << i;
        EXPECT_EQ(a.cell, b.cell);
        expectFactsDescribe(a);
        worst = std::max(worst, massError(a.mesh, a.mass));
        volume += a.mass.volume;
    }
    // Volume is conserved (the dropped pieces counted).
    EXPECT_NEAR(volume + with->droppedVolume, facts.integrals.volume, 1e-9 * facts.integrals.volume);
    return std::move(with).value();
}

TEST(KnownFacts, AnalyzeMeshIsWhatFractureChecks) {
    const Mesh sphere = makeSphere({1, 2, 3}, 1.5, 24, 12);
    auto f = analyzeMesh(sphere);
    ASSERT_TRUE(f);
    EXPECT_TRUE(f->fit(sphere));
    const MassProperties m = massProperties(f->integrals);
    const MassProperties full = computeMassProperties(sphere);
    EXPECT_EQ(m.volume, full.volume); // the same sums in the same order
    EXPECT_EQ(m.inertia.m[0][0], full.inertia.m[0][0]);
    Mesh open = sphere;
    open.triangles.pop_back();
    EXPECT_FALSE(analyzeMesh(open));
    EXPECT_FALSE(analyzeMesh(Mesh{}));
    // Facts that do not fit a mesh are ignored: the open mesh is still refused.
    EXPECT_FALSE(f->fit(open));
    auto r = fracture(open, Impact{{1, 2, 4.5}, {0, 0, 1}, 10}, FractureParams{}, 1, *f);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, ErrorCode::InvalidInput);
}

TEST(KnownFacts, RandomHitsGiveTheSamePiecesAndExactMass) {
    Mesh box = makeSubdividedBox({-1, -0.5, -2}, {1, 0.5, 2}, 8);
    box.computeFlatNormals();
    const std::vector<Mesh> meshes = {makeSphere({0.3, -0.2, 0.1}, 1, 48, 24),
                                      makeTorus({5, 0, 0}, 1, 0.3, 48, 16), box};
    Rng rng(0x4D455341);
    double worst = 0;
    int hits = 0;
    for (const Mesh& mesh : meshes) {
        const MeshFacts facts = analyzeMesh(mesh).value();
        for (int i = 0; i < 25; ++i) {
            const Hit h = randomHit(mesh, rng);
            hits += checkedHit(mesh, facts, h, rng.next(), worst) ? 1 : 0;
        }
    }
    EXPECT_GE(hits, 60);
    EXPECT_LE(worst, kRelative);
    char text[32];
    std::snprintf(text, sizeof text, "%.3g", worst);
    RecordProperty("worst_relative_mass_error", text);
}

/// A piece hit again and again with the facts its parent's fracture gave it: the remainder's mass is a
/// difference of differences, and still a full recomputation's.
TEST(KnownFacts, ChainedHitsKeepMassExact) {
    for (const Mesh& start : {makeSphere({0, 0, 0}, 1, 64, 32), makeTorus({0, 0, 0}, 1, 0.35, 64, 24)}) {
        Mesh mesh = start;
        MeshFacts facts = analyzeMesh(mesh).value();
        Rng rng(0xC4A1);
        double worst = 0;
        int hits = 0;
        for (int i = 0; i < 30; ++i) {
            auto r = checkedHit(mesh, facts, randomHit(mesh, rng), rng.next(), worst);
            if (!r)
                continue;
            ++hits;
            // The largest piece goes on (it is usually the remainder, whose mass came by difference).
            std::size_t largest = 0;
            for (std::size_t k = 1; k < r->pieces.size(); ++k)
                if (r->pieces[k].mass.volume > r->pieces[largest].mass.volume)
                    largest = k;
            mesh = std::move(r->pieces[largest].mesh);
            facts = r->pieces[largest].facts;
        }
        EXPECT_GE(hits, 20);
        EXPECT_LE(worst, kRelative);
        EXPECT_LE(massError(mesh, massProperties(facts.integrals)), kRelative);
    }
}

/// A ring cut twice falls apart far from the second cut: the remainder has two islands, the larger by
/// difference, the other measured.
TEST(KnownFacts, RingCutTwiceSplitsTheRemainderExactly) {
    const Mesh ring = makeTorus({0, 0, 0}, 1, 0.2, 96, 16);
    const MeshFacts facts = analyzeMesh(ring).value();
    FractureParams p;
    p.pattern = CellPattern::SingleCell;
    auto box = [](Vec3 c, double h) {
        return ConvexPolytope::fromAabb({c - Vec3{h, h, h}, c + Vec3{h, h, h}});
    };
    auto first = fractureWithCells(ring, {box({1, 0, 0}, 0.3)}, p, facts);
    ASSERT_TRUE(first);
    ASSERT_EQ(first->pieces.front().cell, -1);
    const Piece& bent = first->pieces.front();
    auto second = fractureWithCells(bent.mesh, {box({-1, 0, 0.3}, 0.35)}, p, bent.facts);
    auto check = fractureWithCells(bent.mesh, {box({-1, 0, 0.3}, 0.35)}, p);
    ASSERT_TRUE(second);
    ASSERT_TRUE(check);
    int remainders = 0;
    for (const Piece& piece : second->pieces) {
        remainders += piece.cell == -1 ? 1 : 0;
        expectFactsDescribe(piece);
        EXPECT_LE(massError(piece.mesh, piece.mass), kRelative);
    }
    EXPECT_EQ(remainders, 2);
    ASSERT_EQ(second->pieces.size(), check->pieces.size());
    for (std::size_t i = 0; i < check->pieces.size(); ++i)
        EXPECT_EQ(second->pieces[i].mesh.hash(), check->pieces[i].mesh.hash());
}

/// simplifyPlanarRegions reports what it changed in the volume integrals.
TEST(KnownFacts, SimplificationReportsItsIntegralsChange) {
    const Mesh box = makeSubdividedBox({0, 0, 0}, {2, 1, 1}, 6);
    PlanarSimplifyParams sp;
    sp.integralsReference = {0.3, 0.7, -0.2};
    PlanarSimplifyReport report;
    const Mesh simple = simplifyPlanarRegions(box, sp, &report);
    ASSERT_FALSE(report.unchanged);
    ASSERT_LT(simple.triangleCount(), box.triangleCount());
    VolumeIntegrals tracked = volumeIntegrals(box, sp.integralsReference);
    tracked.accumulate(report.integralsChange, 1.0);
    const VolumeIntegrals full = volumeIntegrals(simple, sp.integralsReference);
    EXPECT_NEAR(tracked.volume, full.volume, 1e-14);
    for (int i = 0; i < 3; ++i) {
        EXPECT_NEAR(tracked.first[i], full.first[i], 1e-14);
        for (int j = i; j < 3; ++j)
            EXPECT_NEAR(tracked.cov[i][j], full.cov[i][j], 1e-14);
    }
}

/// The case: chained hits on a 100k-triangle mesh, mass against full recomputation.
TEST(KnownFacts, ChainedHitsOnAHundredThousandTriangles) {
    Mesh mesh = makeSphere({0, 0, 0}, 1, 316, 158);
    ASSERT_GE(mesh.triangleCount(), 99000u);
    MeshFacts facts = analyzeMesh(mesh).value();
    Rng rng(0x100C);
    double worst = 0;
    for (int i = 0; i < 8; ++i) {
        Hit h = randomHit(mesh, rng);
        h.params.pattern = CellPattern::SingleCell;
        auto r = fracture(mesh, h.impact, h.params, rng.next(), facts);
        ASSERT_TRUE(r);
        std::size_t largest = 0;
        for (std::size_t k = 0; k < r->pieces.size(); ++k) {
            worst = std::max(worst, massError(r->pieces[k].mesh, r->pieces[k].mass));
            if (r->pieces[k].mass.volume > r->pieces[largest].mass.volume)
                largest = k;
        }
        mesh = std::move(r->pieces[largest].mesh);
        facts = r->pieces[largest].facts;
    }
    EXPECT_TRUE(test::closedAndOriented(mesh));
    EXPECT_LE(worst, kRelative);
}

} // namespace
} // namespace rubble
