// Late join: a client that loaded the scene itself gets its unbroken objects by id and the rest deflated, and
// ends in the host's state; objects it has in another state are sent in full; malformed messages are refused.
#include "JoinSnapshot.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <utility>

#include "JournalScene.hpp"
#include "rubble/runtime/JournalPlayer.hpp"

namespace rubble {
namespace {

using net::detail::captureJoin;
using net::detail::decodeHello;
using net::detail::decodeJoinSnapshot;
using net::detail::encodeHello;
using net::detail::encodeJoin;
using net::detail::encodeJoinSnapshot;
using net::detail::JoinCapture;
using net::detail::JoinSnapshotSize;
using net::detail::KnownObjects;
using net::detail::PackedObjects;
using net::detail::SnapshotCodec;

// A host whose first shot broke the wall (the column and the slab are as loaded).
struct Fired {
    Fired() : host(1) {
        host.play(10);
        host.settle();
    }
    Snapshot snapshot() const { return takeSnapshot(host.runtime); }
    test::JournalRig host;
};

TEST(JoinSnapshot, AClientWithTheSceneGetsItsUnbrokenObjectsByIdAndEndsInTheHostsState) {
    Fired fired;
    const DestructionWorld& world = fired.host.runtime.world();
    auto client = test::journalWorld(1);
    KnownObjects known;
    const std::vector<std::uint8_t> hello = encodeHello(*client);
    ASSERT_TRUE(decodeHello(hello.data(), hello.size(), known));
    EXPECT_EQ(known.size(), client->objects().size());

    JoinSnapshotSize size;
    const std::vector<std::uint8_t> msg = encodeJoinSnapshot(fired.snapshot(), known, &size);
    std::size_t unbroken = 0; // scene objects the host still has as they were loaded
    for (ObjectId id : client->objects())
        unbroken += world.object(id) && world.object(id)->version == 0;
    ASSERT_GT(unbroken, 0u);
    ASSERT_LT(unbroken, client->objects().size()) << "the host fractured some";
    EXPECT_EQ(size.referenced, unbroken);
    const std::size_t full = encodeSnapshot(fired.snapshot()).size();
    EXPECT_LT(size.raw, full) << "without the unbroken objects";
    EXPECT_LT(size.wire, size.raw / 2) << "compressed";
    EXPECT_LT(size.wire, encodeJoinSnapshot(fired.snapshot(), KnownObjects{}).size())
        << "smaller than the whole world compressed";
    EXPECT_EQ(size.wire, msg.size());

    Result<Snapshot> s = decodeJoinSnapshot(msg.data(), msg.size(), *client);
    ASSERT_TRUE(s) << s.error().message;
    ASSERT_TRUE(restoreSnapshot(*client, std::move(*s)));
    EXPECT_EQ(client->geometryHash(), world.geometryHash());
    EXPECT_EQ(client->objects(), world.objects());

    // An empty client gets every object in the snapshot.
    DestructionWorld empty(test::journalConfig(1).world);
    const std::vector<std::uint8_t> all = encodeJoinSnapshot(fired.snapshot(), {}, &size);
    EXPECT_EQ(size.referenced, 0u);
    Result<Snapshot> t = decodeJoinSnapshot(all.data(), all.size(), empty);
    ASSERT_TRUE(t) << t.error().message;
    ASSERT_TRUE(restoreSnapshot(empty, std::move(*t)));
    EXPECT_EQ(empty.geometryHash(), world.geometryHash());
}

TEST(JoinSnapshot, ZstdPacksASnapshotTighterThanDeflateAndDecodesToTheSameState) {
    Fired fired;
    DestructionWorld deflated(test::journalConfig(1).world), zstd(test::journalConfig(1).world);
    JoinSnapshotSize a, b;
    const std::vector<std::uint8_t> deflateMsg =
        encodeJoinSnapshot(fired.snapshot(), {}, &a, SnapshotCodec::Deflate);
    const std::vector<std::uint8_t> zstdMsg =
        encodeJoinSnapshot(fired.snapshot(), {}, &b, SnapshotCodec::Zstd);
    EXPECT_EQ(a.raw, b.raw);
    EXPECT_LT(b.wire, a.wire) << "on the demolition scene a third smaller; here less (docs/netplay.md)";
    for (auto [msg, world] : {std::pair{&deflateMsg, &deflated}, std::pair{&zstdMsg, &zstd}}) {
        Result<Snapshot> s = decodeJoinSnapshot(msg->data(), msg->size(), *world);
        ASSERT_TRUE(s) << s.error().message;
        ASSERT_TRUE(restoreSnapshot(*world, std::move(*s)));
        EXPECT_EQ(world->geometryHash(), fired.host.runtime.world().geometryHash());
    }
    std::printf("join snapshot: %zu raw bytes, %zu deflated, %zu with zstd\n", a.raw, a.wire, b.wire);
}

// What a world announces in its Hello, as the host decodes it.
KnownObjects announced(const DestructionWorld& world) {
    KnownObjects known;
    const std::vector<std::uint8_t> hello = encodeHello(world);
    EXPECT_TRUE(decodeHello(hello.data(), hello.size(), known));
    return known;
}

TEST(JoinSnapshot, ObjectsPackedOneByOneAreCompressedOnceAndDecodeToTheSameState) {
    Fired fired;
    auto client = test::journalWorld(1);
    const KnownObjects known = announced(*client);
    PackedObjects cache;
    JoinSnapshotSize first, again, whole, later;
    const std::vector<std::uint8_t> msg =
        encodeJoinSnapshot(fired.snapshot(), known, &first, SnapshotCodec::Zstd, nullptr, &cache);
    ASSERT_GT(first.sent, 1u);
    EXPECT_EQ(first.packed, first.sent);
    EXPECT_EQ(encodeJoinSnapshot(fired.snapshot(), known, &again, SnapshotCodec::Zstd, nullptr, &cache), msg);
    EXPECT_EQ(again.packed, 0u) << "every object came from the cache";
    (void)encodeJoinSnapshot(fired.snapshot(), known, &whole);
    EXPECT_EQ(first.raw, whole.raw);
    std::printf("join snapshot: %zu bytes compressed whole, %zu packed object by object\n", whole.wire,
                first.wire);
    Result<Snapshot> s = decodeJoinSnapshot(msg.data(), msg.size(), *client);
    ASSERT_TRUE(s) << s.error().message;
    ASSERT_TRUE(restoreSnapshot(*client, std::move(*s)));
    EXPECT_EQ(client->geometryHash(), fired.host.runtime.world().geometryHash());

    fired.host.play(30); // more pieces: only they are compressed
    fired.host.settle();
    auto fresh = test::journalWorld(1);
    const std::vector<std::uint8_t> next =
        encodeJoinSnapshot(fired.snapshot(), known, &later, SnapshotCodec::Zstd, nullptr, &cache);
    EXPECT_GT(later.packed, 0u);
    EXPECT_LT(later.packed, later.sent);
    Result<Snapshot> t = decodeJoinSnapshot(next.data(), next.size(), *fresh);
    ASSERT_TRUE(t) << t.error().message;
    ASSERT_TRUE(restoreSnapshot(*fresh, std::move(*t)));
    EXPECT_EQ(fresh->geometryHash(), fired.host.runtime.world().geometryHash());
}

TEST(JoinSnapshot, ACaptureOfWhatTheClientLacksGivesTheSameMessageAsTheWholeWorldsSnapshot) {
    Fired fired;
    const DestructionWorld& world = fired.host.runtime.world();
    auto client = test::journalWorld(1);
    const KnownObjects known = announced(*client);
    KnownObjects changed = known;
    for (auto& [id, hash] : changed) // one object the client has in another state
        if (world.object(id) && world.object(id)->version == 0) {
            hash ^= 1;
            break;
        }
    const std::vector<ObjectPlacement> placements = fired.host.runtime.placements();
    const KnownObjects none;
    const KnownObjects* const sets[] = {&known, &changed, &none};
    for (const KnownObjects* set : sets) {
        const KnownObjects& k = *set;
        JoinSnapshotSize whole, chosen;
        const std::vector<std::uint8_t> expected =
            encodeJoinSnapshot(takeSnapshot(world, placements), k, &whole);
        JoinCapture capture = captureJoin(world, k, placements);
        EXPECT_EQ(capture.sent.size() + capture.byId.size(), world.objects().size());
        EXPECT_TRUE(capture.rest.world.objects.empty());
        for (const ObjectState* o : capture.sent)
            EXPECT_EQ(o, world.object(o->id)) << "read where the world keeps it, not copied";
        const std::vector<std::uint8_t> msg = encodeJoin(std::move(capture), &chosen);
        EXPECT_EQ(msg, expected) << "byte for byte";
        EXPECT_EQ(chosen.referenced, whole.referenced);
        if (set == &known) {
            EXPECT_GT(chosen.referenced, 0u);
        }
        Result<Snapshot> s = decodeJoinSnapshot(msg.data(), msg.size(), *client);
        ASSERT_TRUE(s) << s.error().message;
        EXPECT_EQ(encodeSnapshot(*s), encodeSnapshot(takeSnapshot(world, placements))) << "the host's state";
    }
    PackedObjects cache, other; // the same with objects compressed one by one
    JoinCapture capture = captureJoin(world, known, placements);
    EXPECT_EQ(encodeJoin(std::move(capture), nullptr, SnapshotCodec::Zstd, &cache),
              encodeJoinSnapshot(takeSnapshot(world, placements), known, nullptr, SnapshotCodec::Zstd,
                                 nullptr, &other));
}

TEST(JoinSnapshot, AClientThatReplayedTheJournalHasEveryPieceById) {
    test::JournalRig host(1);
    std::vector<JournalEvent> events;
    host.runtime.setJournalSink([&](const JournalEvent& e) { events.push_back(e); });
    host.play(40);
    host.settle();
    const DestructionWorld& world = host.runtime.world();
    auto client = test::journalWorld(1);
    JournalPlayer player(*client);
    for (const JournalEvent& e : events)
        ASSERT_TRUE(player.receive(e));
    ASSERT_TRUE(player.advanceTo(world.frame()));
    ASSERT_EQ(client->geometryHash(), world.geometryHash());
    KnownObjects known;
    const std::vector<std::uint8_t> hello = encodeHello(*client);
    ASSERT_TRUE(decodeHello(hello.data(), hello.size(), known));
    JoinSnapshotSize size;
    (void)encodeJoinSnapshot(takeSnapshot(host.runtime), known, &size);
    EXPECT_GT(host.runtime.counters().fractures, 3);
    EXPECT_EQ(size.referenced, world.objects().size())
        << "the pieces it cut itself are the host's, byte for byte";
}

TEST(JoinSnapshot, ObjectsInAnotherStateAreSentAndMalformedMessagesRefused) {
    Fired fired;
    auto client = test::journalWorld(1);
    KnownObjects known;
    const std::vector<std::uint8_t> hello = encodeHello(*client);
    ASSERT_TRUE(decodeHello(hello.data(), hello.size(), known));
    JoinSnapshotSize honest, changed;
    (void)encodeJoinSnapshot(fired.snapshot(), known, &honest);
    ASSERT_GT(honest.referenced, 0u);
    for (auto& [id, hash] : known) // one object the client has in another state
        if (fired.host.runtime.world().object(id) && fired.host.runtime.world().object(id)->version == 0) {
            hash ^= 1;
            break;
        }
    (void)encodeJoinSnapshot(fired.snapshot(), known, &changed);
    EXPECT_EQ(changed.referenced + 1, honest.referenced);

    // A world without the objects sent by id cannot take the snapshot, and says which object.
    std::vector<std::uint8_t> msg = encodeJoinSnapshot(fired.snapshot(), known);
    DestructionWorld empty(test::journalConfig(1).world);
    Result<Snapshot> missing = decodeJoinSnapshot(msg.data(), msg.size(), empty);
    ASSERT_FALSE(missing);
    EXPECT_NE(missing.error().message.find("this world does not have it"), std::string::npos);
    // Truncated or corrupted deflate data.
    EXPECT_FALSE(decodeJoinSnapshot(msg.data(), msg.size() - 7, *client));
    msg[msg.size() / 2] ^= 0x5a;
    EXPECT_FALSE(decodeJoinSnapshot(msg.data(), msg.size(), *client));
    EXPECT_FALSE(decodeJoinSnapshot(msg.data(), 1, *client));
    // A hello that is truncated, or whose ids do not ascend, changes nothing.
    KnownObjects before = known;
    EXPECT_FALSE(decodeHello(hello.data(), hello.size() - 1, known));
    std::vector<std::uint8_t> twice = {hello[0], 2, 5, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
    EXPECT_FALSE(decodeHello(twice.data(), twice.size(), known));
    EXPECT_EQ(known, before);
}

} // namespace
} // namespace rubble
