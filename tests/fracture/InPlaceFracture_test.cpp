// Fracturing a large mesh in place with its topology (MeshFacts::topology, docs/megamesh.md): the remainder
// is the input edited where the cut touched, checked closed around the cut, split into islands by a walk
// around the cut with the full labelling as the fallback, and simplified around the cut. Every piece is
// checked in full against the invariants: closed and oriented, its topology equal to one built from
// scratch, its mass equal to a full recomputation, volume conserved.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "TestSupport.hpp"
#include "fracture/BooleanBackends.hpp"
#include "fracture/FracturePipeline.hpp"
#include "geometry/MeshTopology.hpp"
#include "geometry/TopologyEdit.hpp"
#include "rubble/core/Random.hpp"
#include "rubble/fracture/Fracture.hpp"

namespace rubble {
namespace {

constexpr double kRelative = 1e-12;

/// EXPECTs that the piece is closed and oriented, its facts describe it (mass within kRelative of a full
/// recomputation) and its topology, when it has one, is the one its mesh has.
void expectSoundPiece(const Piece& p) {
    ASSERT_TRUE(p.facts.fit(p.mesh));
    EXPECT_TRUE(test::closedAndOriented(p.mesh));
    EXPECT_LE(test::massError(p.mesh, massProperties(p.facts.integrals)), kRelative);
    EXPECT_LE(test::massError(p.mesh, p.mass), kRelative);
    if (p.mesh.triangles.size() > kTopologyAboveTriangles || !p.facts.topology.empty()) {
        const auto rebuilt = buildTopology(p.mesh);
        ASSERT_TRUE(rebuilt.has_value()) << "a piece above the threshold that is not one shell";
        ASSERT_NE(p.facts.topology.get(), nullptr);
        EXPECT_TRUE(*p.facts.topology.get() == *rebuilt);
    }
}

/// A random hit on the surface: a single cell or a small shatter, sized relative to the mesh.
std::pair<Impact, FractureParams> randomHit(const Mesh& mesh, Rng& rng) {
    const Vec3 p = test::surfacePoint(mesh, rng);
    const Vec3 n = normalized(p - mesh.bounds().center());
    FractureParams params;
    const Vec3 s = mesh.bounds().size();
    params.sizeLaw.base = (0.15 + 0.3 * rng.uniform()) * std::max({s.x, s.y, s.z});
    params.sizeLaw.scale = 0;
    if (rng.below(3) == 0) {
        params.pattern = CellPattern::Shatter;
        params.cells = 3 + static_cast<int>(rng.below(6));
    }
    return {{p - n * (1e-3 * mesh.bounds().diagonal()), n, 100}, params};
}

TEST(MeshTopology, BuiltAboveTheThresholdForOneShellOnly) {
    EXPECT_TRUE(analyzeMesh(makeSphere({0, 0, 0}, 1, 32, 16)).value().topology.empty());
    const Mesh big = makeSphere({0, 0, 0}, 1, 160, 80);
    ASSERT_GT(big.triangles.size(), kTopologyAboveTriangles);
    const MeshFacts facts = analyzeMesh(big).value();
    ASSERT_TRUE(facts.topology.fits(big));
    const std::vector<std::uint32_t>& twin = facts.topology.get()->twin;
    for (std::uint32_t h = 0; h < twin.size(); ++h) { // twins are mutual and reversed
        const std::uint32_t g = twin[h];
        EXPECT_EQ(twin[g], h);
        EXPECT_EQ(big.triangles[h / 3][h % 3], big.triangles[g / 3][(g % 3 + 1) % 3]);
    }
    Mesh two = big;
    two.append(makeSphere({5, 0, 0}, 1, 8, 4));
    EXPECT_FALSE(buildTopology(two).has_value());
    Mesh open = big;
    open.triangles.pop_back();
    open.uvs.clear();
    open.normals.clear();
    open.materials.clear();
    EXPECT_FALSE(buildTopology(open).has_value());
}

/// replaceTriangles on random edge flips (as many triangles out as in) and vertex removals (a fan of k
/// triangles replaced by k - 2: slots filled from the end): the topology stays the one built from scratch,
/// and a replacement that does not close up is refused with nothing changed.
TEST(MeshTopology, ReplacingTrianglesKeepsTheTopology) {
    Mesh mesh = makeSubdividedBox({0, 0, 0}, {1, 1, 1}, 42);
    ASSERT_GT(mesh.triangles.size(), kTopologyAboveTriangles);
    mesh.uvs.assign(3 * mesh.triangles.size(), Vec2f{});
    mesh.materials.assign(mesh.triangles.size(), 0);
    mesh.normals.clear();
    MeshTopology topo = buildTopology(mesh).value();
    Rng rng(7);
    auto batchOf = [](std::vector<Triangle> tris) {
        detail::TriangleBatch b;
        b.uvs.assign(3 * tris.size(), Vec2f{});
        b.materials.assign(tris.size(), 0);
        b.triangles = std::move(tris);
        return b;
    };
    int flips = 0, removals = 0, refusals = 0;
    for (int i = 0; i < 300; ++i) {
        const auto t = static_cast<std::uint32_t>(rng.below(mesh.triangles.size()));
        const std::uint32_t h = 3 * t + static_cast<std::uint32_t>(rng.below(3));
        const std::uint32_t g = topo.twin[h], u = g / 3;
        const std::uint32_t a = mesh.triangles[t][h % 3], b = mesh.triangles[t][(h % 3 + 1) % 3];
        const std::uint32_t c = mesh.triangles[t][(h % 3 + 2) % 3], d = mesh.triangles[u][(g % 3 + 2) % 3];
        const std::vector<std::uint32_t> pair{std::min(t, u), std::max(t, u)};
        if (i % 3 == 0) { // a replacement that repeats a kept edge's direction: refused
            const Mesh before = mesh;
            const MeshTopology topoBefore = topo;
            EXPECT_FALSE(detail::replaceTriangles(mesh, topo, pair, {}, batchOf({{a, b, d}, {b, a, c}})));
            EXPECT_TRUE(mesh == before);
            EXPECT_TRUE(topo == topoBefore);
            ++refusals;
            continue;
        }
        if (i % 3 == 1) { // flip the edge a-b of the triangles (a, b, c) and (b, a, d)
            if (c == d)
                continue;
            ASSERT_TRUE(detail::replaceTriangles(mesh, topo, pair, {}, batchOf({{c, a, d}, {d, b, c}})));
            ++flips;
        } else { // remove corner a: its fan becomes a fan of its ring from one ring vertex
            std::vector<std::uint32_t> fan, ring;
            std::uint32_t e = h;
            do {
                fan.push_back(e / 3);
                ring.push_back(mesh.triangles[e / 3][(e % 3 + 1) % 3]);
                e = topo.twin[3 * (e / 3) + (e % 3 + 2) % 3]; // the edge into a, reversed: out of a
            } while (e != h && fan.size() < 64);
            std::sort(fan.begin(), fan.end());
            if (e != h || std::unique(fan.begin(), fan.end()) != fan.end())
                continue;
            std::vector<Triangle> tris;
            for (std::size_t k = 1; k + 1 < ring.size(); ++k)
                tris.push_back({ring[0], ring[k], ring[k + 1]});
            auto done = detail::replaceTriangles(mesh, topo, fan, {}, batchOf(tris));
            if (!done)
                continue; // a ring that would repeat a kept edge
            ++removals;
        }
        if (i % 5 == 1 || i == 298) {
            ASSERT_TRUE(test::closedAndOriented(mesh));
            ASSERT_TRUE(topo == buildTopology(mesh).value());
        }
    }
    EXPECT_GT(flips, 50);
    EXPECT_GT(removals, 20);
    EXPECT_GT(refusals, 50);
}

/// Chained random hits on 100k-triangle meshes, each piece checked in full after every hit; the const& and
/// consuming overloads give the same pieces, and the remainder is edited in place.
void chainedHits(Mesh mesh, std::uint64_t seed, int hits) {
    MeshFacts facts = analyzeMesh(mesh).value();
    ASSERT_TRUE(facts.topology.fits(mesh));
    Rng rng(seed);
    int inPlace = 0;
    for (int i = 0; i < hits; ++i) {
        const auto [impact, params] = randomHit(mesh, rng);
        const std::uint64_t s = rng.next();
        auto copied = fracture(mesh, impact, params, s, facts);
        auto r = fracture(Mesh(mesh), impact, params, s, MeshFacts(facts));
        ASSERT_EQ(bool(copied), bool(r));
        if (!r)
            continue;
        inPlace += r->stats.editedInPlace ? 1 : 0;
        ASSERT_EQ(copied->pieces.size(), r->pieces.size());
        double volume = r->droppedVolume;
        std::size_t largest = 0;
        for (std::size_t k = 0; k < r->pieces.size(); ++k) {
            EXPECT_EQ(copied->pieces[k].mesh.hash(), r->pieces[k].mesh.hash());
            expectSoundPiece(r->pieces[k]);
            volume += r->pieces[k].mass.volume;
            if (r->pieces[k].mass.volume > r->pieces[largest].mass.volume)
                largest = k;
        }
        EXPECT_NEAR(volume, facts.integrals.volume, 1e-9 * facts.integrals.volume);
        mesh = std::move(r->pieces[largest].mesh);
        facts = std::move(r->pieces[largest].facts);
    }
    EXPECT_GE(inPlace, hits / 2);
}

TEST(InPlaceFracture, ChainedHitsOnASphereKeepEveryInvariant) {
    chainedHits(makeSphere({0, 0, 0}, 1, 316, 158), 0x51, 6);
}

TEST(InPlaceFracture, ChainedHitsOnATorusKeepEveryInvariant) {
    chainedHits(makeTorus({0, 0, 0}, 1, 0.3, 500, 100), 0x70, 6);
}

TEST(InPlaceFracture, SameSeedSameBytes) {
    const Mesh mesh = makeSphere({0, 0, 0}, 1, 160, 80);
    const MeshFacts facts = analyzeMesh(mesh).value();
    auto run = [&] {
        Rng rng(3);
        std::vector<std::uint64_t> hashes;
        Mesh m = mesh;
        MeshFacts f = facts;
        for (int i = 0; i < 3; ++i) {
            const auto [impact, params] = randomHit(m, rng);
            auto r = fracture(std::move(m), impact, params, rng.next(), std::move(f));
            if (!r)
                return hashes;
            for (const Piece& p : r->pieces)
                hashes.push_back(p.mesh.hash());
            m = std::move(r->pieces.front().mesh);
            f = std::move(r->pieces.front().facts);
        }
        return hashes;
    };
    const auto first = run();
    EXPECT_GE(first.size(), 6u);
    EXPECT_EQ(first, run());
}

/// A ring cut across twice falls apart far from the second cut: the walk around the cut cannot prove one
/// shell, the racing walks find two remainder islands (the first cut's walks meet the long way round), as the
/// copying path does.
TEST(InPlaceFracture, ARingCutTwiceIsSplitByRacingWalks) {
    const Mesh ring = makeTorus({0, 0, 0}, 1, 0.2, 256, 48);
    ASSERT_GT(ring.triangles.size(), kTopologyAboveTriangles);
    const MeshFacts facts = analyzeMesh(ring).value();
    FractureParams p;
    auto box = [](Vec3 c, double h) {
        return ConvexPolytope::fromAabb({c - Vec3{h, h, h}, c + Vec3{h, h, h}});
    };
    auto first = fractureWithCells(Mesh(ring), {box({1.0031, 0.0017, 0.0023}, 0.3011)}, p, MeshFacts(facts));
    ASSERT_TRUE(first);
    EXPECT_TRUE(first->stats.editedInPlace);
    EXPECT_TRUE(first->stats.islandsByRace); // cut across: the two cut faces meet only far away
    EXPECT_FALSE(first->stats.islandsLabelledFully);
    ASSERT_EQ(first->pieces.front().cell, -1);
    ASSERT_EQ(
        std::count_if(first->pieces.begin(), first->pieces.end(), [](const Piece& q) { return q.cell < 0; }),
        1);
    Piece bent = std::move(first->pieces.front());
    expectSoundPiece(bent);
    ASSERT_TRUE(bent.facts.topology.fits(bent.mesh));
    const Mesh bentMesh = bent.mesh;
    auto check = fractureWithCells(
        bentMesh, {box({-1.0027, 0.0013, 0.3019}, 0.3507)}, p,
        MeshFacts{true, bentMesh.triangles.size(), bentMesh.positions.size(), bent.facts.integrals, {}});
    auto second = fractureWithCells(std::move(bent.mesh), {box({-1.0027, 0.0013, 0.3019}, 0.3507)}, p,
                                    std::move(bent.facts));
    ASSERT_TRUE(second);
    ASSERT_TRUE(check);
    EXPECT_TRUE(second->stats.editedInPlace);
    EXPECT_TRUE(second->stats.islandsByRace);
    EXPECT_FALSE(second->stats.islandsLabelledFully);
    std::vector<double> volumes, expected;
    for (const Piece& piece : second->pieces) {
        expectSoundPiece(piece);
        if (piece.cell == -1)
            volumes.push_back(piece.mass.volume);
    }
    for (const Piece& piece : check->pieces)
        if (piece.cell == -1)
            expected.push_back(piece.mass.volume);
    ASSERT_EQ(volumes.size(), 2u);
    ASSERT_EQ(expected.size(), 2u);
    std::sort(volumes.begin(), volumes.end());
    std::sort(expected.begin(), expected.end());
    for (std::size_t i = 0; i < 2; ++i)
        EXPECT_NEAR(volumes[i], expected[i], 1e-9 * expected[i]);
}

/// A 100k ring cut by two slabs close together: the short arc between them breaks off, far from either cut
/// face's walk. The racing walks find it without labelling the ring: the same islands (triangles and
/// volumes) as the copying path, every piece sound with the topology of a rebuild, volume conserved, and the
/// same bytes on a second run.
TEST(InPlaceFracture, AnArcThatBreaksOffIsFoundByRacingWalks) {
    const Mesh ring = makeTorus({0, 0, 0}, 1, 0.2, 512, 96);
    ASSERT_GT(ring.triangles.size(), 90000u);
    const MeshFacts facts = analyzeMesh(ring).value();
    FractureParams p;
    p.simplifyPieces = false; // the copying path simplifies differently; the islands are compared as cut
    const ConvexPolytope across =
        ConvexPolytope::fromAabb({{0.5013, -0.5017, -0.3011}, {1.5021, 0.5023, 0.2987}});
    const ConvexPolytope slab =
        ConvexPolytope::fromAabb({{0.3007, -0.5013, 0.5019}, {1.3011, 0.5029, 0.6023}});
    auto first = fractureWithCells(Mesh(ring), {across}, p, MeshFacts(facts));
    ASSERT_TRUE(first);
    ASSERT_EQ(first->pieces.front().cell, -1);
    Piece bent = std::move(first->pieces.front());
    ASSERT_TRUE(bent.facts.topology.fits(bent.mesh));
    const Mesh bentMesh = bent.mesh;
    const MeshFacts bentFacts = bent.facts;
    auto run = [&](const FractureParams& params) {
        return fractureWithCells(Mesh(bentMesh), {slab}, params, MeshFacts(bentFacts));
    };
    auto second = run(p);
    auto copied = fractureWithCells(
        bentMesh, {slab}, p,
        MeshFacts{true, bentMesh.triangles.size(), bentMesh.positions.size(), bentFacts.integrals, {}});
    ASSERT_TRUE(second) << second.error().message;
    ASSERT_TRUE(copied);
    EXPECT_TRUE(second->stats.editedInPlace);
    EXPECT_TRUE(second->stats.islandsByRace);
    EXPECT_FALSE(second->stats.islandsLabelledFully);
    EXPECT_FALSE(copied->stats.editedInPlace);
    auto remainderIslands = [](const FractureResult& r) {
        std::vector<const Piece*> out;
        for (const Piece& q : r.pieces)
            if (q.cell == -1)
                out.push_back(&q);
        std::sort(out.begin(), out.end(), [](auto* a, auto* b) { return a->mass.volume < b->mass.volume; });
        return out;
    };
    const auto got = remainderIslands(*second), want = remainderIslands(*copied);
    ASSERT_EQ(got.size(), 2u);
    ASSERT_EQ(want.size(), 2u);
    EXPECT_LT(got[0]->mesh.triangles.size(), bentMesh.triangles.size() / 10); // a chip, not a half
    double total = 0;
    for (std::size_t i = 0; i < 2; ++i) {
        EXPECT_TRUE(test::triangleSoup(got[i]->mesh) == test::triangleSoup(want[i]->mesh));
        EXPECT_NEAR(got[i]->mass.volume, want[i]->mass.volume, 1e-9 * want[i]->mass.volume);
    }
    for (const Piece& piece : second->pieces) {
        expectSoundPiece(piece);
        total += piece.mass.volume;
    }
    EXPECT_NEAR(total + second->droppedVolume, bentFacts.integrals.volume, 1e-9 * bentFacts.integrals.volume);
    // With simplification too, and twice: the same bytes.
    auto a = run(FractureParams{}), b = run(FractureParams{});
    ASSERT_TRUE(a);
    ASSERT_TRUE(b);
    EXPECT_TRUE(a->stats.islandsByRace);
    ASSERT_EQ(a->pieces.size(), b->pieces.size());
    for (std::size_t i = 0; i < a->pieces.size(); ++i) {
        expectSoundPiece(a->pieces[i]);
        EXPECT_EQ(a->pieces[i].mesh.hash(), b->pieces[i].mesh.hash());
    }
}

/// A chip off the surface keeps the remainder one shell, proven by the walk (no full labelling).
TEST(InPlaceFracture, AChipIsProvenOneShellAroundTheCut) {
    const Mesh ring = makeTorus({0, 0, 0}, 1, 0.2, 256, 48);
    const MeshFacts facts = analyzeMesh(ring).value();
    const ConvexPolytope chip =
        ConvexPolytope::fromAabb({{1.1013, -0.0937, -0.1071}, {1.43, 0.1123, 0.0917}});
    auto r = fractureWithCells(Mesh(ring), {chip}, FractureParams{}, MeshFacts(facts));
    ASSERT_TRUE(r);
    EXPECT_TRUE(r->stats.editedInPlace);
    EXPECT_FALSE(r->stats.islandsLabelledFully);
    for (const Piece& piece : r->pieces)
        expectSoundPiece(piece);
}

/// Simplification around the cut removes the vertices the cut made on flat faces, in place: fewer triangles
/// than without it, the same solid, and a topology that is still the mesh's.
TEST(InPlaceFracture, SimplificationAroundTheCutRemovesVertices) {
    const Mesh box = makeSubdividedBox({0, 0, 0}, {1, 1, 1}, 48);
    const MeshFacts facts = analyzeMesh(box).value();
    ASSERT_TRUE(facts.topology.fits(box));
    const ConvexPolytope corner = ConvexPolytope::fromAabb({{0.6013, 0.6071, 0.5937}, {1.2, 1.3, 1.25}});
    FractureParams plain;
    plain.simplifyPieces = false;
    auto simple = fractureWithCells(Mesh(box), {corner}, FractureParams{}, MeshFacts(facts));
    auto full = fractureWithCells(Mesh(box), {corner}, plain, MeshFacts(facts));
    ASSERT_TRUE(simple);
    ASSERT_TRUE(full);
    ASSERT_TRUE(simple->stats.editedInPlace);
    ASSERT_EQ(simple->pieces.front().cell, -1);
    ASSERT_EQ(full->pieces.front().cell, -1);
    const Piece &a = simple->pieces.front(), &b = full->pieces.front();
    EXPECT_LT(a.mesh.triangles.size(), b.mesh.triangles.size());
    expectSoundPiece(a);
    EXPECT_NEAR(a.mass.volume, b.mass.volume, 1e-12);
}

/// A cell inside the solid makes a cavity (new triangles only, none removed): the fallback labels it, and
/// the remainder (two shells) carries no topology.
TEST(InPlaceFracture, ACavityTakesTheFallback) {
    const Mesh ball = makeSphere({0, 0, 0}, 1, 160, 80);
    const MeshFacts facts = analyzeMesh(ball).value();
    const ConvexPolytope inner = ConvexPolytope::fromAabb({{-0.2, -0.2, -0.2}, {0.2, 0.2, 0.2}});
    auto r = fractureWithCells(Mesh(ball), {inner}, FractureParams{}, MeshFacts(facts));
    ASSERT_TRUE(r);
    EXPECT_TRUE(r->stats.editedInPlace);
    EXPECT_TRUE(r->stats.islandsLabelledFully);
    ASSERT_EQ(r->pieces.size(), 2u);
    EXPECT_EQ(r->pieces[0].cell, -1);
    EXPECT_TRUE(r->pieces[0].facts.topology.empty());
    EXPECT_NEAR(r->pieces[1].mass.volume, 0.4 * 0.4 * 0.4, 1e-12);
    EXPECT_NEAR(r->pieces[0].mass.volume, facts.integrals.volume - 0.064, 1e-9);
    for (const Piece& piece : r->pieces) {
        EXPECT_TRUE(test::closedAndOriented(piece.mesh));
        EXPECT_LE(test::massError(piece.mesh, piece.mass), kRelative);
    }
}

/// Runs the Fast backend's edit, then flips one of its new triangles: the edit no longer closes up.
class FaultyEditor final : public detail::EditingBackend {
public:
    explicit FaultyEditor(const VolumeIntegrals& integrals)
        : fast_(detail::makeFastBackend(false, &integrals)) {}
    std::string name() const override { return "faulty"; }
    Result<SplitResult> split(const Mesh& mesh, const std::vector<ConvexPolytope>& cells) const override {
        return fast_->split(mesh, cells);
    }
    Result<detail::SplitEdit> splitAsEdit(const Mesh& mesh, const std::vector<ConvexPolytope>& cells,
                                          const Aabb& bounds) const override {
        auto r = dynamic_cast<const detail::EditingBackend&>(*fast_).splitAsEdit(mesh, cells, bounds);
        if (r && !r->remainder.added.triangles.empty())
            std::swap(r->remainder.added.triangles[0][1], r->remainder.added.triangles[0][2]);
        return r;
    }

private:
    std::unique_ptr<BooleanBackend> fast_;
};

TEST(InPlaceFracture, AnEditThatDoesNotCloseLeavesTheInputIntact) {
    const Mesh ball = makeSphere({0, 0, 0}, 1, 160, 80);
    MeshFacts facts = analyzeMesh(ball).value();
    const FaultyEditor faulty(facts.integrals);
    const std::vector<ConvexPolytope> cells{ConvexPolytope::fromAabb({{0.7, -0.2, -0.2}, {1.2, 0.2, 0.2}})};
    Mesh mesh = ball;
    auto refused = detail::fractureInPlaceWithBackend(mesh, facts, cells, FractureParams{}, faulty, false);
    ASSERT_FALSE(refused);
    EXPECT_EQ(refused.error().code, ErrorCode::GeometryFailure);
    EXPECT_TRUE(mesh == ball);
    EXPECT_TRUE(facts.topology == buildTopology(ball).value());
    auto redone = detail::fractureInPlaceWithBackend(mesh, facts, cells, FractureParams{}, faulty, true);
    ASSERT_TRUE(redone);
    EXPECT_TRUE(redone->stats.exactFallback);
    EXPECT_FALSE(redone->stats.editedInPlace);
    double volume = redone->droppedVolume;
    for (const Piece& piece : redone->pieces) {
        expectSoundPiece(piece);
        volume += piece.mass.volume;
    }
    EXPECT_NEAR(volume, facts.integrals.volume, 1e-9 * facts.integrals.volume);
}

} // namespace
} // namespace rubble
