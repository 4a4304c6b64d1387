// Determinism across builds, pinned (as Box2D pins EXPECTED_HASH): a fixed journal replayed on a fixed scene
// must give this geometry hash in the gcc build and in the clang sanitizer build alike. A change of this
// value is a change of every saved journal's meaning: update it only on purpose (docs/journal.md).
#include <gtest/gtest.h>

#include "JournalScene.hpp"
#include "WorldSteps.hpp"
#include "geometry/FormerMeshHash.hpp"
#include "persist/Bytes.hpp"
#include "rubble/core/Random.hpp"
#include "rubble/persist/JournalFile.hpp"
#include "rubble/runtime/JournalPlayer.hpp"

namespace rubble {
namespace {

constexpr std::uint64_t kExpectedGeometryHash = 0x929A860E7BF0E5A2ull;
/// The same geometry hashed by Mesh::hash's former FNV-1a: pinned before Mesh::hash changed, unchanged since.
constexpr std::uint64_t kExpectedFormerGeometryHash = 0x8EA90FB6A15C2F45ull;
constexpr std::uint32_t kExpectedJournalCrc = 0x2144DF1Cu;
/// The same scene and journal with rough cut faces (the concrete preset; docs/roughness.md).
constexpr std::uint64_t kExpectedRoughGeometryHash = 0xCEDCE36FA2F7967Eull;

DestructionWorld::Config goldenConfig(int workers) {
    DestructionWorld::Config c;
    c.workers = workers;
    c.deterministic = true;
    c.seed = 20261125;
    c.minPieceVolume = 1e-4;
    return c;
}

// A subdivided wall (shatter), a sphere (single cell) and a torus (shatter, crumbles once detailed enough),
// their cuts flat unless roughness says otherwise.
void addScene(DestructionWorld& world, const Roughness& roughness = {}) {
    ObjectDesc wall;
    wall.mesh = makeSubdividedBox({-2, 0, -0.2}, {2, 3, 0.2}, 6);
    wall.fracture.pattern = CellPattern::Shatter;
    wall.fracture.cells = 6;
    ObjectDesc ball;
    ball.mesh = makeSphere({0, 0, 0}, 1.0, 24, 16);
    ObjectDesc ring;
    ring.mesh = makeTorus({0, 0, 0}, 1.5, 0.4, 32, 12);
    ring.fracture.pattern = CellPattern::Shatter;
    ring.fracture.cells = 4;
    for (ObjectDesc* d : {&wall, &ball, &ring}) {
        d->fracture.roughness = roughness;
        ASSERT_TRUE(world.addObject(std::move(*d)));
    }
}

// The journal: impacts on the three objects, some in the same frame (merged into one job), and hits on the
// pieces of earlier fractures (ids 4 and up), derived from the world as it plays so that the test also
// records them; the recorded journal is then replayed on a fresh world.
std::vector<JournalEvent> recordGoldenJournal(const Roughness& roughness = {}) {
    DestructionWorld world(goldenConfig(1));
    addScene(world, roughness);
    std::vector<JournalEvent> events;
    world.setJournalSink([&](const JournalEvent& e) { events.push_back(e); });
    for (int frame = 0; frame < 40; ++frame) {
        if (frame == 0) {
            EXPECT_TRUE(world.submitImpact(1, Impact{{0.3, 1.4, 0.2}, {0, 0, 1}, 400}));
            EXPECT_TRUE(world.submitImpact(1, Impact{{-1.2, 2.1, 0.2}, {0, 0, 1}, 900}));
            EXPECT_TRUE(world.submitImpact(2, Impact{{0.6, 0.8, 0.0}, {0.6, 0.8, 0}, 300}));
            EXPECT_TRUE(world.submitImpact(3, Impact{{1.9, 0.0, 0.0}, {1, 0, 0}, 700}));
        }
        if (frame == 10 || frame == 20) { // the largest live object is hit near its centre, then removed
            const ObjectId largest = test::largestObject(world);
            const Aabb b = world.object(largest)->mesh.bounds();
            EXPECT_TRUE(world.submitImpact(largest, Impact{b.hi, {0.577, 0.577, 0.577}, 1500}));
            if (frame == 20)
                world.removeObject(world.objects().front());
        }
        world.beginFrame();
        (void)collectAndCommit(world);
    }
    return events;
}

/// DestructionWorld::geometryHash with each mesh hashed by the former Mesh::hash.
std::uint64_t formerGeometryHash(const DestructionWorld& world) {
    std::uint64_t sum = 0;
    for (ObjectId id : world.objects()) {
        const ObjectState& o = *world.object(id);
        sum += mixSeed(mixSeed(o.id, o.version), detail::formerMeshHash(o.mesh));
    }
    return mixSeed(sum, world.objects().size());
}

std::uint64_t replay(const JournalFile& journal, int workers, const Roughness& roughness = {},
                     std::uint64_t* former = nullptr) {
    DestructionWorld world(goldenConfig(workers));
    EXPECT_TRUE(checkJournalHeader(journal.header, goldenConfig(workers)));
    addScene(world, roughness);
    JournalPlayer player(world);
    for (const JournalEvent& e : journal.events)
        EXPECT_TRUE(player.receive(e));
    EXPECT_TRUE(player.drain());
    if (former)
        *former = formerGeometryHash(world);
    return world.geometryHash();
}

TEST(GoldenHash, FixedJournalOnFixedSceneGivesThePinnedGeometry) {
    JournalFile journal{journalHeaderOf(goldenConfig(1), "golden"), recordGoldenJournal()};
    ASSERT_EQ(journal.events.size(), 7u);
    const std::vector<std::uint8_t> bytes = encodeJournal(journal);
    const std::uint32_t crc = persist::crc32(bytes.data(), bytes.size());
    Result<JournalFile> decoded = decodeJournal(bytes.data(), bytes.size(), "golden");
    ASSERT_TRUE(decoded) << decoded.error().message;
    std::uint64_t former = 0;
    const std::uint64_t one = replay(*decoded, 1, {}, &former);
    const std::uint64_t two = replay(*decoded, 2);
    EXPECT_EQ(one, two);
    std::printf("golden: journal crc 0x%08X, geometry hash 0x%016llX\n", crc,
                static_cast<unsigned long long>(one));
    EXPECT_EQ(crc, kExpectedJournalCrc) << "the journal's encoding or its recorded values changed";
    EXPECT_EQ(one, kExpectedGeometryHash) << "the geometry differs from the pinned one";
    EXPECT_EQ(former, kExpectedFormerGeometryHash) << "the geometry or the former mesh hash changed";
}

// Rough scenes have a pinned geometry of their own, the same on 1 and 2 workers; the flat one above is not
// touched by rough cuts.
TEST(GoldenHash, RoughScenesHaveTheirOwnPinnedGeometry) {
    const Roughness concrete = roughnessPreset("concrete");
    const JournalFile journal{journalHeaderOf(goldenConfig(1), "golden rough"),
                              recordGoldenJournal(concrete)};
    ASSERT_EQ(journal.events.size(), 7u);
    const std::uint64_t one = replay(journal, 1, concrete);
    EXPECT_EQ(one, replay(journal, 2, concrete));
    std::printf("golden rough: geometry hash 0x%016llX\n", static_cast<unsigned long long>(one));
    EXPECT_NE(one, kExpectedGeometryHash);
    EXPECT_EQ(one, kExpectedRoughGeometryHash) << "the rough geometry differs from the pinned one";
}

} // namespace
} // namespace rubble
