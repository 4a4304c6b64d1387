// The fracture pipeline verifies every split before it becomes pieces (closed, oriented, volume conserved).
// These tests inject corrupted splits through a faulty backend and check that each one is caught: reported
// as GeometryFailure, or redone by the exact backend when the pipeline may fall back. They also compare the
// fast closedness check and the island split against straightforward reference implementations.

#include <gtest/gtest.h>

#include <functional>
#include <map>

#include "fracture/BooleanBackends.hpp"
#include "fracture/FracturePipeline.hpp"
#include "geometry/Islands.hpp"
#include "rubble/core/Random.hpp"
#include "rubble/fracture/Fracture.hpp"
#include "rubble/geometry/MassProperties.hpp"

using namespace rubble;

namespace {

// Reference: every directed edge once, no loops, and its reverse present.
bool referenceClosedOriented(const Mesh& m) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
    for (const Triangle& t : m.triangles)
        for (int c = 0; c < 3; ++c) {
            if (t[c] >= m.positions.size() || t[c] == t[(c + 1) % 3])
                return false;
            ++directed[{t[c], t[(c + 1) % 3]}];
        }
    for (const auto& [e, count] : directed)
        if (count != 1 || !directed.count({e.second, e.first}))
            return false;
    return true;
}

/// Runs the Fast backend, then damages its output.
class FaultyBackend final : public BooleanBackend {
public:
    explicit FaultyBackend(std::function<void(SplitResult&)> damage) : damage_(std::move(damage)) {}
    std::string name() const override { return "faulty"; }
    Result<SplitResult> split(const Mesh& mesh, const std::vector<ConvexPolytope>& cells) const override {
        auto r = makeBooleanBackend(BooleanKind::Fast)->split(mesh, cells);
        if (r)
            damage_(*r);
        return r;
    }

private:
    std::function<void(SplitResult&)> damage_;
};

struct Corruption {
    std::string name;
    std::function<void(SplitResult&)> damage;
};

std::vector<Corruption> corruptions() {
    return {
        {"flipped remainder triangle",
         [](SplitResult& s) { std::swap(s.remainder.triangles[5][1], s.remainder.triangles[5][2]); }},
        {"dropped debris triangle",
         [](SplitResult& s) {
             s.inside[0].triangles.pop_back();
             s.inside[0].materials.pop_back();
             s.inside[0].uvs.resize(3 * s.inside[0].triangles.size());
             if (s.inside[0].hasNormals())
                 s.inside[0].normals.resize(3 * s.inside[0].triangles.size());
         }},
        {"duplicated remainder triangle",
         [](SplitResult& s) {
             s.remainder.triangles.push_back(s.remainder.triangles[0]);
             s.remainder.materials.push_back(s.remainder.materials[0]);
             s.remainder.uvs.resize(3 * s.remainder.triangles.size());
             if (s.remainder.hasNormals())
                 s.remainder.normals.resize(3 * s.remainder.triangles.size());
         }},
        {"moved debris vertex (closed, volume not conserved)",
         [](SplitResult& s) {
             for (Vec3& p : s.inside[0].positions)
                 p = p * 1.001;
         }},
        {"vertex index out of range", [](SplitResult& s) { s.remainder.triangles[0][0] = 1u << 30; }},
        {"non-finite coordinate", [](SplitResult& s) { s.inside[0].positions[0].x = std::nan(""); }},
        {"debris inside out",
         [](SplitResult& s) {
             for (Triangle& t : s.inside[0].triangles)
                 std::swap(t[1], t[2]);
         }},
    };
}

FractureParams boxParams() {
    FractureParams p;
    p.backend = BooleanKind::Fast;
    p.sizeLaw.base = 1.0;
    p.sizeLaw.scale = 0;
    return p;
}

} // namespace

TEST(SplitVerification, EveryInjectedCorruptionIsCaught) {
    const Mesh box = makeSubdividedBox({-1, -1, -1}, {1, 1, 1}, 4);
    const double v0 = signedVolume(box);
    const FractureParams params = boxParams();
    const auto cells = generateCells(box.bounds(), {{1, 0.1, 0.2}, {1, 0, 0}, 1}, params, 7);
    // The undamaged split passes.
    auto good = makeBooleanBackend(BooleanKind::Fast)->split(box, cells);
    ASSERT_TRUE(good.isOk()) << good.error().message;
    ASSERT_FALSE(good->inside[0].empty());
    EXPECT_TRUE(detail::splitIsSound(*good, v0));
    const FaultyBackend harmless([](SplitResult&) {});
    auto ok = detail::fractureWithBackend(box, cells, params, harmless, false);
    ASSERT_TRUE(ok.isOk()) << ok.error().message;
    EXPECT_FALSE(ok->stats.exactFallback);

    for (const Corruption& c : corruptions()) {
        SplitResult bad = *good;
        c.damage(bad);
        EXPECT_FALSE(detail::splitIsSound(bad, v0)) << c.name;
        const FaultyBackend faulty(c.damage);
        // Without a fallback the pipeline refuses the split ...
        auto refused = detail::fractureWithBackend(box, cells, params, faulty, false);
        ASSERT_FALSE(refused.isOk()) << c.name;
        EXPECT_EQ(refused.error().code, ErrorCode::GeometryFailure) << c.name;
        // ... with one it redoes the split exactly and says so.
        auto redone = detail::fractureWithBackend(box, cells, params, faulty, true);
        ASSERT_TRUE(redone.isOk()) << c.name << ": " << redone.error().message;
        EXPECT_TRUE(redone->stats.exactFallback) << c.name;
        double sum = redone->droppedVolume;
        for (const Piece& p : redone->pieces) {
            EXPECT_TRUE(referenceClosedOriented(p.mesh)) << c.name;
            sum += p.mass.volume;
        }
        EXPECT_NEAR(sum, v0, 1e-9 * v0) << c.name;
    }
}

TEST(SplitVerification, ClosednessCheckAgreesWithReferenceOnRandomDamage) {
    Mesh twoBoxes = makeSubdividedBox({-1, -1, -1}, {0, 1, 1}, 2);
    twoBoxes.append(makeSubdividedBox({0.5, -1, -1}, {1.5, 1, 1}, 2));
    const std::vector<Mesh> meshes{makeSubdividedBox({-1, -1, -1}, {1, 1, 1}, 3),
                                   makeTorus({0, 0, 0}, 1, 0.35, 12, 6), makeSphere({0, 0, 0}, 1, 10, 6),
                                   twoBoxes};
    Rng rng(3);
    int closed = 0, open = 0;
    for (const Mesh& base : meshes) {
        EXPECT_TRUE(detail::isClosedOriented(base));
        for (int i = 0; i < 200; ++i) {
            Mesh m = base;
            const auto t = static_cast<std::size_t>(rng.below(m.triangleCount()));
            switch (rng.below(6)) {
            case 0: // flip
                std::swap(m.triangles[t][0], m.triangles[t][1]);
                break;
            case 1: // drop
                m.triangles.erase(m.triangles.begin() + static_cast<std::ptrdiff_t>(t));
                break;
            case 2: // duplicate
                m.triangles.push_back(m.triangles[t]);
                break;
            case 3: // collapse an edge into a loop
                m.triangles[t][1] = m.triangles[t][0];
                break;
            case 4: // re-point a corner to another vertex
                m.triangles[t][2] = static_cast<std::uint32_t>(rng.below(m.positions.size()));
                break;
            default: // an unreferenced extra vertex: still closed
                m.positions.push_back(m.positions[m.triangles[t][0]]);
                break;
            }
            const bool want = referenceClosedOriented(m);
            EXPECT_EQ(detail::isClosedOriented(m), want) << "mesh " << &base - meshes.data() << " case " << i;
            (want ? closed : open)++;
        }
    }
    // Both verdicts occur often (about 4 in 6 damages open a mesh).
    EXPECT_GT(open, 400);
    EXPECT_GT(closed, 100);
}

TEST(SplitVerification, MovingSplitIntoIslandsMatchesCopying) {
    Mesh m = makeSubdividedBox({-1, -1, -1}, {0, 1, 1}, 2);
    m.append(makeSubdividedBox({0.5, -1, -1}, {1.5, 1, 1}, 3));
    m.append(makeSphere({5, 0, 0}, 1, 8, 5));
    m.computeFlatNormals();
    const std::vector<Mesh> copied = splitIntoIslands(m);
    ASSERT_EQ(copied.size(), 3u);
    EXPECT_EQ(splitIntoIslands(Mesh(m)), copied);
    // Each island is the old-style result: its triangles in order, vertices numbered by first use.
    for (const Mesh& island : copied) {
        Mesh expected = island;
        expected.removeUnreferencedVertices();
        EXPECT_EQ(expected, island);
        EXPECT_TRUE(detail::isClosedOriented(island));
    }
    const Mesh one = makeSubdividedBox({-1, -1, -1}, {1, 1, 1}, 2);
    const std::vector<Mesh> moved = splitIntoIslands(Mesh(one));
    ASSERT_EQ(moved.size(), 1u);
    EXPECT_EQ(moved[0], one);
}
