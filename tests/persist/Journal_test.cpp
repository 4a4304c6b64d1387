// The destruction journal: 48-byte events, recorded for every accepted impact and removal, replayed on a
// fresh world from the same scene to the same geometry on 1 or 2 workers; the journal file and its errors.
#include "rubble/persist/JournalFile.hpp"

#include <gtest/gtest.h>

#include <fstream>

#include "JournalScene.hpp"
#include "TestSupport.hpp"
#include "persist/Bytes.hpp"
#include "rubble/runtime/JournalPlayer.hpp"

namespace rubble {
namespace {

struct Recording {
    std::vector<JournalEvent> events;
    std::uint64_t frame = 0;
    std::uint64_t geometry = 0;
    std::uint64_t journalPosition = 0;
    long long fractures = 0;
};

Recording record(int workers, int frames) {
    test::JournalRig rig(workers);
    Recording r;
    rig.runtime.setJournalSink([&](const JournalEvent& e) { r.events.push_back(e); });
    rig.play(frames);
    rig.settle();
    r.frame = rig.runtime.world().frame();
    r.geometry = rig.runtime.world().geometryHash();
    r.journalPosition = rig.runtime.world().journalPosition();
    r.fractures = rig.runtime.counters().fractures;
    return r;
}

std::uint64_t replay(const std::vector<JournalEvent>& events, std::uint64_t frame, int workers) {
    auto world = test::journalWorld(workers);
    JournalPlayer player(*world);
    for (const JournalEvent& e : events)
        EXPECT_TRUE(player.receive(e));
    EXPECT_TRUE(player.advanceTo(frame));
    EXPECT_EQ(player.pending(), 0u);
    EXPECT_EQ(world->jobsInFlight(), 0);
    EXPECT_EQ(world->journalPosition(), events.size()) << "the replaying world journals the same events";
    return world->geometryHash();
}

TEST(Journal, EventIs48BytesAndRoundTrips) {
    JournalEvent e;
    e.kind = JournalEventKind::Impact;
    e.object = 0xDEADBEEF;
    e.tick = 123456;
    e.point = {1.5f, -2.25f, 1e-7f};
    e.normal = {0.f, 1.f, 0.f};
    e.impulse = 2500.f;
    e.pattern = 1;
    e.cells = 300;
    e.seed = 0x0123456789ABCDEFull;
    const auto bytes = encodeJournalEvent(e);
    static_assert(std::tuple_size_v<decltype(bytes)> == 48);
    EXPECT_EQ(bytes[0], 1);
    EXPECT_EQ(bytes[4], 0xEF) << "little-endian object id at offset 4";
    EXPECT_EQ(bytes[40], 0xEF) << "seed at offset 40";
    Result<JournalEvent> back = decodeJournalEvent(bytes.data());
    ASSERT_TRUE(back) << back.error().message;
    EXPECT_EQ(*back, e);
}

TEST(Journal, Crc32IsTheStandardOne) {
    const std::string check = "123456789"; // the CRC-32 (IEEE) check value, as zlib computes it
    EXPECT_EQ(persist::crc32(reinterpret_cast<const std::uint8_t*>(check.data()), check.size()), 0xCBF43926u);
    std::vector<std::uint8_t> bytes(1000);
    for (std::size_t i = 0; i < bytes.size(); ++i)
        bytes[i] = static_cast<std::uint8_t>(i * 7 + 3);
    auto oneByteAtATime = [&](std::size_t n) { // the reference for the eight-at-a-time version
        std::uint32_t c = 0xFFFFFFFFu;
        for (std::size_t i = 0; i < n; ++i) {
            c ^= bytes[i];
            for (int k = 0; k < 8; ++k)
                c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
        }
        return c ^ 0xFFFFFFFFu;
    };
    for (std::size_t n : {0, 1, 7, 8, 13, 1000})
        EXPECT_EQ(persist::crc32(bytes.data(), n), oneByteAtATime(n)) << n << " bytes";
}

TEST(Journal, DecodingRefusesUnknownKindsAndNonFiniteNumbers) {
    JournalEvent e;
    auto bytes = encodeJournalEvent(e);
    bytes[0] = 7;
    Result<JournalEvent> bad = decodeJournalEvent(bytes.data(), 96);
    ASSERT_FALSE(bad);
    EXPECT_NE(bad.error().message.find("offset 96, field kind"), std::string::npos) << bad.error().message;
    e.impulse = std::numeric_limits<float>::quiet_NaN();
    bytes = encodeJournalEvent(e);
    bad = decodeJournalEvent(bytes.data());
    ASSERT_FALSE(bad);
    EXPECT_NE(bad.error().message.find("offset 36, field impulse"), std::string::npos) << bad.error().message;
}

// The pattern byte holds the CellPattern (low four bits) and the ShatterLayout (high four bits); a byte
// naming neither a known pattern nor a known layout is refused at its offset.
TEST(Journal, ThePatternByteCarriesTheLayout) {
    FractureParams f;
    f.pattern = CellPattern::Shatter;
    f.layout = ShatterLayout::Splinter;
    JournalEvent e;
    e.pattern = patternByte(f);
    EXPECT_EQ(e.pattern, 0x21);
    auto bytes = encodeJournalEvent(e);
    Result<JournalEvent> back = decodeJournalEvent(bytes.data());
    ASSERT_TRUE(back) << back.error().message;
    EXPECT_EQ(back->pattern, 0x21);
    f.pattern = CellPattern::Adaptive;
    f.layout = ShatterLayout::Radial;
    EXPECT_EQ(patternByte(f), 0x12);
    bytes[1] = patternByte(f);
    EXPECT_TRUE(decodeJournalEvent(bytes.data(), 48)) << "the adaptive pattern is a known one";
    for (std::uint8_t bad : {0x03, 0x41, 0xF0}) {
        bytes[1] = bad;
        Result<JournalEvent> refused = decodeJournalEvent(bytes.data(), 48);
        ASSERT_FALSE(refused) << int(bad);
        EXPECT_NE(refused.error().message.find("offset 49, field pattern"), std::string::npos)
            << refused.error().message;
    }
}

TEST(Journal, AcceptedImpactsAreRoundedToTheJournalPrecision) {
    auto world = test::journalWorld(1);
    std::vector<JournalEvent> events;
    world->setJournalSink([&](const JournalEvent& e) { events.push_back(e); });
    const Impact exact{{0.1, 0.2 + 1e-12, 0.3}, {1, 0, 0}, 1000.0 / 3};
    ASSERT_TRUE(world->submitImpact(1, exact));
    EXPECT_FALSE(world->submitImpact(1, Impact{{0, 0, 0}, {1, 0, 0}, 0.5})) << "below the threshold";
    ASSERT_EQ(events.size(), 1u);
    EXPECT_EQ(events[0].impact().point.y, static_cast<double>(0.2f));
    EXPECT_EQ(events[0].impact().impulse, static_cast<double>(1000.0f / 3));
    EXPECT_EQ(events[0].tick, 0u);
    world->removeObject(2);
    world->removeObject(2); // already gone: not journaled twice
    ASSERT_EQ(events.size(), 2u);
    EXPECT_EQ(events[1].kind, JournalEventKind::Remove);
    EXPECT_EQ(world->journalPosition(), 2u);
}

TEST(Journal, ReplayRebuildsTheSameGeometryOnOneAndTwoWorkers) {
    const Recording rec = record(1, 240);
    ASSERT_GT(rec.fractures, 5);
    const auto removals = std::count_if(rec.events.begin(), rec.events.end(), [](const JournalEvent& e) {
        return e.kind == JournalEventKind::Remove;
    });
    EXPECT_GT(removals, 0) << "the awake budget retired debris: removals are journaled too";
    EXPECT_EQ(rec.journalPosition, rec.events.size());
    EXPECT_EQ(record(2, 240).geometry, rec.geometry) << "recording is deterministic";
    EXPECT_EQ(replay(rec.events, rec.frame, 1), rec.geometry);
    EXPECT_EQ(replay(rec.events, rec.frame, 2), rec.geometry);
    // Every event counts: without the last impact the geometry differs.
    std::vector<JournalEvent> fewer = rec.events;
    const auto lastImpact = std::find_if(fewer.rbegin(), fewer.rend(), [](const JournalEvent& e) {
        return e.kind == JournalEventKind::Impact;
    });
    ASSERT_NE(lastImpact, fewer.rend());
    fewer.erase(std::next(lastImpact).base());
    auto world = test::journalWorld(1);
    JournalPlayer player(*world);
    for (const JournalEvent& e : fewer)
        if (!player.receive(e))
            break;
    (void)player.advanceTo(rec.frame);
    (void)player.drain();
    EXPECT_NE(world->geometryHash(), rec.geometry);
}

// The adaptive pattern decides per impact from the journaled impulse and the geometry (impactCut), so a
// journal of weak and strong hits (chips and shatters, on pieces too) replays to the same geometry; nothing
// per impact travels beyond the 48 bytes.
TEST(Journal, AdaptiveHitsReplayToTheSameGeometry) {
    auto makeWorld = [](int workers) {
        auto world = std::make_unique<DestructionWorld>(test::journalConfig(workers).world);
        ObjectDesc d;
        d.mesh = makeBox({-3, 0, -0.3}, {3, 4, 0.3});
        d.density = 400;
        d.impulseThreshold = 1;
        d.fracture.pattern = CellPattern::Adaptive;
        d.fracture.cells = 8;
        d.fracture.sizeLaw.base = 0.5;
        d.fracture.sizeLaw.scale = 0.02;
        EXPECT_TRUE(world->addObject(std::move(d)));
        return world;
    };
    auto world = makeWorld(1);
    std::vector<JournalEvent> events;
    world->setJournalSink([&](const JournalEvent& e) { events.push_back(e); });
    JournalPlayer recorder(*world);
    std::size_t maxPieces = 0;
    recorder.setOnOutcome(
        [&](const FractureOutcome& o) { maxPieces = std::max(maxPieces, o.pieces.size()); });
    const double impulses[] = {100, 4000, 150, 6000}; // chip, shatter, chip, shatter (sizeFor: 0.7, 1.8, ...)
    for (int i = 0; i < 4; ++i) {
        ASSERT_TRUE(recorder.advanceTo(static_cast<std::uint64_t>(3 * i)));
        const std::vector<ObjectId> ids = world->objects();
        const ObjectId target = ids[static_cast<std::size_t>(i) % ids.size()];
        const Aabb b = world->object(target)->mesh.bounds();
        ASSERT_TRUE(
            world->submitImpact(target, Impact{b.center() + Vec3{0, 0, -1}, {0, 0, -1}, impulses[i]}));
    }
    ASSERT_TRUE(recorder.drain());
    ASSERT_EQ(events.size(), 4u);
    for (const JournalEvent& e : events)
        EXPECT_EQ(e.pattern & 15u, static_cast<unsigned>(CellPattern::Adaptive));
    EXPECT_GE(maxPieces, 3u) << "a strong hit shatters";
    const std::uint64_t frame = world->frame(), geometry = world->geometryHash();
    for (int workers : {1, 2}) {
        auto replayed = makeWorld(workers);
        JournalPlayer player(*replayed);
        for (const JournalEvent& e : events)
            ASSERT_TRUE(player.receive(e));
        ASSERT_TRUE(player.advanceTo(frame));
        ASSERT_TRUE(player.drain());
        EXPECT_EQ(replayed->geometryHash(), geometry) << workers << " workers";
    }
}

TEST(Journal, ReplayRefusesEventsOfAnotherWorldOrOutOfOrder) {
    const Recording rec = record(1, 60);
    ASSERT_FALSE(rec.events.empty());
    DestructionRuntime::Config other = test::journalConfig(1);
    other.world.seed = 12;
    DestructionWorld world(other.world);
    for (test::SceneObject& o : test::journalScene())
        ASSERT_TRUE(world.addObject(std::move(o.desc)));
    const JournalEvent first = rec.events.front();
    ASSERT_EQ(first.kind, JournalEventKind::Impact);
    Status s = world.applyJournalEvent(first);
    ASSERT_FALSE(s);
    EXPECT_NE(s.message().find("seed"), std::string::npos) << s.message();
    EXPECT_EQ(world.journalPosition(), 0u) << "nothing applied";
    JournalEvent missing = first;
    missing.object = 999;
    EXPECT_FALSE(world.applyJournalEvent(missing));

    auto fresh = test::journalWorld(1);
    JournalPlayer player(*fresh);
    ASSERT_TRUE(player.advanceTo(first.tick + 1));
    Status late = player.receive(first);
    ASSERT_FALSE(late);
    EXPECT_NE(late.message().find("journal order"), std::string::npos) << late.message();
    EXPECT_FALSE(checkJournalHeader(journalHeaderOf(test::journalConfig(1).world), other.world));
}

TEST(Journal, FileRoundTripsAndNamesTheOffsetOfDamage) {
    const Recording rec = record(1, 60);
    JournalFile j{journalHeaderOf(test::journalConfig(1).world, "tests/journal-scene"), rec.events};
    const std::filesystem::path path = test::tempDir("journal") / "run.rjournal";
    ASSERT_TRUE(writeJournal(path, j));
    EXPECT_EQ(std::filesystem::file_size(path),
              4 + 2 + 2 + 8 + 4 + 8 + 4 + 8 + 4 + j.header.scene.size() + 4 + 48 * j.events.size() + 4);
    Result<JournalFile> back = readJournal(path);
    ASSERT_TRUE(back) << back.error().message;
    EXPECT_EQ(back->header, j.header);
    EXPECT_EQ(back->events, j.events);
    EXPECT_TRUE(checkJournalHeader(back->header, test::journalConfig(2).world)) << "workers do not matter";

    std::vector<std::uint8_t> bytes = encodeJournal(j);
    std::vector<std::uint8_t> flipped = bytes;
    flipped[60] ^= 0x10;
    Result<JournalFile> bad = decodeJournal(flipped.data(), flipped.size(), "x.rjournal");
    ASSERT_FALSE(bad);
    EXPECT_NE(bad.error().message.find("field crc32"), std::string::npos) << bad.error().message;
    bad = decodeJournal(bytes.data(), bytes.size() - 30, "x.rjournal");
    ASSERT_FALSE(bad);
    EXPECT_NE(bad.error().message.find("x.rjournal: offset"), std::string::npos) << bad.error().message;
    std::vector<std::uint8_t> future = bytes;
    future[4] = 9;
    bad = decodeJournal(future.data(), future.size(), "x.rjournal");
    ASSERT_FALSE(bad);
    EXPECT_NE(bad.error().message.find("offset 4, field version"), std::string::npos) << bad.error().message;
}

// Round 3, defect 5: a journal with valid CRCs whose last event's tick is 0xFFFFFFF0 made the replay step
// toward it for about 4 hours. The decoder refuses such a gap naming offset and field, and so does the
// player.
TEST(Journal, AGapOfBillionsOfFramesIsRefused) {
    const Recording rec = record(1, 60);
    ASSERT_FALSE(rec.events.empty());
    JournalFile j{journalHeaderOf(test::journalConfig(1).world), rec.events};
    JournalEvent far = rec.events.back();
    far.tick = 0xFFFFFFF0u;
    j.events.push_back(far);
    std::vector<std::uint8_t> bytes = encodeJournal(j); // a valid checksum
    Result<JournalFile> bad = decodeJournal(bytes.data(), bytes.size(), "x.rjournal");
    ASSERT_FALSE(bad);
    const std::size_t tickAt = 48 + 48 * rec.events.size() + 8;
    EXPECT_NE(bad.error().message.find("offset " + std::to_string(tickAt) + ", field tick"),
              std::string::npos)
        << bad.error().message;
    EXPECT_NE(bad.error().message.find("more than the limit of 4194304 frames"), std::string::npos)
        << bad.error().message;
    // A gap of exactly the limit is a journal.
    j.events.back().tick = static_cast<std::uint32_t>(rec.events.back().tick + kMaxJournalTickGap);
    bytes = encodeJournal(j);
    EXPECT_TRUE(decodeJournal(bytes.data(), bytes.size(), "x.rjournal"));

    // The player refuses the far event from any source and keeps the others.
    auto world = test::journalWorld(1);
    JournalPlayer player(*world);
    for (const JournalEvent& e : rec.events)
        ASSERT_TRUE(player.receive(e));
    const std::size_t pending = player.pending();
    Status s = player.receive(far);
    ASSERT_FALSE(s);
    EXPECT_NE(s.message().find("more than the limit of 4194304 frames"), std::string::npos) << s.message();
    EXPECT_EQ(player.pending(), pending);
    ASSERT_TRUE(player.advanceTo(rec.frame));
    EXPECT_EQ(world->geometryHash(), rec.geometry);
}

} // namespace
} // namespace rubble
