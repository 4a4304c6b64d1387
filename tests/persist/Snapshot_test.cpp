// Snapshots: load then save gives the same bytes and geometry, a late joiner converges with snapshot +
// journal tail, damaged or hostile files are refused naming offset and field with the world untouched, and a
// process killed mid-save leaves the previous snapshot intact.
#include "rubble/persist/Snapshot.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <future>
#include <random>

#include "JournalScene.hpp"
#include "TestSupport.hpp"
#include "WorldSteps.hpp"
#include "geometry/MeshTopology.hpp"
#include "persist/Bytes.hpp"
#include "rubble/fracture/Roughness.hpp"
#include "rubble/persist/JournalFile.hpp"
#include "rubble/runtime/JournalPlayer.hpp"

namespace rubble {
namespace {

const DestructionWorld::Config kConfig = test::journalConfig(1).world;

// A world in mid-fire (jobs in flight) and its snapshot with the bodies' placements.
struct MidFire {
    test::JournalRig rig{1};
    Snapshot snapshot;
    MidFire() {
        rig.play(100);
        for (int i = 0; i < 30 && rig.runtime.world().jobsInFlight() == 0; ++i)
            rig.play(1, 1);
        snapshot = takeSnapshot(rig.runtime.world(), rig.runtime.placements());
    }
};

void refix(std::vector<std::uint8_t>& bytes) { // a valid checksum over tampered bytes
    const std::uint32_t crc = persist::crc32(bytes.data(), bytes.size() - 4);
    for (int i = 0; i < 4; ++i)
        bytes[bytes.size() - 4 + i] = static_cast<std::uint8_t>(crc >> (8 * i));
}

TEST(Snapshot, LoadThenSaveGivesIdenticalBytesAndGeometry) {
    MidFire m;
    ASSERT_GT(m.snapshot.world.work.size(), 0u) << "saved with jobs in flight";
    ASSERT_GT(m.snapshot.world.objects.size(), 5u);
    ASSERT_EQ(m.snapshot.placements.size(), m.snapshot.world.objects.size());
    const std::vector<std::uint8_t> bytes = encodeSnapshot(m.snapshot);
    Result<Snapshot> decoded = decodeSnapshot(bytes.data(), bytes.size(), "mid.rsnap");
    ASSERT_TRUE(decoded) << decoded.error().message;
    DestructionWorld world(kConfig);
    const std::vector<ObjectPlacement> placements = decoded->placements;
    ASSERT_TRUE(restoreSnapshot(world, std::move(*decoded)));
    EXPECT_EQ(world.geometryHash(), m.rig.runtime.world().geometryHash());
    EXPECT_EQ(world.journalPosition(), m.rig.runtime.world().journalPosition());
    EXPECT_EQ(encodeSnapshot(takeSnapshot(world, placements)), bytes);
}

// The box of tests/data/snapshot/v4-box-attributes.rsnap: flat normals and texture coordinates that float
// does not hold exactly, one material.
Mesh attributedBox() {
    Mesh box = makeSubdividedBox({-1, -0.5, -0.25}, {1, 0.5, 0.25}, 2);
    box.computeFlatNormals();
    for (std::size_t t = 0; t < box.triangles.size(); ++t)
        for (std::uint32_t v : box.triangles[t]) {
            const Vec3& p = box.positions[v];
            box.uvs.push_back({0.1 * p.x + 0.3, p.y / 3 + 0.7 * p.z});
        }
    box.materials.assign(box.triangles.size(), 1u);
    return box;
}

// Normals and texture coordinates (float) survive a save and a load exactly, pieces' included, and the
// loaded world saves the same bytes.
TEST(Snapshot, KeepsNormalsAndTextureCoordinatesExactly) {
    DestructionWorld world(kConfig);
    ObjectDesc d;
    d.mesh = attributedBox();
    d.fracture.pattern = CellPattern::Shatter;
    d.fracture.cells = 4;
    const ObjectId id = world.addObject(std::move(d)).value();
    ASSERT_TRUE(world.submitImpact(id, Impact{{0.9, 0.4, 0.25}, {0, 0, 1}, 500}));
    for (int frame = 0; frame < 20 && world.objects().size() == 1; ++frame) {
        world.beginFrame();
        world.waitIdle();
        (void)collectAndCommit(world);
    }
    ASSERT_GT(world.objects().size(), 2u);
    const std::vector<std::uint8_t> bytes = encodeSnapshot(takeSnapshot(world));
    Result<Snapshot> decoded = decodeSnapshot(bytes.data(), bytes.size(), "attributes.rsnap");
    ASSERT_TRUE(decoded) << decoded.error().message;
    DestructionWorld loaded(kConfig);
    ASSERT_TRUE(restoreSnapshot(loaded, std::move(*decoded)));
    ASSERT_EQ(loaded.objects(), world.objects());
    for (ObjectId o : world.objects()) {
        const Mesh& a = world.object(o)->mesh;
        const Mesh& b = loaded.object(o)->mesh;
        ASSERT_TRUE(a.hasNormals() && a.hasUvs()) << "object " << o;
        EXPECT_EQ(b.normals, a.normals) << "object " << o;
        EXPECT_EQ(b.uvs, a.uvs) << "object " << o;
        EXPECT_EQ(loaded.object(o)->meshHash, b.hash()) << "object " << o;
    }
    EXPECT_EQ(loaded.geometryHash(), world.geometryHash());
    EXPECT_EQ(encodeSnapshot(takeSnapshot(loaded)), bytes);
}

// A version-4 file (attributes in double, saved by the build before float attributes) still loads: its
// attributes rounded to float, its mesh hash that of the rounded mesh; saving it again writes version 7.
TEST(Snapshot, AVersion4FileLoadsWithItsAttributesRoundedToFloat) {
    const std::filesystem::path v4 = test::sourceDir() / "tests/data/snapshot/v4-box-attributes.rsnap";
    Result<Snapshot> r = loadSnapshot(v4);
    ASSERT_TRUE(r) << r.error().message;
    ASSERT_EQ(r->world.objects.size(), 1u);
    const Mesh want = attributedBox();
    const ObjectState& o = r->world.objects[0];
    EXPECT_EQ(o.mesh.positions, want.positions);
    EXPECT_EQ(o.mesh.normals, want.normals);
    EXPECT_EQ(o.mesh.uvs, want.uvs);
    EXPECT_EQ(o.mesh.materials, want.materials);
    EXPECT_EQ(o.meshHash, want.hash());
    const std::vector<std::uint8_t> again = encodeSnapshot(*r);
    EXPECT_EQ(again[4] | again[5] << 8, 7);
    Result<Snapshot> reloaded = decodeSnapshot(again.data(), again.size(), "again.rsnap");
    ASSERT_TRUE(reloaded) << reloaded.error().message;
    EXPECT_EQ(reloaded->world.objects[0].mesh, o.mesh);
    EXPECT_EQ(encodeSnapshot(*reloaded), again);
}

// An object's shatter layout (from its material) survives a save and a load.
TEST(Snapshot, KeepsTheShatterLayoutOfEveryObject) {
    DestructionWorld world(kConfig);
    ObjectDesc d;
    d.mesh = makeBox({-1, -1, -1}, {1, 1, 1});
    d.density = 2;
    d.material = "glass";
    d.fracture.pattern = CellPattern::Shatter;
    ASSERT_TRUE(world.addObject(std::move(d)));
    ObjectPlacement placement;
    placement.object = world.objects().front();
    const Snapshot s = takeSnapshot(world, {placement});
    const std::vector<std::uint8_t> bytes = encodeSnapshot(s);
    Result<Snapshot> decoded = decodeSnapshot(bytes.data(), bytes.size(), "glass.rsnap");
    ASSERT_TRUE(decoded) << decoded.error().message;
    ASSERT_EQ(decoded->world.objects.size(), 1u);
    EXPECT_EQ(decoded->world.objects[0].fracture.layout, ShatterLayout::Radial);
    EXPECT_EQ(decoded->world.objects[0].fracture.pattern, CellPattern::Shatter);
}

// Version 4 keeps each object's roughness (a rough world loaded, or joined over the network, cuts rough).
TEST(Snapshot, KeepsTheRoughnessOfEveryObject) {
    DestructionWorld world(kConfig);
    ObjectDesc d;
    d.mesh = makeBox({-1, -1, -1}, {1, 1, 1});
    d.fracture.roughness = roughnessPreset("wood");
    d.fracture.roughness.seed = 99;
    d.fracture.roughness.grain = {0, 0, 1};
    d.fracture.roughness.maxTrianglesPerPiece = 700;
    ASSERT_TRUE(world.addObject(std::move(d)));
    ObjectPlacement placement;
    placement.object = world.objects().front();
    const std::vector<std::uint8_t> bytes = encodeSnapshot(takeSnapshot(world, {placement}));
    Result<Snapshot> decoded = decodeSnapshot(bytes.data(), bytes.size(), "rough.rsnap");
    ASSERT_TRUE(decoded) << decoded.error().message;
    const Roughness& r = decoded->world.objects.at(0).fracture.roughness;
    const Roughness wood = roughnessPreset("wood");
    EXPECT_EQ(r.amplitude, wood.amplitude);
    EXPECT_EQ(r.featureSize, wood.featureSize);
    EXPECT_EQ(r.hurst, wood.hurst);
    EXPECT_EQ(r.octaves, wood.octaves);
    EXPECT_EQ(r.relative, wood.relative);
    EXPECT_EQ(r.grainStretch, wood.grainStretch);
    EXPECT_EQ(r.seed, 99u);
    EXPECT_EQ(r.grain, (Vec3{0, 0, 1}));
    EXPECT_EQ(r.maxTrianglesPerPiece, 700);
    // A roughness no fracture accepts is refused, naming the field.
    std::vector<std::uint8_t> bad = bytes;
    const std::size_t size = bad.size();
    DestructionWorld other(kConfig);
    ObjectDesc e;
    e.mesh = makeBox({-1, -1, -1}, {1, 1, 1});
    e.fracture.roughness = wood;
    e.fracture.roughness.hurst = 0.123456789;
    ASSERT_TRUE(other.addObject(std::move(e)));
    placement.object = other.objects().front();
    bad = encodeSnapshot(takeSnapshot(other, {placement}));
    ASSERT_EQ(bad.size(), size);
    const double hurst = 0.123456789;
    std::uint8_t pattern[8];
    std::memcpy(pattern, &hurst, 8);
    const auto at = std::search(bad.begin(), bad.end(), pattern, pattern + 8);
    ASSERT_NE(at, bad.end());
    const double refused = 0;
    std::memcpy(&*at, &refused, 8);
    refix(bad);
    Result<Snapshot> refusedSnapshot = decodeSnapshot(bad.data(), bad.size(), "rough.rsnap");
    ASSERT_FALSE(refusedSnapshot);
    EXPECT_NE(refusedSnapshot.error().message.find("fracture.roughness"), std::string::npos)
        << refusedSnapshot.error().message;
    EXPECT_NE(refusedSnapshot.error().message.find("hurst"), std::string::npos)
        << refusedSnapshot.error().message;
}

TEST(Snapshot, RestoresARuntimeWithTheBodiesOfItsObjects) {
    MidFire m;
    test::JournalRig other(2);
    other.play(30); // a state of its own, replaced by the snapshot's
    auto byObject = [](std::vector<ObjectPlacement> v) {
        std::sort(v.begin(), v.end(), [](const auto& a, const auto& b) { return a.object < b.object; });
        return v;
    };
    // Refused, nothing changed: a placement missing, a placement of a body that is no object or piece.
    const std::uint64_t before = other.runtime.stateHash();
    Snapshot broken = m.snapshot;
    broken.placements.pop_back();
    Status s = restoreSnapshot(other.runtime, broken);
    EXPECT_FALSE(s);
    EXPECT_NE(s.message().find("placements"), std::string::npos) << s.message();
    broken = m.snapshot;
    broken.placements.front().role = BodyRole::Ground;
    EXPECT_FALSE(restoreSnapshot(other.runtime, broken));
    EXPECT_EQ(other.runtime.stateHash(), before);

    ASSERT_TRUE(restoreSnapshot(other.runtime, m.snapshot));
    EXPECT_EQ(other.runtime.world().geometryHash(), m.rig.runtime.world().geometryHash());
    const std::vector<ObjectPlacement> saved = byObject(m.snapshot.placements);
    const std::vector<ObjectPlacement> now = byObject(other.runtime.placements());
    ASSERT_EQ(now.size(), saved.size());
    int frozen = 0, dynamic = 0, pieces = 0;
    for (std::size_t i = 0; i < now.size(); ++i) {
        EXPECT_EQ(now[i].object, saved[i].object);
        EXPECT_EQ(now[i].role, saved[i].role);
        EXPECT_EQ(now[i].motion, saved[i].motion);
        EXPECT_LT(length(now[i].objectToWorld.translation - saved[i].objectToWorld.translation), 1e-9);
        EXPECT_LT(length(now[i].linearVelocity - saved[i].linearVelocity), 1e-9);
        frozen += now[i].motion == BodyMotionState::Frozen;
        dynamic += now[i].motion == BodyMotionState::Dynamic;
        pieces += now[i].role == BodyRole::Piece;
    }
    EXPECT_GT(pieces, 0);
    EXPECT_GT(frozen + dynamic, 0);
    // The restored runtime plays on: new fractures, volume conserved from here.
    const double start = other.runtime.volumes().total();
    const long long fractures = other.runtime.counters().fractures;
    other.play(120);
    other.settle();
    EXPECT_GT(other.runtime.counters().fractures, fractures);
    EXPECT_LT(std::abs(other.runtime.volumes().total() - start) / start, 1e-9);
}

// Version 2 holds the decomposition settings (the loading world adopts them), each object's mesh hash (taken
// as saved, so a load does not hash every mesh again) and the runtime's volume ledger (the ledger continues).
TEST(Snapshot, KeepsDecompositionSettingsMeshHashesAndTheVolumeLedger) {
    MidFire m;
    Snapshot s = takeSnapshot(m.rig.runtime);
    EXPECT_EQ(s.placements.size(), s.world.objects.size());
    const VolumeLedger saved = m.rig.runtime.volumes();
    EXPECT_GT(saved.retired + saved.dust + saved.dropped, 0) << "the rig removed some volume";
    s.world.decomposition.maxParts = 7;
    s.world.decomposition.concavity = 0.125;
    s.world.decomposition.maxPartFaces = 96;
    const std::vector<std::uint8_t> bytes = encodeSnapshot(s);
    Result<Snapshot> decoded = decodeSnapshot(bytes.data(), bytes.size(), "v2.rsnap");
    ASSERT_TRUE(decoded) << decoded.error().message;
    EXPECT_EQ(decoded->volumes.retired, saved.retired);
    EXPECT_EQ(decoded->volumes.dust, saved.dust);
    EXPECT_EQ(decoded->volumes.dropped, saved.dropped);
    for (std::size_t i = 0; i < s.world.objects.size(); ++i)
        EXPECT_EQ(decoded->world.objects[i].meshHash, s.world.objects[i].mesh.hash());
    test::JournalRig other(2);
    other.play(30);
    ASSERT_TRUE(restoreSnapshot(other.runtime, std::move(*decoded)));
    EXPECT_EQ(other.runtime.world().geometryHash(), m.rig.runtime.world().geometryHash());
    const WorldState loaded = captureState(other.runtime.world());
    EXPECT_EQ(loaded.decomposition.maxParts, 7);
    EXPECT_EQ(loaded.decomposition.concavity, 0.125);
    EXPECT_EQ(loaded.decomposition.maxPartFaces, 96u);
    const VolumeLedger now = other.runtime.volumes();
    EXPECT_EQ(now.retired, saved.retired);
    EXPECT_EQ(now.dust, saved.dust);
    EXPECT_EQ(now.dropped, saved.dropped);
    EXPECT_LT(std::abs(now.total() - saved.total()) / saved.total(), 1e-9)
        << "volume conserved across a load";
    Snapshot again = takeSnapshot(other.runtime);
    again.placements = s.placements; // bodies are remade: their placements agree to 1e-9, not bit for bit
    EXPECT_EQ(encodeSnapshot(again), bytes) << "load then save: the same bytes";

    // Refused, the runtime untouched: decomposition settings out of range, a negative ledger entry.
    const std::uint64_t before = other.runtime.stateHash();
    Snapshot broken = s;
    broken.world.decomposition.maxParts = 0;
    Status st = restoreSnapshot(other.runtime, broken);
    EXPECT_FALSE(st);
    EXPECT_NE(st.message().find("settings out of range: world config: decomposition: maxParts 0"),
              std::string::npos)
        << st.message();
    broken = s;
    broken.volumes.dust = -1;
    st = restoreSnapshot(other.runtime, broken);
    EXPECT_FALSE(st);
    EXPECT_NE(st.message().find("volume ledger"), std::string::npos) << st.message();
    EXPECT_EQ(other.runtime.stateHash(), before);
}

// A snapshot saved by the previous format (version 1, tests/data/snapshot/v1-box.rsnap: a box shattered into
// 4 pieces) is refused naming the version and what to do; the world stays as it was.
TEST(Snapshot, AnOlderVersionIsRefusedWithAClearError) {
    const std::filesystem::path v1 = test::sourceDir() / "tests/data/snapshot/v1-box.rsnap";
    Result<Snapshot> r = loadSnapshot(v1);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("v1-box.rsnap: offset 4, field version: version 1 is not supported"),
              std::string::npos)
        << r.error().message;
    EXPECT_NE(r.error().message.find("older build"), std::string::npos) << r.error().message;
    // A hostile file: a zero mesh hash and a negative ledger entry, each named by offset and field.
    MidFire m;
    std::vector<std::uint8_t> b = encodeSnapshot(takeSnapshot(m.rig.runtime));
    const std::size_t firstObject = 4 + 2 + 2 + 8 + 4 + 8 + 4 + 8 + 36 + 8 + 4 + 8 + 4;
    std::fill(b.begin() + static_cast<std::ptrdiff_t>(firstObject + 8),
              b.begin() + static_cast<std::ptrdiff_t>(firstObject + 16), 0);
    refix(b);
    r = decodeSnapshot(b.data(), b.size(), "bad.rsnap");
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("offset " + std::to_string(firstObject + 8) +
                                     ", field objects[0].meshHash: is 0"),
              std::string::npos)
        << r.error().message;
    b = encodeSnapshot(takeSnapshot(m.rig.runtime));
    b[b.size() - 4 - 24 + 7] = 0xBF; // volumes.retired < 0
    refix(b);
    r = decodeSnapshot(b.data(), b.size(), "bad.rsnap");
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("offset " + std::to_string(b.size() - 4 - 24) +
                                     ", field volumes.retired: is negative"),
              std::string::npos)
        << r.error().message;
}

TEST(Snapshot, SnapshotPlusJournalTailConvergesWithTheHost) {
    MidFire m;
    std::vector<JournalEvent> tail;
    m.rig.runtime.setJournalSink([&](const JournalEvent& e) { tail.push_back(e); });
    m.rig.play(120);
    m.rig.settle();
    ASSERT_GT(tail.size(), 3u);
    for (int workers : {1, 2}) {
        DestructionWorld::Config
            c; // another seed and minimum piece volume: the snapshot's settings are adopted
        c.workers = workers;
        c.deterministic = true;
        DestructionWorld late(c);
        ASSERT_TRUE(restoreSnapshot(late, m.snapshot));
        JournalPlayer player(late);
        for (const JournalEvent& e : tail)
            ASSERT_TRUE(player.receive(e));
        ASSERT_TRUE(player.advanceTo(m.rig.runtime.world().frame()));
        EXPECT_EQ(late.geometryHash(), m.rig.runtime.world().geometryHash()) << workers << " workers";
        EXPECT_EQ(late.journalPosition(), m.rig.runtime.world().journalPosition());
    }
}

// The world keeps each object's MeshFacts (not saved) and fractures with them; a loaded world finds them
// again. Hits on pieces of pieces, with a job in flight at the save: the loaded world must continue bit for
// bit as the original (every mesh and mass property in the saved bytes), on 1 and 2 workers.
void expectALoadedWorldContinuesBitForBit(Mesh wallMesh) {
    auto config = [](int workers) {
        DestructionWorld::Config c;
        c.workers = workers;
        c.deterministic = true;
        c.seed = 77;
        return c;
    };
    auto hitLargest = [](DestructionWorld& w) { // the largest live object, near a corner of its bounds
        const ObjectId largest = test::largestObject(w);
        const ObjectState& o = *w.object(largest);
        const Aabb b = o.mesh.bounds();
        EXPECT_TRUE(w.submitImpact(largest, Impact{0.3 * b.lo + 0.7 * b.hi, {0.577, 0.577, 0.577}, 1200}));
    };
    auto frames = [](DestructionWorld& w, int n) {
        for (int i = 0; i < n; ++i) {
            w.beginFrame();
            (void)collectAndCommit(w);
        }
    };
    DestructionWorld host(config(1));
    ObjectDesc wall;
    wall.mesh = std::move(wallMesh);
    wall.fracture.pattern = CellPattern::Shatter;
    wall.fracture.cells = 5;
    ASSERT_TRUE(host.addObject(std::move(wall)));
    ObjectDesc ball;
    ball.mesh = makeSphere({4, 1, 0}, 1.0, 24, 16);
    ASSERT_TRUE(host.addObject(std::move(ball)));
    hitLargest(host);
    frames(host, 4);
    hitLargest(host); // a piece: fractured with the facts its parent's job found
    const std::vector<std::uint8_t> saved = encodeSnapshot(takeSnapshot(host));
    ASSERT_EQ(host.jobsInFlight(), 1);
    auto game = [&](DestructionWorld& w) {
        frames(w, 4);
        hitLargest(w);
        frames(w, 4);
        hitLargest(w);
        frames(w, 4);
    };
    game(host);
    const std::vector<std::uint8_t> end = encodeSnapshot(takeSnapshot(host));
    ASSERT_GE(host.objects().size(), 8u);
    for (int workers : {1, 2}) {
        Result<Snapshot> s = decodeSnapshot(saved.data(), saved.size(), "facts.rsnap");
        ASSERT_TRUE(s) << s.error().message;
        DestructionWorld loaded(config(workers));
        ASSERT_TRUE(restoreSnapshot(loaded, std::move(*s)));
        game(loaded);
        EXPECT_EQ(loaded.geometryHash(), host.geometryHash()) << workers << " workers";
        EXPECT_TRUE(encodeSnapshot(takeSnapshot(loaded)) == end) << workers << " workers";
    }
}

TEST(Snapshot, ALoadedWorldFracturesPiecesOfPiecesBitForBitAsTheOriginal) {
    expectALoadedWorldContinuesBitForBit(makeSubdividedBox({-2, 0, -0.3}, {2, 3, 0.3}, 5));
}

// The same with an object above kTopologyAboveTriangles: its pieces are edited in place with the topology
// that a loaded world builds again.
TEST(Snapshot, ALoadedWorldFracturesALargeMeshInPlaceBitForBitAsTheOriginal) {
    Mesh large = makeSphere({0, 1.5, 0}, 1.5, 250, 121); // 60k: its remainders stay above the threshold
    ASSERT_GT(large.triangles.size(), kTopologyAboveTriangles);
    ASSERT_FALSE(analyzeMesh(large)->topology.empty());
    expectALoadedWorldContinuesBitForBit(std::move(large));
}

TEST(Snapshot, DamagedFilesAreRefusedNamingOffsetAndFieldAndTheWorldStaysAsItWas) {
    MidFire m;
    const std::vector<std::uint8_t> bytes = encodeSnapshot(m.snapshot);
    DestructionWorld world(kConfig);
    ASSERT_TRUE(restoreSnapshot(world, m.snapshot));
    const std::uint64_t before = world.geometryHash();
    auto refused = [&](const std::vector<std::uint8_t>& b, const std::string& expect) {
        Result<Snapshot> r = decodeSnapshot(b.data(), b.size(), "bad.rsnap");
        EXPECT_FALSE(r) << expect;
        if (r)
            return;
        EXPECT_NE(r.error().message.find("bad.rsnap: offset "), std::string::npos) << r.error().message;
        EXPECT_NE(r.error().message.find(expect), std::string::npos) << r.error().message;
    };
    // Truncated anywhere.
    std::mt19937 rng(7);
    for (int i = 0; i < 40; ++i) {
        const std::size_t n = std::uniform_int_distribution<std::size_t>(0, bytes.size() - 1)(rng);
        refused(std::vector<std::uint8_t>(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(n)),
                "field ");
    }
    // A flipped bit: the checksum.
    std::vector<std::uint8_t> b = bytes;
    b[bytes.size() / 2] ^= 4;
    refused(b, "field crc32: checksum mismatch");
    // Another version, another format.
    b = bytes;
    b[4] = 8;
    refused(b, "offset 4, field version: version 8 is not supported");
    b = bytes;
    b[0] = 'X';
    refused(b, "offset 0, field magic");
    // Hostile but checksummed: a huge count, an out-of-range vertex index, a NaN.
    b = bytes;
    const std::size_t objectsCount =
        4 + 2 + 2 + 8 + 4 + 8 + 4 + 8 + 36 + 8 + 4 + 8; // header, settings, decomposition, frame, ids
    b[objectsCount + 3] = 0x7F;
    refix(b);
    refused(b, "offset " + std::to_string(objectsCount) + ", field objects.count: count");
    const std::size_t firstObject = objectsCount + 4;
    const std::size_t roughness = 3 * 8 + 4 + 1 + 8 + 8 + 24 + 4;
    const std::size_t meshAt = firstObject + 4 + 4 + 8 + 1 + 8 + 8 + 8 + 1 + 4 + 4 + 40 + 1 + 8 + 8 + 1 +
                               roughness + 8 + 24 + 72 + 24 + 72; // positions.count
    const std::uint32_t nPos = m.snapshot.world.objects[0].mesh.positions.size();
    const Mesh& mesh0 = m.snapshot.world.objects[0].mesh;
    const bool corners = mesh0.hasNormals() || mesh0.hasUvs(); // a corner table (version 6) before triangles
    const std::size_t attributesAt = meshAt + 4 + 24 * nPos + 4;
    const std::size_t firstIndex = attributesAt + 1 + (corners ? 4 : 0);
    b = bytes;
    b[firstIndex + 2] = 0x10;
    refix(b);
    refused(b, "offset " + std::to_string(firstIndex) + ", field objects[0].mesh." +
                   (corners ? "corners.vertex" : "triangles") + ": vertex index");
    b = bytes;
    b[attributesAt] = 4;
    refix(b);
    refused(b, "offset " + std::to_string(attributesAt) + ", field objects[0].mesh.attributes: is 4");
    b = bytes;
    for (int k = 0; k < 8; ++k)
        b[meshAt + 4 + k] = 0xFF; // positions[0].x = NaN
    refix(b);
    refused(b, "offset " + std::to_string(meshAt + 4) + ", field objects[0].mesh.positions.x: is not finite");
    // Inconsistent states: refused, the world untouched.
    Snapshot broken = m.snapshot;
    broken.world.delayFrames = -1;
    Status s = restoreSnapshot(world, broken);
    EXPECT_FALSE(s);
    EXPECT_NE(s.message().find("settings out of range: world config: delayFrames -1"), std::string::npos)
        << s.message();
    broken = m.snapshot;
    broken.world.work.push_back({12345, 0, true, 0, {Impact{}}, {0}});
    s = restoreSnapshot(world, broken);
    EXPECT_FALSE(s);
    EXPECT_NE(s.message().find("work on object 12345"), std::string::npos) << s.message();
    EXPECT_EQ(world.geometryHash(), before);
    EXPECT_EQ(encodeSnapshot(takeSnapshot(world, m.snapshot.placements)), bytes);
}

TEST(Snapshot, AProcessKilledMidSaveLeavesThePreviousSnapshot) {
    std::vector<std::uint8_t> a, b;
    {
        MidFire m;
        a = encodeSnapshot(m.snapshot);
        m.rig.play(60);
        b = encodeSnapshot(takeSnapshot(m.rig.runtime.world(), m.rig.runtime.placements()));
    } // the worlds' threads are gone before fork()
    ASSERT_NE(a, b);
    ASSERT_GT(a.size(), 100000u) << "large enough that a kill lands inside a write";
    const std::filesystem::path dir = test::tempDir("snapshot-kill");
    const std::filesystem::path path = dir / "world.rsnap";
    ASSERT_TRUE(writeFileAtomic(path, a));
    std::mt19937 rng(20261125);
    int sawA = 0, sawB = 0;
    for (int round = 0; round < 25; ++round) {
        const pid_t child = fork();
        ASSERT_GE(child, 0);
        if (child == 0) { // saves B and A in turn until killed
            for (int i = 0;; ++i)
                if (!writeFileAtomic(path, i % 2 ? a : b))
                    _exit(3);
        }
        usleep(std::uniform_int_distribution<unsigned>(200, 20000)(rng));
        kill(child, SIGKILL);
        int status = 0;
        ASSERT_EQ(waitpid(child, &status, 0), child);
        ASSERT_TRUE(WIFSIGNALED(status)) << "the child was killed, not finished (" << status << ")";
        Result<std::vector<std::uint8_t>> now = readFileBinary(path);
        ASSERT_TRUE(now);
        ASSERT_TRUE(*now == a || *now == b)
            << "round " << round << ": " << now->size() << " bytes, neither snapshot";
        (*now == a ? sawA : sawB)++;
        Result<Snapshot> loaded = loadSnapshot(path);
        EXPECT_TRUE(loaded) << loaded.error().message;
    }
    EXPECT_GT(sawA + sawB, 0);
    std::size_t leftovers = 0;
    for (const auto& entry : std::filesystem::directory_iterator(dir))
        leftovers += entry.path().filename().string().find(".tmp.") != std::string::npos;
    std::printf("kill test: %d times the first, %d times the second snapshot, %zu temporary files left\n",
                sawA, sawB, leftovers);
}

// Round 3, defect 4: /dev/zero as a snapshot or journal (the demo's F9 and --replay) read until memory ran
// out, and a FIFO blocked forever; both are refused without reading or blocking, as the mesh readers do.
TEST(Snapshot, DevicesAndFifosAreRefusedWithoutBlocking) {
    const std::filesystem::path dir = test::tempDir("snapshot_special");
    const std::filesystem::path fifo = dir / "quicksave.rsnap";
    const std::filesystem::path zero = dir / "zero.rsnap";
    std::filesystem::remove(fifo);
    std::filesystem::remove(zero);
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    std::filesystem::create_symlink("/dev/zero", zero);
    // Each reader runs on its own thread; one blocked on the FIFO past the deadline is released by a writer.
    auto refused = [&](const std::filesystem::path& path, auto read) {
        auto result = std::async(std::launch::async, read);
        if (result.wait_for(std::chrono::seconds(60)) == std::future_status::timeout) {
            const int fd = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
            if (fd >= 0)
                ::close(fd);
            ADD_FAILURE() << path << ": the reader blocked";
            return std::string();
        }
        return result.get();
    };
    for (const auto& [path, kind] :
         {std::pair{fifo, std::string("it is a FIFO, not a regular file")},
          std::pair{zero, std::string("it is a character device, not a regular file")}}) {
        const std::string expected = path.string() + ": cannot read: " + kind;
        EXPECT_EQ(refused(path,
                          [p = path] {
                              auto r = loadSnapshot(p);
                              return r ? std::string("loaded") : r.error().message;
                          }),
                  expected);
        EXPECT_EQ(refused(path,
                          [p = path] {
                              auto r = readJournal(p);
                              return r ? std::string("read") : r.error().message;
                          }),
                  expected);
        EXPECT_EQ(refused(path,
                          [p = path] {
                              auto r = readFileBinary(p);
                              return r ? std::string("read") : r.error().message;
                          }),
                  expected);
    }
}

} // namespace
} // namespace rubble
