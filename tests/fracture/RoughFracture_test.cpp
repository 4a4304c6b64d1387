// Rough cut faces (docs/roughness.md): the invariants of a flat cut kept (closed pieces, exact volume,
// neighbours that fit, the outer surface unmoved, no self-intersection) and the cut really rough, with the
// requested Hurst exponent.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <set>

#include "PieceHash.hpp"
#include "TestSupport.hpp"
#include "fracture/RoughCut.hpp"
#include "geometry/FormerMeshHash.hpp"
#include "rubble/core/Random.hpp"
#include "rubble/fracture/Fracture.hpp"
#include "rubble/geometry/MassProperties.hpp"
#include "rubble/geometry/MeshCheck.hpp"

using namespace rubble;
using rubble::test::closedAndOriented;
using rubble::test::surfacePoint;

namespace {

Mesh cube() {
    return makeSubdividedBox({-1, -1, -1}, {1, 1, 1}, 6);
}

FractureParams roughParams(CellPattern pattern = CellPattern::SingleCell) {
    FractureParams p;
    p.pattern = pattern;
    p.cells = 8;
    p.sizeLaw.base = 1.6;
    p.sizeLaw.scale = 0;
    p.roughness = roughnessPreset("concrete");
    p.minPieceVolumeFraction = 0;
    return p;
}

/// Sum of the pieces' volumes (of their meshes) and dropped volume.
double volumeSum(const FractureResult& r) {
    double v = r.droppedVolume;
    for (const Piece& p : r.pieces)
        v += signedVolume(p.mesh);
    return v;
}

void expectSoundPieces(const Mesh& input, const FractureResult& r, const std::string& what) {
    const double v0 = signedVolume(input);
    for (const Piece& p : r.pieces) {
        EXPECT_TRUE(closedAndOriented(p.mesh)) << what;
        EXPECT_TRUE(p.mesh.validate().isOk()) << what;
        EXPECT_GT(p.mass.volume, 0) << what;
        EXPECT_LT(test::massError(p.mesh, p.mass), 1e-9) << what; // mass of the rough mesh
        EXPECT_EQ(p.mesh.uvs.size(), 3 * p.mesh.triangles.size()) << what;
    }
    EXPECT_NEAR(volumeSum(r), v0, 1e-9 * v0) << what;
}

/// A triangle's corners from its smallest, in its orientation (reversed: the other orientation).
std::array<double, 9> orientedKey(const Mesh& m, std::size_t t, bool reversed) {
    auto c = m.corners(t);
    if (reversed)
        std::swap(c[1], c[2]);
    std::size_t first = 0;
    for (std::size_t k = 1; k < 3; ++k)
        if (std::tie(c[k].x, c[k].y, c[k].z) < std::tie(c[first].x, c[first].y, c[first].z))
            first = k;
    std::array<double, 9> key{};
    for (std::size_t k = 0; k < 3; ++k)
        for (int a = 0; a < 3; ++a)
            key[3 * k + static_cast<std::size_t>(a)] = c[(first + k) % 3][a];
    return key;
}

/// Every cut triangle (interior material) of every piece is in exactly one other piece, reversed, with the
/// same bits: neighbouring cut surfaces coincide.
void expectCutsCoincide(const FractureResult& r, const std::string& what) {
    std::map<std::array<double, 9>, std::vector<std::size_t>> owners;
    for (std::size_t i = 0; i < r.pieces.size(); ++i) {
        const Mesh& m = r.pieces[i].mesh;
        for (std::size_t t = 0; t < m.triangles.size(); ++t)
            if (m.materials[t] == kInteriorMaterial)
                owners[orientedKey(m, t, false)].push_back(i);
    }
    std::size_t unmatched = 0;
    for (const auto& [key, pieces] : owners) {
        std::array<double, 9> rev{};
        // The reversed triangle: corners 0, 2, 1 from the same first corner.
        for (int a = 0; a < 3; ++a) {
            rev[static_cast<std::size_t>(a)] = key[static_cast<std::size_t>(a)];
            rev[3 + static_cast<std::size_t>(a)] = key[6 + static_cast<std::size_t>(a)];
            rev[6 + static_cast<std::size_t>(a)] = key[3 + static_cast<std::size_t>(a)];
        }
        auto it = owners.find(rev);
        if (pieces.size() != 1 || it == owners.end() || it->second.size() != 1 || it->second[0] == pieces[0])
            ++unmatched;
    }
    EXPECT_EQ(unmatched, 0u) << what << ": of " << owners.size() << " cut triangles";
}

/// The largest distance of an outer (non-cut) triangle's corner from the cube's surface.
double offCube(const FractureResult& r) {
    double worst = 0;
    for (const Piece& p : r.pieces)
        for (std::size_t t = 0; t < p.mesh.triangles.size(); ++t) {
            if (p.mesh.materials[t] == kInteriorMaterial)
                continue;
            for (const Vec3& c : p.mesh.corners(t)) {
                const double d = std::min(
                    {std::abs(std::abs(c.x) - 1), std::abs(std::abs(c.y) - 1), std::abs(std::abs(c.z) - 1)});
                worst = std::max(worst, d);
            }
        }
    return worst;
}

/// A cube cut by one big cell: its part x > 0.01 (the cut is a square of area 4; x = 0 holds vertices).
Result<FractureResult> halfCut(const Roughness& rough, const Mesh& input = cube()) {
    FractureParams p;
    p.roughness = rough;
    p.simplifyPieces = false;
    std::vector<ConvexPolytope> cells{ConvexPolytope::fromAabb({{0.01, -3, -3}, {3, 3, 3}})};
    return fractureWithCells(input, cells, p);
}

/// An absolute roughness of this amplitude, feature size, octaves and triangle budget.
Roughness absoluteRoughness(double amplitude, double featureSize, int octaves, int budget) {
    Roughness rough;
    rough.relative = false;
    rough.amplitude = amplitude;
    rough.featureSize = featureSize;
    rough.octaves = octaves;
    rough.maxTrianglesPerPiece = budget;
    return rough;
}

/// The vertices of the half cut's cut face (interior material) of the piece x < 0.
std::vector<Vec3> cutVertices(const FractureResult& r) {
    std::set<std::tuple<double, double, double>> seen;
    std::vector<Vec3> out;
    for (const Piece& p : r.pieces) {
        if (p.cell != -1)
            continue;
        for (std::size_t t = 0; t < p.mesh.triangles.size(); ++t)
            if (p.mesh.materials[t] == kInteriorMaterial)
                for (const Vec3& c : p.mesh.corners(t))
                    if (seen.emplace(c.x, c.y, c.z).second)
                        out.push_back(c);
    }
    return out;
}

/// The area of the cut faces (interior material) of the pieces of this cell (every piece: kAnyCell).
constexpr std::int32_t kAnyCell = -2;
double cutArea(const FractureResult& r, std::int32_t cell = kAnyCell) {
    double a = 0;
    for (const Piece& p : r.pieces)
        if (cell == kAnyCell || p.cell == cell)
            for (std::size_t t = 0; t < p.mesh.triangles.size(); ++t)
                if (p.mesh.materials[t] == kInteriorMaterial)
                    a += 0.5 * length(p.mesh.triangleNormal(t));
    return a;
}

/// The vertices of cut triangles (interior material) of r's pieces that are not vertices of the mesh it cut
/// and lie on none of its cells' face planes: new cut vertices moved off their flat cut.
std::size_t displacedNewCutVertices(const Mesh& before, const FractureResult& r) {
    std::set<std::tuple<double, double, double>> old;
    for (const Vec3& v : before.positions)
        old.emplace(v.x, v.y, v.z);
    std::set<std::tuple<double, double, double>> moved;
    for (const Piece& p : r.pieces)
        for (std::size_t t = 0; t < p.mesh.triangles.size(); ++t) {
            if (p.mesh.materials[t] != kInteriorMaterial)
                continue;
            for (const Vec3& c : p.mesh.corners(t)) {
                if (old.count({c.x, c.y, c.z}))
                    continue;
                double nearest = 1e300;
                for (const ConvexPolytope& cell : r.cells)
                    for (const PolytopeFaceView& f : cell.faces())
                        nearest = std::min(nearest, std::abs(f.plane.signedDistance(c)));
                if (nearest > 1e-6)
                    moved.emplace(c.x, c.y, c.z);
            }
        }
    return moved.size();
}

} // namespace

TEST(RoughFracture, RandomHitsAndPiecesOfPiecesKeepTheInvariants) {
    const Mesh input = cube();
    Rng rng(7);
    int rough = 0, total = 0, roughAgain = 0;
    for (int i = 0; i < 6; ++i) {
        Impact impact;
        impact.point = surfacePoint(input, rng);
        impact.impulse = 1;
        const FractureParams params = roughParams(i % 2 ? CellPattern::Shatter : CellPattern::SingleCell);
        const std::string what = "impact " + std::to_string(i);
        auto r = fracture(input, impact, params, rng.next());
        ASSERT_TRUE(r) << what << ": " << r.error().message;
        ++total;
        rough += r->stats.rough ? 1 : 0;
        expectSoundPieces(input, *r, what);
        if (r->stats.rough) // a flat cut (exact fallback) is simplified: its sides may differ in flat regions
            expectCutsCoincide(*r, what);
        EXPECT_LT(offCube(*r), 1e-12) << what;
        // Pieces of pieces: the largest piece hit again is roughened again where it is cut.
        const auto largest =
            std::max_element(r->pieces.begin(), r->pieces.end(),
                             [](const Piece& a, const Piece& b) { return a.mass.volume < b.mass.volume; });
        Impact again;
        again.point = surfacePoint(largest->mesh, rng);
        auto r2 = fracture(largest->mesh, again, params, rng.next(), largest->facts);
        ASSERT_TRUE(r2) << what << " again: " << r2.error().message;
        ++total;
        rough += r2->stats.rough ? 1 : 0;
        expectSoundPieces(largest->mesh, *r2, what + " again");
        EXPECT_LT(offCube(*r2), 1e-12) << what << " again";
        roughAgain += displacedNewCutVertices(largest->mesh, *r2) > 0 ? 1 : 0;
        for (const Piece& p : r2->pieces) {
            const MeshReport report = checkMesh(p.mesh);
            EXPECT_TRUE(report.selfIntersectionsChecked) << report.selfIntersectionNote;
            EXPECT_TRUE(report.valid()) << what << " again: " << test::joinLines(report.problems);
        }
    }
    EXPECT_GE(rough, total - 2); // the exact fallback (flat) is rare
    EXPECT_GE(roughAgain, 4);    // the second cuts are rough too
}

TEST(RoughFracture, PiecesDoNotSelfIntersect) {
    const Mesh input = cube();
    Rng rng(11);
    for (int i = 0; i < 12; ++i) {
        Impact impact;
        impact.point = surfacePoint(input, rng);
        FractureParams params = roughParams(i % 2 ? CellPattern::Shatter : CellPattern::SingleCell);
        if (i >= 6) { // three times the preset's amplitude: heights limited by the envelope near the creases
            params.roughness.amplitude = 0.3;
            params.roughness.featureSize = 0.5;
        }
        auto r = fracture(input, impact, params, rng.next());
        ASSERT_TRUE(r);
        EXPECT_TRUE(r->stats.rough);
        for (const Piece& p : r->pieces) {
            const MeshReport report = checkMesh(p.mesh);
            EXPECT_TRUE(report.selfIntersectionsChecked) << report.selfIntersectionNote;
            EXPECT_EQ(report.selfIntersections, 0u) << "impact " << i;

            EXPECT_TRUE(report.valid()) << test::joinLines(report.problems);
        }
    }
}

TEST(RoughFracture, TheCutIsRough) {
    // Fine roughness (amplitude 0.8 of the feature size) with a budget that resolves it.
    const Roughness rough = absoluteRoughness(0.12, 0.15, 2, 100000);
    auto r = halfCut(rough);
    ASSERT_TRUE(r) << r.error().message;
    ASSERT_TRUE(r->stats.rough);
    ASSERT_EQ(r->pieces.size(), 2u);
    expectCutsCoincide(*r, "half cut");
    // The flat cut is the square x = 0 of area 4.
    EXPECT_GE(cutArea(*r, -1), 1.15 * 4.0);
    EXPECT_NEAR(cutArea(*r, -1), cutArea(*r, 0), 1e-9);
    double largest = 0;
    for (const Vec3& v : cutVertices(*r))
        largest = std::max(largest, std::abs(v.x - 0.01));
    EXPECT_GE(largest, rough.amplitude / 3);
    EXPECT_LE(largest, rough.amplitude);
    EXPECT_LT(offCube(*r), 1e-12);
}

TEST(RoughFracture, StructureFunctionFollowsTheHurstExponent) {
    for (const double hurst : {0.5, 0.8}) {
        Roughness rough;
        rough.relative = false;
        rough.amplitude = 0.05;
        rough.featureSize = 3.2;
        rough.hurst = hurst;
        rough.octaves = 7;
        rough.maxTrianglesPerPiece = 200000;
        rough.seed = 3;
        auto r = halfCut(rough);
        ASSERT_TRUE(r) << r.error().message;
        ASSERT_TRUE(r->stats.rough);
        // Heights (x) of vertices away from the outline (where the envelope does not bind), binned by
        // distance.
        std::vector<Vec3> v;
        std::size_t k = 0;
        for (const Vec3& p : cutVertices(*r))
            if (std::abs(p.y) < 0.75 && std::abs(p.z) < 0.75 && k++ % 3 == 0)
                v.push_back(p);
        ASSERT_GT(v.size(), 1000u);
        const double r0 = 0.06, r1 = 0.4; // between the finest wavelength and the longest's quarter
        constexpr int kBins = 8;
        std::array<double, kBins> sum{}, count{};
        for (std::size_t i = 0; i < v.size(); ++i)
            for (std::size_t j = i + 1; j < v.size(); ++j) {
                const double d = std::hypot(v[i].y - v[j].y, v[i].z - v[j].z);
                if (d < r0 || d >= r1)
                    continue;
                const int b = static_cast<int>(kBins * std::log(d / r0) / std::log(r1 / r0));
                const double dh = v[i].x - v[j].x; // the plane is x = 0.01
                sum[static_cast<std::size_t>(b)] += dh * dh;
                count[static_cast<std::size_t>(b)] += 1;
            }
        // Least-squares slope of log S against log r.
        double sx = 0, sy = 0, sxx = 0, sxy = 0;
        for (std::size_t b = 0; b < kBins; ++b) {
            ASSERT_GT(count[b], 0);
            const double x = std::log(r0) + (static_cast<double>(b) + 0.5) * std::log(r1 / r0) / kBins;
            const double y = std::log(sum[b] / count[b]);
            sx += x;
            sy += y;
            sxx += x * x;
            sxy += x * y;
        }
        const double slope = (kBins * sxy - sx * sy) / (kBins * sxx - sx * sx);
        EXPECT_NEAR(slope, 2 * hurst, 0.2) << "hurst " << hurst;
    }
}

TEST(RoughFracture, SameSeedSameBytesOtherSeedOtherSurface) {
    const Mesh input = cube();
    Impact impact;
    impact.point = {1, 0.2, 0.1};
    impact.normal = {1, 0, 0};
    const FractureParams params = roughParams(CellPattern::Shatter);
    auto a = fracture(input, impact, params, 42);
    auto b = fracture(input, impact, params, 42);
    ASSERT_TRUE(a && b);
    EXPECT_TRUE(a->stats.rough);
    EXPECT_EQ(test::hashPieces(*a), test::hashPieces(*b));
    // Pinned, as the flat scenes' golden hash (tests/persist/GoldenHash_test.cpp): a change of the rough
    // surface's bytes must be deliberate.
    EXPECT_EQ(test::hashPieces(*a), 0x4c467e018975d6d6ull);
    EXPECT_EQ(test::hashPieces(*a, detail::formerMeshHash),
              0x93cce0998883d0c0ull); // pinned before Mesh::hash changed
    FractureParams other = params;
    other.roughness.seed = 1;
    auto c = fracture(input, impact, other, 42);
    ASSERT_TRUE(c);
    EXPECT_NE(test::hashPieces(*a), test::hashPieces(*c));
    // Flat is the default, and roughness 0 is flat, bit for bit.
    FractureParams flat = params;
    flat.roughness = {};
    auto f = fracture(input, impact, flat, 42);
    flat.roughness.hurst = 0.5;
    auto g = fracture(input, impact, flat, 42);
    ASSERT_TRUE(f && g);
    EXPECT_FALSE(f->stats.rough);
    EXPECT_EQ(test::hashPieces(*f), test::hashPieces(*g));
    EXPECT_NE(test::hashPieces(*f), test::hashPieces(*a));
}

TEST(RoughFracture, SmallPiecesFollowTheBudget) {
    Roughness rough;
    rough.relative = false;
    rough.amplitude = 0.1;
    rough.featureSize = 1.0;
    rough.octaves = 8; // finer than any budget allows
    rough.maxTrianglesPerPiece = 500;
    auto r = halfCut(rough);
    ASSERT_TRUE(r && r->stats.rough);
    for (const Piece& p : r->pieces) {
        std::size_t cut = 0;
        for (std::uint32_t m : p.mesh.materials)
            cut += m == kInteriorMaterial ? 1 : 0;
        EXPECT_LE(cut, 500u);
        EXPECT_GT(cut, 100u);
    }
}

namespace {

/// The most cut triangles (interior material) of one piece.
std::size_t mostCutTriangles(const FractureResult& r) {
    std::size_t most = 0;
    for (const Piece& p : r.pieces)
        most = std::max(most, static_cast<std::size_t>(std::count(
                                  p.mesh.materials.begin(), p.mesh.materials.end(), kInteriorMaterial)));
    return most;
}

} // namespace

// A cut through a fine mesh: its outline has many short segments, whose slivers an estimate from the cut's
// area misses. The bisection's triangles are counted, so no piece's cut faces exceed the budget, copied or
// edited in place, and the cut is still rough, with no self-intersection.
TEST(RoughFracture, TheBudgetHoldsOnAFineOutline) {
    Mesh sphere = makeSphere({0, 0, 0}, 1, 160, 80);
    const Mesh input = sphere;
    auto facts = analyzeMesh(sphere);
    ASSERT_TRUE(facts);
    FractureParams p = roughParams();
    p.sizeLaw.base = 0.8;
    p.roughness.maxTrianglesPerPiece = 600;
    const Impact impact{{1 - 1e-3, 0.01, 0.02}, {1, 0, 0}, 10};
    auto copied = fracture(input, impact, p, 5);
    auto inPlace = fracture(std::move(sphere), impact, p, 5, std::move(*facts));
    ASSERT_TRUE(copied && inPlace);
    for (const FractureResult* r : {&*copied, &*inPlace}) {
        const std::string what = r->stats.editedInPlace ? "in place" : "copied";
        ASSERT_TRUE(r->stats.rough) << what;
        EXPECT_LE(mostCutTriangles(*r), 600u) << what;
        EXPECT_GT(mostCutTriangles(*r), 300u) << what;
        expectSoundPieces(input, *r, what);
        expectCutsCoincide(*r, what);
    }
    EXPECT_TRUE(inPlace->stats.editedInPlace);
    EXPECT_GT(displacedNewCutVertices(input, *copied), 10u);
    for (const Piece& piece : copied->pieces) {
        const MeshReport report = checkMesh(piece.mesh);
        EXPECT_TRUE(report.selfIntersectionsChecked) << report.selfIntersectionNote;
        EXPECT_TRUE(report.valid()) << test::joinLines(report.problems);
    }
}

// The UVs of a rough face are the planar projection of its flat position in the face's basis, the same
// basis for both sides: every cut corner at a point has the same UV in both pieces, and the UVs span the flat
// cut (the square x = 0.01, |y|, |z| <= 1, at uvScale 2).
TEST(RoughFracture, UvsAreContinuousAcrossTheRoughFace) {
    FractureParams p;
    p.roughness = absoluteRoughness(0.12, 0.5, 2, 20000);
    p.simplifyPieces = false;
    p.uvScale = 2;
    std::vector<ConvexPolytope> cells{ConvexPolytope::fromAabb({{0.01, -3, -3}, {3, 3, 3}})};
    auto r = fractureWithCells(cube(), cells, p);
    ASSERT_TRUE(r) << r.error().message;
    ASSERT_TRUE(r->stats.rough);
    std::map<std::tuple<double, double, double>, Vec2> uvAt;
    std::size_t corners = 0, mismatched = 0;
    Vec2 lo{1e300, 1e300}, hi{-1e300, -1e300};
    for (const Piece& piece : r->pieces) {
        const Mesh& m = piece.mesh;
        for (std::size_t t = 0; t < m.triangles.size(); ++t) {
            if (m.materials[t] != kInteriorMaterial)
                continue;
            const auto c = m.corners(t);
            for (std::size_t k = 0; k < 3; ++k) {
                const Vec2 uv = m.uvs[3 * t + k];
                const auto [it, fresh] = uvAt.emplace(std::tuple{c[k].x, c[k].y, c[k].z}, uv);
                mismatched += !fresh && (it->second.x != uv.x || it->second.y != uv.y) ? 1 : 0;
                ++corners;
                lo = {std::min(lo.x, uv.x), std::min(lo.y, uv.y)};
                hi = {std::max(hi.x, uv.x), std::max(hi.y, uv.y)};
            }
        }
    }
    EXPECT_GT(corners, 1000u);
    EXPECT_EQ(mismatched, 0u) << "of " << corners << " cut corners";
    EXPECT_NEAR(hi.x - lo.x, 4.0, 2e-6); // stored in float (values up to 6)
    EXPECT_NEAR(hi.y - lo.y, 4.0, 2e-6);
}

// Wood (the preset's grainStretch 6): wavelengths along the grain six times the ones across it, so the
// height field changes far less along the grain at the same distance.
TEST(RoughFracture, WoodIsSmootherAlongTheGrain) {
    Roughness wood = roughnessPreset("wood");
    wood.seed = 5;
    const Vec3 grain{0, 0, 1};
    const detail::RoughField field(wood, 1.0, wood.octaves, grain);
    Rng rng(3);
    double along = 0, across = 0;
    for (int i = 0; i < 2000; ++i) {
        const Vec3 p{rng.uniform(-5, 5), rng.uniform(-5, 5), rng.uniform(-5, 5)};
        const double h = field(p);
        along += std::pow(field(p + grain * 0.1) - h, 2);
        across += std::pow(field(p + Vec3{0.1, 0, 0}) - h, 2);
    }
    EXPECT_LT(along, 0.3 * across);
    EXPECT_GT(along, 0);
    Roughness isotropic = wood;
    isotropic.grainStretch = 1;
    const detail::RoughField plain(isotropic, 1.0, wood.octaves, grain);
    double plainAlong = 0, plainAcross = 0;
    for (int i = 0; i < 2000; ++i) {
        const Vec3 p{rng.uniform(-5, 5), rng.uniform(-5, 5), rng.uniform(-5, 5)};
        plainAlong += std::pow(plain(p + grain * 0.1) - plain(p), 2);
        plainAcross += std::pow(plain(p + Vec3{0.1, 0, 0}) - plain(p), 2);
    }
    EXPECT_GT(plainAlong, 0.6 * plainAcross);
}

TEST(RoughFracture, ParametersAreValidated) {
    EXPECT_TRUE(validateRoughness({}));
    for (const char* m : {"concrete", "brick", "stone", "wood", "glass", "steel"})
        EXPECT_TRUE(validateRoughness(roughnessPreset(m))) << m;
    EXPECT_FALSE(roughnessPreset("steel").active());
    EXPECT_TRUE(roughnessPreset("concrete").active());
    auto expectRefused = [](Roughness r, const std::string& name) {
        const Status s = validateRoughness(r);
        ASSERT_FALSE(s);
        EXPECT_NE(s.message().find(name), std::string::npos) << s.message();
    };
    Roughness r;
    r.amplitude = std::nan("");
    expectRefused(r, "roughness must be");
    r = {};
    r.amplitude = 2; // relative: at most 1
    expectRefused(r, "roughness must be");
    r = {};
    r.hurst = 0;
    expectRefused(r, "hurst must be");
    r = {};
    r.octaves = 11;
    expectRefused(r, "octaves must be");
    r = {};
    r.featureSize = -1;
    expectRefused(r, "feature_size must be");
    r = {};
    r.grainStretch = 0.5;
    expectRefused(r, "grain_stretch must be");
}

// At the concrete preset and the default budget, on 16-cell shatters of the cube: the cut area over the flat
// cut's. The envelope follows the dihedral angle along cell edges and the outer surface's angle along it
// (docs/roughness.md): 1.027 here, 1.021 with 10° along the outer surface, 1.014 with 10° everywhere.
TEST(RoughFracture, EdgeEnvelopesFollowTheDihedralAngle) {
    const Mesh input = cube();
    double rough = 0, flat = 0;
    for (int i = 0; i < 4; ++i) {
        Rng rng(100 + static_cast<std::uint64_t>(i));
        Impact impact;
        impact.point = surfacePoint(input, rng);
        FractureParams params = roughParams(CellPattern::Shatter);
        const auto seed = rng.next();
        auto r = fracture(input, impact, params, seed);
        params.roughness.amplitude = 0;
        auto f = fracture(input, impact, params, seed);
        ASSERT_TRUE(r && f);
        ASSERT_TRUE(r->stats.rough);
        rough += cutArea(*r);
        flat += cutArea(*f);
    }
    EXPECT_GT(rough / flat, 1.025);
}

// Rendered normals of a rough face: the area-weighted normals of the face's own triangles around each vertex
// (smooth across it, not mixed with the outer surface at its outline), pointing outward (out of the flat cut
// plane: the rough face is a graph over it, so every triangle does too), each within the cone of the
// geometric normals around its vertex; the outer surface keeps its own normals. (A corner normal can be more
// than 90° from its own triangle's normal where the surface turns sharply: the cone bound, not a fixed
// angle.)
TEST(RoughFracture, NormalsAreSmoothOnTheRoughFaceAndSharpAtItsOutline) {
    Mesh input = cube();
    for (std::size_t t = 0; t < input.triangles.size(); ++t)
        for (int k = 0; k < 3; ++k)
            input.normals.emplace_back(normalized(input.triangleNormal(t)));
    auto r = halfCut(absoluteRoughness(0.12, 0.5, 2, 20000), input);
    ASSERT_TRUE(r) << r.error().message;
    ASSERT_TRUE(r->stats.rough);
    std::size_t cutCorners = 0, outlineCorners = 0;
    double worstExcess = -1; // angle to the triangle's normal beyond the widest neighbour's, radians
    for (const Piece& piece : r->pieces) {
        const Mesh& m = piece.mesh;
        ASSERT_EQ(m.normals.size(), 3 * m.triangles.size());
        const Vec3 outward = piece.cell == -1 ? Vec3{1, 0, 0} : Vec3{-1, 0, 0}; // out of the cut x = 0.01
        using Key = std::tuple<double, double, double>;
        std::map<Key, Vec3> sum;                 // area-weighted normal of the cut triangles at a point
        std::map<Key, std::vector<Vec3>> around; // their unit normals
        std::set<Key> outer;                     // points of outer triangles
        for (std::size_t t = 0; t < m.triangles.size(); ++t)
            for (const Vec3& c : m.corners(t)) {
                const Key key{c.x, c.y, c.z};
                if (m.materials[t] != kInteriorMaterial) {
                    outer.insert(key);
                    continue;
                }
                sum[key] += m.triangleNormal(t);
                around[key].push_back(normalized(m.triangleNormal(t)));
            }
        for (std::size_t t = 0; t < m.triangles.size(); ++t) {
            const Vec3 tn = normalized(m.triangleNormal(t));
            const auto c = m.corners(t);
            for (std::size_t k = 0; k < 3; ++k) {
                const Vec3 stored = m.normals[3 * t + k];
                EXPECT_NEAR(length(stored), 1.0, 1e-6); // unit, rounded to float
                const Vec3 n = normalized(stored);
                if (m.materials[t] != kInteriorMaterial) { // the outer surface keeps its flat normals
                    EXPECT_GT(dot(n, tn), 1 - 1e-9);
                    continue;
                }
                const Key key{c[k].x, c[k].y, c[k].z};
                ++cutCorners;
                outlineCorners += outer.count(key);
                EXPECT_GT(dot(n, normalized(sum[key])), 1 - 1e-9) << "not the face's own smooth normal";
                EXPECT_GT(dot(tn, outward), 0) << "a folded triangle";
                EXPECT_GT(dot(n, outward), 0) << "points inward";
                double widest = 0;
                for (const Vec3& o : around[key])
                    widest = std::max(widest, std::acos(std::clamp(dot(o, tn), -1.0, 1.0)));
                worstExcess = std::max(worstExcess, std::acos(std::clamp(dot(n, tn), -1.0, 1.0)) - widest);
            }
        }
    }
    EXPECT_GT(cutCorners, 1000u);
    EXPECT_GT(outlineCorners, 50u); // the outline is tested, not only the face's inside
    EXPECT_LE(worstExcess, 1e-7);
}
// A cut that grazes the outer surface: the plane z = 0.88 + x tan 8° meets the cube's top at 8°, less than
// the 10° envelope of a cut face whose outer angle is unknown. The envelope along the outer surface follows
// the angle both sides recorded there (docs/roughness.md), so the thin piece above the cut stays a simple
// solid.
TEST(RoughFracture, ACutGrazingTheOuterSurfaceDoesNotCrossIt) {
    const double tan8 = std::tan(8 * std::numbers::pi / 180);
    const Plane below = Plane::fromPointNormal({0, 0, 0.88}, {tan8, 0, -1});
    std::vector<ConvexPolytope> cells{ConvexPolytope::fromAabb({{-3, -3, -3}, {3, 3, 3}}).clipped(below)};
    FractureParams p;
    p.roughness = absoluteRoughness(0.05, 0.2, 2, 20000);
    p.simplifyPieces = false;
    auto r = fractureWithCells(cube(), cells, p);
    ASSERT_TRUE(r) << r.error().message;
    ASSERT_TRUE(r->stats.rough);
    ASSERT_EQ(r->pieces.size(), 2u);
    expectCutsCoincide(*r, "grazing cut");
    EXPECT_LT(offCube(*r), 1e-12);
    for (const Piece& piece : r->pieces) {
        const MeshReport report = checkMesh(piece.mesh);
        EXPECT_TRUE(report.selfIntersectionsChecked) << report.selfIntersectionNote;
        EXPECT_EQ(report.selfIntersections, 0u) << "piece of cell " << piece.cell;
    }
}

namespace {

/// A rough hit edited in place (docs/megamesh.md): on a UV sphere of radius r (slices 160 r, stacks 80 r: the
/// same triangle size, ~25k r² triangles) by one cell of fixed size, the remainder's triangles that differ
/// from the input's slot by slot.
struct RoughHit {
    std::size_t triangles = 0; // of the input
    std::size_t changed = 0;   // remainder slots that differ from the input's, and slots added or dropped
    std::size_t remainder = 0; // triangles of the remainder
    std::set<std::array<double, 9>> cut; // the cut triangles of every piece (oriented keys)
    std::uint64_t hash = 0;              // of the pieces
};

RoughHit roughHitInPlace(int radius, bool inPlace) {
    Mesh sphere = makeSphere({0, 0, 0}, radius, 160 * radius, 80 * radius);
    RoughHit h;
    h.triangles = sphere.triangles.size();
    const Mesh input = sphere;
    auto facts = analyzeMesh(sphere);
    EXPECT_TRUE(facts);
    if (!facts)
        return h;
    FractureParams p = roughParams();
    p.sizeLaw.base = 0.4;
    const Impact impact{{radius - 1e-3, 0.01, 0.02}, {1, 0, 0}, 10};
    auto r = inPlace ? fracture(std::move(sphere), impact, p, 5, std::move(*facts))
                     : fracture(input, impact, p, 5);
    EXPECT_TRUE(r) << (r ? "" : r.error().message);
    if (!r)
        return h;
    const std::string what = "sphere " + std::to_string(radius) + (inPlace ? " in place" : " copied");
    EXPECT_TRUE(r->stats.rough) << what;
    EXPECT_EQ(r->stats.editedInPlace, inPlace) << what;
    // the walk around the cut proved the remainder one shell
    EXPECT_FALSE(r->stats.islandsLabelledFully) << what;
    expectSoundPieces(input, *r, what);
    expectCutsCoincide(*r, what);
    h.hash = test::hashPieces(*r);
    for (const Piece& piece : r->pieces) {
        const Mesh& m = piece.mesh;
        for (std::size_t t = 0; t < m.triangles.size(); ++t)
            if (m.materials[t] == kInteriorMaterial)
                h.cut.insert(orientedKey(m, t, false));
        if (piece.cell != -1 || m.triangles.size() < h.remainder)
            continue;
        h.remainder = m.triangles.size();
        h.changed = std::max(m.triangles.size(), input.triangles.size()) -
                    std::min(m.triangles.size(), input.triangles.size());
        for (std::size_t t = 0; t < std::min(m.triangles.size(), input.triangles.size()); ++t)
            h.changed += m.corners(t) != input.corners(t) ? 1 : 0;
    }
    return h;
}

} // namespace

// A rough cut on a mesh above kTopologyAboveTriangles is made in place, as a flat one: the remainder's edit
// is roughened as a mesh of its own, so the triangles it changes follow the cut, not the mesh, and the rough
// surface is the copying path's, point for point.
TEST(RoughFracture, RoughCutsOnLargeMeshesAreMadeInPlace) {
    const RoughHit small = roughHitInPlace(1, true), large = roughHitInPlace(2, true);
    ASSERT_GT(small.remainder, 0u);
    ASSERT_GT(large.remainder, 0u);
    EXPECT_GT(large.triangles, 3 * small.triangles);
    // the same cut on four times the triangles: a copy would change every slot after the first removed one
    EXPECT_LT(large.changed, 2 * small.changed + 2000);
    EXPECT_LT(large.changed, large.remainder / 20);
    EXPECT_GT(small.cut.size(), 100u);
    EXPECT_EQ(roughHitInPlace(1, false).cut, small.cut);
    EXPECT_EQ(roughHitInPlace(1, true).hash, small.hash); // same seed, same bytes
}
