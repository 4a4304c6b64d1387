// Fuzz target: the snapshot and journal readers. Mode 0 reads the input as a file; mode 1 takes a valid
// snapshot of a small world (a broken box with work in flight), overwrites fuzzer-chosen bytes and fixes the
// checksum, so that the parser behind the checksum is reached. Reading must never crash; an accepted snapshot
// must encode to the same bytes and load into a world or be refused without changing it.
#include <cstdint>
#include <cstdio>
#include <functional>
#include <vector>

#include "FuzzInput.hpp"
#include "persist/Bytes.hpp"
#include "rubble/core/JobSystem.hpp"
#include "rubble/persist/JournalFile.hpp"
#include "rubble/persist/Snapshot.hpp"

namespace {

using namespace rubble;

[[noreturn]] void fail(const char* what) {
    std::fprintf(stderr, "SnapshotFuzz: %s\n", what);
    __builtin_trap();
}

DestructionWorld::Config config() {
    DestructionWorld::Config c;
    c.workers = 1;
    c.deterministic = true;
    return c;
}

/// Keeps submitted jobs without running them. A restored snapshot relaunches its jobs in flight, and fuzzed
/// fracture settings can make one take seconds (24 s under ASan for a 12-byte input); the fracture target
/// covers fractures, this one the reader and the restore.
class HeldJobs final : public JobSystem {
public:
    void submit(std::function<void()> job) override { jobs_.push_back(std::move(job)); }
    int workerCount() const override { return 1; }

private:
    std::vector<std::function<void()>> jobs_;
};

const std::vector<std::uint8_t>& validSnapshot() {
    static const std::vector<std::uint8_t> bytes = [] {
        DestructionWorld world(config());
        ObjectDesc d;
        d.mesh = makeBox({-1, -1, -1}, {1, 1, 1});
        d.fracture.pattern = CellPattern::Shatter;
        d.fracture.cells = 3;
        const ObjectId id = *world.addObject(d);
        (void)world.submitImpact(id, Impact{{1, 0, 0}, {1, 0, 0}, 100});
        for (int i = 0; i < 3; ++i) {
            world.beginFrame();
            for (const FractureOutcome& split : world.collect())
                world.commit(split);
        }
        (void)world.submitImpact(world.objects().back(), Impact{{0, 1, 0}, {0, 1, 0}, 100});
        // Static placements and a structure over the pieces: damaged, broken and ground bonds.
        std::vector<ObjectPlacement> placements;
        Snapshot s = takeSnapshot(world);
        s.structure.saved = true;
        for (ObjectId piece : world.objects()) {
            ObjectPlacement p;
            p.object = piece;
            p.role = BodyRole::Piece;
            placements.push_back(p);
            s.structure.nodes.push_back({piece, id, 3, piece == world.objects().front(), false, false});
        }
        s.placements = placements;
        for (std::size_t i = 0; i + 1 < placements.size(); ++i)
            s.structure.bonds.push_back({placements[i].object, placements[i + 1].object, 0.5, i == 0});
        s.structure.bonds.push_back({placements.back().object, kSceneryNodeKey | 1, 1, false});
        return encodeSnapshot(s);
    }();
    return bytes;
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    fuzz::FuzzInput in(data, size);
    std::vector<std::uint8_t> bytes;
    if (in.byte() % 2 == 0) {
        bytes.assign(data + (size > 0 ? 1 : 0), data + size);
        (void)decodeJournal(bytes.data(), bytes.size(), "fuzz");
        if (bytes.size() >= kJournalEventBytes)
            (void)decodeJournalEvent(bytes.data());
    } else {
        bytes = validSnapshot();
        const int edits = 1 + in.byte() % 8;
        for (int i = 0; i < edits; ++i) {
            const std::size_t at = static_cast<std::size_t>(in.u64() % bytes.size());
            bytes[at] = in.byte();
        }
        if (in.byte() % 4 == 0) // truncated
            bytes.resize(static_cast<std::size_t>(in.u64() % bytes.size()) + 4);
        const std::uint32_t crc = persist::crc32(bytes.data(), bytes.size() - 4);
        for (int i = 0; i < 4; ++i)
            bytes[bytes.size() - 4 + i] = static_cast<std::uint8_t>(crc >> (8 * i));
    }
    Result<Snapshot> s = decodeSnapshot(bytes.data(), bytes.size(), "fuzz");
    if (!s)
        return 0;
    const std::vector<std::uint8_t> again = encodeSnapshot(*s);
    const bool current = bytes[4] == again[4] && bytes[5] == again[5];
    if (current && again != bytes)
        fail("an accepted snapshot does not encode to its own bytes");
    if (!current) { // an older version saved again in the current one, which reads back to the same bytes
        Result<Snapshot> reread = decodeSnapshot(again.data(), again.size(), "fuzz");
        if (!reread || encodeSnapshot(*reread) != again)
            fail("an accepted older snapshot does not encode to a current snapshot of itself");
    }
    HeldJobs jobs; // outlives the world
    DestructionWorld::Config c = config();
    c.jobs = &jobs;
    DestructionWorld world(c);
    const std::uint64_t before = world.geometryHash();
    if (!restoreSnapshot(world, std::move(*s)) && world.geometryHash() != before)
        fail("a refused snapshot changed the world");
    return 0;
}
