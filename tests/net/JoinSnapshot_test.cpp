// Late join: a client that loaded the scene itself gets its unbroken objects by id and the rest deflated, and
// ends in the host's state; objects it has in another state are sent in full; malformed messages are refused.
#include "JoinSnapshot.hpp"

#include <gtest/gtest.h>

#include "JournalScene.hpp"

namespace rubble {
namespace {

using net::detail::decodeHello;
using net::detail::decodeJoinSnapshot;
using net::detail::encodeHello;
using net::detail::encodeJoinSnapshot;
using net::detail::JoinSnapshotSize;
using net::detail::KnownObjects;

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
    EXPECT_LT(size.wire, full / 3) << "deflated, without the unbroken objects";
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
