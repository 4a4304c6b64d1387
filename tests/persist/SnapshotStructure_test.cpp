// Snapshots of a structure (issue #17, deliverable 3): a restored runtime has the same bonds (pairs, health,
// broken), continues as the original under the same hits, keeps which object each piece was cut from (welds
// within an object, bearings between objects), saves the same bytes again; a version 2 file loads with fresh
// bonds, and damaged structure records are refused naming offset and field, the runtime untouched.
#include <gtest/gtest.h>

#include <algorithm>

#include <set>
#include <tuple>

#include "StructureRig.hpp"
#include "TestSupport.hpp"
#include "persist/Bytes.hpp"
#include "rubble/persist/JournalFile.hpp"
#include "rubble/persist/Snapshot.hpp"
#include "rubble/structure/Material.hpp"

namespace rubble {
namespace {

void refix(std::vector<std::uint8_t>& bytes) { // a valid checksum over tampered bytes
    const std::uint32_t crc = persist::crc32(bytes.data(), bytes.size() - 4);
    for (int i = 0; i < 4; ++i)
        bytes[bytes.size() - 4 + i] = static_cast<std::uint8_t>(crc >> (8 * i));
}

// Offset of the structure section: before the volume ledger (3 doubles) and the checksum.
std::size_t structureAt(const std::vector<std::uint8_t>& bytes, const StructureState& s) {
    return bytes.size() - 4 - 24 - (1 + 4 + 10 * s.nodes.size() + 4 + 25 * s.bonds.size());
}

// A slab on three columns (bearings). Two hits break the first column's bond to the slab (which then rests
// on the other two) and one weakens the third's to 0.7.
struct Colonnade {
    test::StructureRig rig{true, 1, false, 0.6};
    ObjectId columns[3]{};
    ObjectId slab = 0;
    Colonnade() {
        for (int i = 0; i < 3; ++i)
            columns[i] = rig.addBox({4.0 * i - 0.2, 0, -0.2}, {4.0 * i + 0.2, 3, 0.2});
        slab = rig.addBox({-0.2, 3, -0.75}, {8.2, 3.2, 0.75}, "concrete");
        steps(rig, 40);
        hit(rig, columns[0], 6000);
        steps(rig, 2);
        hit(rig, columns[0], 6000);
        hit(rig, columns[2], 3000);
        steps(rig, 40);
    }
    // A hit on a column's top (the slab's bearing; damage only: the columns are indestructible).
    static void hit(test::StructureRig& r, ObjectId column, double impulse) {
        const BodyRecord* b = r.runtime.bodyOf(column);
        ASSERT_NE(b, nullptr);
        const Vec3 top = r.runtime.motion(b->id).transform.translation + Vec3{0, 1.5, 0};
        (void)r.runtime.submitImpact(b->id, top, {0, 1, 0}, impulse);
    }
    static void steps(test::StructureRig& r, int n) {
        for (int i = 0; i < n; ++i)
            r.runtime.stepFrame();
    }
};

// The objects whose bodies are no longer static, ascending.
std::set<ObjectId> fallen(const DestructionRuntime& runtime) {
    std::set<ObjectId> out;
    for (BodyId id : runtime.bodies())
        if (const BodyRecord* r = runtime.body(id); r->hasObject && r->motion != BodyMotionState::Static)
            out.insert(r->object);
    return out;
}

// Equal records, field by field (fields: a record's fields as a tuple).
template <class T, class Fields>
void expectSame(const std::vector<T>& x, const std::vector<T>& y, Fields fields) {
    ASSERT_EQ(x.size(), y.size());
    for (std::size_t i = 0; i < x.size(); ++i)
        EXPECT_TRUE(fields(x[i]) == fields(y[i])) << "record " << i;
}

void expectSameBonds(const StructureState& x, const StructureState& y) {
    expectSame(x.bonds, y.bonds, [](const StructureBondState& b) {
        return std::tuple{b.a, b.b, b.health, b.broken};
    });
}

void expectSameNodes(const StructureState& x, const StructureState& y) {
    expectSame(x.nodes, y.nodes, [](const StructureNodeState& n) {
        return std::tuple{n.object, n.solid, n.material, n.root, n.anchor, n.pending};
    });
}

Snapshot decoded(const std::vector<std::uint8_t>& bytes) {
    Result<Snapshot> s = decodeSnapshot(bytes.data(), bytes.size(), "structure.rsnap");
    EXPECT_TRUE(s) << s.error().message;
    return s ? *s : Snapshot{};
}

} // namespace

// (a) Damaged and broken bonds survive a save and a load into a fresh runtime; (b) the original and the
// restored runtime, hit alike, break the same bonds and drop the same bodies frame by frame.
TEST(SnapshotStructure, ARestoredStructureHasTheSameBondsAndContinuesAsTheOriginal) {
    Colonnade original;
    const StructureState before = captureStructure(original.rig.runtime);
    ASSERT_TRUE(before.saved);
    ASSERT_EQ(before.nodes.size(), 4u);
    int damaged = 0, broken = 0;
    for (const StructureBondState& b : before.bonds) {
        damaged += !b.broken && b.health < 1;
        broken += b.broken;
    }
    ASSERT_EQ(broken, 1) << "the first column's bearing";
    ASSERT_EQ(damaged, 1) << "the third column's bearing";
    EXPECT_TRUE(fallen(original.rig.runtime).empty()) << "the slab rests on two columns";
    const std::vector<std::uint8_t> bytes = encodeSnapshot(takeSnapshot(original.rig.runtime));

    test::StructureRig restored{true, 1, false, 0.6};
    ASSERT_TRUE(restoreSnapshot(restored.runtime, decoded(bytes)));
    expectSameBonds(captureStructure(restored.runtime), before);
    expectSameNodes(captureStructure(restored.runtime), before);

    // The same hits on both: the third column's bearing weakens to 0.3, the middle one's breaks at the second
    // hit, and the slab, left on the third column only, tips off it.
    const long long brokenBefore[2] = {original.rig.runtime.counters().bondsBroken,
                                       restored.runtime.counters().bondsBroken};
    test::StructureRig* rigs[2] = {&original.rig, &restored};
    for (int frame = 0; frame < 120; ++frame) {
        for (test::StructureRig* r : rigs) {
            if (frame == 0)
                Colonnade::hit(*r, original.columns[2], 4000);
            if (frame == 10 || frame == 20)
                Colonnade::hit(*r, original.columns[1], 6000);
            r->runtime.stepFrame();
        }
        ASSERT_EQ(fallen(original.rig.runtime), fallen(restored.runtime)) << "frame " << frame;
        ASSERT_EQ(original.rig.runtime.counters().bondsBroken - brokenBefore[0],
                  restored.runtime.counters().bondsBroken - brokenBefore[1])
            << "frame " << frame;
    }
    EXPECT_EQ(fallen(restored.runtime).count(original.slab), 1u) << "it tipped off the third column";
    EXPECT_GE(restored.runtime.counters().bondsBroken - brokenBefore[1], 1) << "the middle column's bearing";
    expectSameBonds(captureStructure(restored.runtime), captureStructure(original.rig.runtime));
}

// (d) Load then save gives the same bytes, structure section included.
TEST(SnapshotStructure, LoadThenSaveGivesIdenticalBytes) {
    Colonnade original;
    Snapshot s = takeSnapshot(original.rig.runtime);
    ASSERT_GT(s.structure.bonds.size(), 3u);
    const std::vector<std::uint8_t> bytes = encodeSnapshot(s);
    EXPECT_EQ(encodeSnapshot(decoded(bytes)), bytes);
    test::StructureRig restored{true, 1, false, 0.6};
    ASSERT_TRUE(restoreSnapshot(restored.runtime, decoded(bytes)));
    Snapshot again = takeSnapshot(restored.runtime);
    again.placements = s.placements; // bodies are remade: their placements agree to 1e-9, not bit for bit
    EXPECT_EQ(encodeSnapshot(again), bytes);
}

// (c) A steel beam on two columns (bearings) loses a chip from its underside, which stays bonded across its
// cut faces (bondDebris): a weld, since both pieces were cut from the beam, so the chip hangs. Restored, the
// pieces keep their solid and the chip still hangs; restored without the structure (a version 2 file), the
// two pieces count as different objects, the chip's joint becomes a bearing that cannot pull, and it drops.
TEST(SnapshotStructure, ARestoredWeldStaysAWeldAndABearingABearing) {
    test::StructureRig rig{true, 1, true, 0.6};
    rig.addBox({-0.2, 0, -0.2}, {0.2, 3, 0.2});
    rig.addBox({5.8, 0, -0.2}, {6.2, 3, 0.2});
    FractureParams chip;
    chip.seedPoints = 0;
    chip.sizeLaw.base = chip.sizeLaw.minSize = chip.sizeLaw.maxSize = 0.3;
    chip.sizeLaw.scale = 0;
    const ObjectId beam = rig.addBox({-0.2, 3, -0.5}, {6.2, 3.4, 0.5}, "steel", true, chip);
    rig.runtime.stepFrame();
    ASSERT_TRUE(rig.runtime.submitLocalImpact(beam, Impact{{0, -0.2, 0}, {0, -1, 0}, 100}));
    for (int i = 0; i < 60; ++i)
        rig.runtime.stepFrame();
    ASSERT_EQ(rig.runtime.counters().fractures, 1);
    ASSERT_EQ(rig.runtime.livePieces(), 2);
    EXPECT_TRUE(fallen(rig.runtime).empty()) << "the chip hangs from the beam";
    const Snapshot saved = takeSnapshot(rig.runtime);
    int pieces = 0;
    for (const StructureNodeState& n : saved.structure.nodes)
        if (rig.runtime.bodyOf(n.object)->role == BodyRole::Piece) {
            EXPECT_EQ(n.solid, beam);
            EXPECT_EQ(materialPresets()[n.material].name, "steel");
            ++pieces;
        }
    EXPECT_EQ(pieces, 2);

    test::StructureRig restored{true, 1, true, 0.6};
    ASSERT_TRUE(restoreSnapshot(restored.runtime, saved));
    expectSameNodes(captureStructure(restored.runtime), saved.structure);
    for (int i = 0; i < 60; ++i)
        restored.runtime.stepFrame();
    EXPECT_TRUE(fallen(restored.runtime).empty()) << "still a weld";
    expectSameBonds(captureStructure(restored.runtime), saved.structure);

    Snapshot forgotten = saved;
    forgotten.structure = {};
    test::StructureRig v2{true, 1, true, 0.6};
    ASSERT_TRUE(restoreSnapshot(v2.runtime, forgotten));
    for (int i = 0; i < 60; ++i)
        v2.runtime.stepFrame();
    EXPECT_EQ(fallen(v2.runtime).size(), 1u) << "a bearing does not hold the chip up";
}

// A version 2 file loads, every bond fresh: tests/data/snapshot/v2-structure.rsnap, the colonnade's snapshot
// without its structure section and roughness records, saved by the build before version 6.
TEST(SnapshotStructure, AVersion2SnapshotLoadsWithFreshBonds) {
    Colonnade original;
    const Snapshot s = takeSnapshot(original.rig.runtime);
    Result<std::vector<std::uint8_t>> bytes =
        readFileBinary(test::sourceDir() / "tests/data/snapshot/v2-structure.rsnap");
    ASSERT_TRUE(bytes) << bytes.error().message;
    ASSERT_EQ((*bytes)[4], 2);
    Snapshot old = decoded(*bytes);
    EXPECT_FALSE(old.structure.saved);
    test::StructureRig restored{true, 1, false, 0.6};
    ASSERT_TRUE(restoreSnapshot(restored.runtime, std::move(old)));
    const StructureState now = captureStructure(restored.runtime);
    ASSERT_EQ(now.bonds.size(), s.structure.bonds.size()) << "the same pairs, from geometry";
    for (std::size_t i = 0; i < now.bonds.size(); ++i) {
        EXPECT_EQ(now.bonds[i].a, s.structure.bonds[i].a);
        EXPECT_EQ(now.bonds[i].b, s.structure.bonds[i].b);
        EXPECT_EQ(now.bonds[i].health, 1.0);
        EXPECT_FALSE(now.bonds[i].broken);
    }
}

// Damaged structure records are refused naming offset and field; records the runtime cannot place are
// refused by the restore; either way the runtime stays as it was.
TEST(SnapshotStructure, DamagedStructureRecordsAreRefusedAndTheRuntimeStaysAsItWas) {
    Colonnade original;
    const Snapshot s = takeSnapshot(original.rig.runtime);
    const std::vector<std::uint8_t> bytes = encodeSnapshot(s);
    const std::size_t nodes = structureAt(bytes, s.structure) + 5;
    const std::size_t bonds = nodes + 10 * s.structure.nodes.size() + 4;
    auto refused = [&](std::vector<std::uint8_t> b, std::size_t offset, const std::string& what) {
        refix(b);
        Result<Snapshot> r = decodeSnapshot(b.data(), b.size(), "bad.rsnap");
        ASSERT_FALSE(r) << what;
        EXPECT_NE(r.error().message.find("bad.rsnap: offset " + std::to_string(offset) + ", field " + what),
                  std::string::npos)
            << r.error().message;
    };
    auto edit = [&](std::size_t at, std::initializer_list<std::uint8_t> v) {
        std::vector<std::uint8_t> b = bytes;
        std::copy(v.begin(), v.end(), b.begin() + static_cast<std::ptrdiff_t>(at));
        return b;
    };
    refused(edit(bonds + 16 + 6, {0xF8, 0x7F}), bonds + 16, "structure.bonds[0].health: is not finite");
    refused(edit(bonds + 16 + 6, {0xF8, 0x3F}), bonds + 16, "structure.bonds[0].health: is 1.5");
    refused(edit(bonds, {0x39, 0x30, 0, 0}), bonds, "structure.bonds[0].a: 12345 is neither a node");
    refused(edit(bonds - 4, {0xFF, 0xFF, 0xFF, 0x7F}), bonds - 4, "structure.bonds.count: count");
    refused(edit(nodes + 9, {2}), nodes + 9, "structure.nodes[0].flags: is 2");
    refused(edit(nodes + 8, {6}), nodes + 8, "structure.nodes[0].material: unknown material 6");
    refused(edit(nodes - 5, {0}), nodes - 4, "structure.nodes.count: is 4, expected 0 (not saved)");
    // A truncated section with a valid checksum: the parse runs out or misreads, naming where.
    std::vector<std::uint8_t> cut = bytes;
    cut.erase(cut.begin() + static_cast<std::ptrdiff_t>(bonds),
              cut.begin() + static_cast<std::ptrdiff_t>(bonds + 25));
    refix(cut);
    Result<Snapshot> r = decodeSnapshot(cut.data(), cut.size(), "cut.rsnap");
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("cut.rsnap: offset "), std::string::npos) << r.error().message;

    // Decoded, but naming a ground body this runtime lacks or an object that is not a node.
    test::StructureRig other{true, 1, false, 0.6};
    other.addBox({20, 0, 20}, {21, 1, 21});
    other.runtime.stepFrame();
    const std::uint64_t hash = other.runtime.stateHash();
    const std::size_t bondCount = captureStructure(other.runtime).bonds.size();
    Snapshot bad = s;
    bad.structure.bonds.back().b = kSceneryNodeKey | 99;
    Status st = restoreSnapshot(other.runtime, bad);
    ASSERT_FALSE(st);
    EXPECT_NE(st.message().find("names no ground or scenery body"), std::string::npos) << st.message();
    bad = s;
    bad.structure.nodes.pop_back();
    st = restoreSnapshot(other.runtime, bad);
    ASSERT_FALSE(st);
    EXPECT_NE(st.message().find("names no structure node"), std::string::npos) << st.message();
    EXPECT_EQ(other.runtime.stateHash(), hash);
    EXPECT_EQ(captureStructure(other.runtime).bonds.size(), bondCount);
}

} // namespace rubble
