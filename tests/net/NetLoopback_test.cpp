// Loopback multiplayer over real ENet sockets on 127.0.0.1: a host runtime under fire, one client from the
// start and one that joins late (snapshot + journal tail); both follow by journal events only and match the
// host's geometry hash at every frame.
#include "rubble/enet/NetClient.hpp"
#include "rubble/enet/NetHost.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <thread>

#include "JournalScene.hpp"
#include "NetRig.hpp"
#include "NetWait.hpp"
#include "TestSupport.hpp"
#include "rubble/persist/JournalFile.hpp"
#include "rubble/persist/Snapshot.hpp"
#include "rubble/runtime/JournalPlayer.hpp"

namespace rubble {
namespace {

TEST(NetLoopback, ClientsConvergeToTheHostsGeometryHash) {
    test::NetHostRig net;
    ASSERT_TRUE(net.server);
    test::JournalRig& host = net.rig;
    const DestructionWorld::Config& config = net.config;
    net::NetHost& h = *net.server;
    ASSERT_NE(h.port(), 0);

    DestructionWorld::Config c2 = config;
    c2.workers = 2;
    DestructionWorld early(config), late(c2);
    auto first = net::NetClient::connect(early, config, "127.0.0.1", h.port());
    ASSERT_TRUE(first) << first.error().message;
    std::unique_ptr<net::NetClient> second;
    auto pump = [&] {
        h.service(0);
        ASSERT_TRUE((*first)->service(0));
        if (second) {
            ASSERT_TRUE(second->service(0));
        }
    };
    // Every wait below is for a condition, with a deadline generous enough for a loaded machine under the
    // sanitizers: never for an assumed number of frames or milliseconds.
    const auto until = [&](const auto& done) {
        return test::waitFor(done, [&] {
            h.service(1);
            return (*first)->service(1) && (!second || second->service(1));
        });
    };
    ASSERT_TRUE(until([&] { return (*first)->stats().joined; }));
    for (int frame = 0; frame < 240; ++frame) {
        host.play(1);
        h.publish();
        if (frame % 6 == 0) // 10 Hz
            h.publishPlacements(host.runtime.placements());
        pump();
        if (frame == 120) { // joins mid-fire, with jobs in flight
            auto c = net::NetClient::connect(late, c2, "127.0.0.1", h.port());
            ASSERT_TRUE(c) << c.error().message;
            second = std::move(*c);
        }
    }
    host.settle();
    h.publish();
    ASSERT_TRUE(second);
    ASSERT_TRUE(until([&] { // both caught up with the last sync
        const std::uint64_t frame = host.runtime.world().frame();
        return (*first)->stats().frame == frame && second->stats().frame == frame &&
               h.stats().acks >= h.stats().syncs;
    }));
    ASSERT_TRUE(second->stats().joined);
    // Motion: the host's last placements arrive, and a late joiner knows the static objects from its
    // snapshot.
    const std::vector<ObjectPlacement> last = host.runtime.placements();
    const double now = static_cast<double>(host.runtime.world().frame());
    const auto arrived = [&] {
        for (const ObjectPlacement& p : last)
            for (net::NetClient* c : {first->get(), second.get()}) {
                const std::optional<Frame> f = c->placement(p.object, now);
                if (p.motion == BodyMotionState::Dynamic &&
                    (!f || length(f->translation - p.objectToWorld.translation) >= 1e-3))
                    return false;
            }
        return true;
    };
    // Placements travel unreliably (ENet throttles such packets when the round trip varies), so they are sent
    // again until they arrive, as a game streams them.
    int sends = 0;
    ASSERT_TRUE(until([&] {
        if (arrived())
            return true;
        if (sends++ % 20 == 0)
            h.publishPlacements(last);
        return false;
    })) << "placements sent "
        << sends << " times";
    int moving = 0, still = 0;
    for (const ObjectPlacement& p : last) {
        for (net::NetClient* c : {first->get(), second.get()}) {
            const std::optional<Frame> f = c->placement(p.object, now);
            if (p.motion != BodyMotionState::Dynamic) {
                still += f.has_value();
                continue;
            }
            ASSERT_TRUE(f) << "object " << p.object;
            ++moving;
            // On the wire's grid: 1 mm, and 10 bits per smallest-three component.
            EXPECT_LT(length(f->translation - p.objectToWorld.translation), 0.5e-3 * std::sqrt(3.0) + 1e-9);
            EXPECT_LT(length(f->rotation * Vec3{1, 0, 0} - p.objectToWorld.rotation * Vec3{1, 0, 0}), 4e-3);
        }
    }
    EXPECT_GT(moving, 0);
    EXPECT_GT(still, 0);
    EXPECT_GT(host.runtime.counters().fractures, 5);
    EXPECT_EQ(early.geometryHash(), host.runtime.world().geometryHash());
    EXPECT_EQ(late.geometryHash(), host.runtime.world().geometryHash());
    EXPECT_EQ((*first)->stats().mismatchedHashes, 0);
    EXPECT_EQ(second->stats().mismatchedHashes, 0);
    EXPECT_EQ(h.stats().mismatchedHashes, 0);
    EXPECT_GT((*first)->stats().syncs, 200);
    EXPECT_EQ(h.stats().joins, 2);
    const double bytesPerEvent = double(h.stats().eventBytes) / double(h.stats().eventsSent);
    EXPECT_LT(bytesPerEvent, 36) << "about 32 bytes per impact, 3 per removal, 3 to 4 per batch";
    std::printf(
        "netplay: %lld events, %.1f bytes/event, snapshot %lld bytes, late join %.1f ms, %lld placement "
        "bytes\n",
        h.stats().eventsSent, bytesPerEvent, h.stats().snapshotBytes, second->stats().joinMs,
        h.stats().placementBytes);
}

TEST(NetLoopback, AClientKeepsAReplayOfTheGameWhenTheHostStops) {
    test::NetHostRig net;
    ASSERT_TRUE(net.server);
    test::JournalRig& host = net.rig;
    const DestructionWorld::Config& config = net.config;
    std::unique_ptr<net::NetHost>& server = net.server;
    host.play(30); // some fractures before the client joins, more after
    DestructionWorld world(config);
    auto client = net::NetClient::connect(world, config, "127.0.0.1", server->port());
    ASSERT_TRUE(client) << client.error().message;
    EXPECT_FALSE((*client)->writeReplay(test::tempDir("net_replay") / "early.rbsn",
                                        test::tempDir("net_replay") / "early.rbj"));
    Status ending;
    const auto pump = [&] {
        if (server)
            server->service(1);
        ending = (*client)->service(1);
        return ending.ok();
    };
    ASSERT_TRUE(test::waitFor([&] { return (*client)->stats().joined; }, pump));
    const std::uint64_t joinedAt = host.runtime.world().frame();
    for (int frame = 0; frame < 120; ++frame) {
        host.play(1);
        server->publish();
        ASSERT_TRUE(pump());
    }
    host.settle();
    server->publish();
    const std::uint64_t last = host.runtime.world().frame(), hash = host.runtime.world().geometryHash();
    ASSERT_TRUE(test::waitFor([&] { return (*client)->stats().frame == last; }, pump));
    bool closed = false; // the host stops: the client hears it at once, not after ENet's timeout
    ASSERT_TRUE(test::waitFor([&] { return closed && !ending; },
                              [&] {
                                  closed = closed || server->close(10);
                                  if (ending)
                                      ending = (*client)->service(1);
                                  return true;
                              }));
    server.reset();
    EXPECT_EQ(ending.error().code, ErrorCode::IoError);
    EXPECT_NE(ending.message().find("closed"), std::string::npos) << ending.message();
    ASSERT_EQ(world.geometryHash(), hash);

    const std::filesystem::path dir = test::tempDir("net_replay");
    ASSERT_TRUE((*client)->writeReplay(dir / "game.rbsn", dir / "game.rbj"));
    Result<Snapshot> snapshot = loadSnapshot(dir / "game.rbsn");
    Result<JournalFile> journal = readJournal(dir / "game.rbj");
    ASSERT_TRUE(snapshot) << snapshot.error().message;
    ASSERT_TRUE(journal) << journal.error().message;
    EXPECT_EQ(snapshot->world.frame, joinedAt);
    ASSERT_TRUE(checkJournalHeader(journal->header, config));
    ASSERT_FALSE(journal->events.empty()) << "fractures after the join";
    DestructionWorld replay(config);
    ASSERT_TRUE(restoreSnapshot(replay, std::move(*snapshot)));
    ASSERT_NE(replay.geometryHash(), hash);
    JournalPlayer player(replay);
    for (const JournalEvent& e : journal->events)
        ASSERT_TRUE(player.receive(e));
    ASSERT_TRUE(player.advanceTo(last));
    EXPECT_EQ(replay.geometryHash(), hash);
}

TEST(NetLoopback, AClientWhoseWorldLagsShowsThoseFramesBetweenPlacements) {
    test::NetHostRig net;
    ASSERT_TRUE(net.server);
    test::JournalRig& host = net.rig;
    const DestructionWorld::Config& config = net.config;
    net::NetHost& h = *net.server;
    h.publish(); // the sync a joining client gets once its snapshot is in
    DestructionWorld world(config);
    auto client = net::NetClient::connect(world, config, "127.0.0.1", h.port());
    ASSERT_TRUE(client) << client.error().message;
    const auto pump = [&] {
        h.service(1);
        return static_cast<bool>((*client)->service(1));
    };
    ASSERT_TRUE(test::waitFor([&] { return h.stats().acks > 0; }, pump)); // joined, and confirmed that sync
    // The host moves a body 1 cm a frame for 3 s and sends its placements at 10 Hz; the client's world stays
    // at its join frame (no syncs), as one busy cutting pieces would.
    ObjectPlacement moving = host.runtime.placements().front();
    const Vec3 start = moving.objectToWorld.translation;
    const double first = static_cast<double>(host.runtime.world().frame());
    for (int publish = 0; publish < 30; ++publish) {
        for (int i = 0; i < 6; ++i)
            host.runtime.stepFrame();
        const double frame = static_cast<double>(host.runtime.world().frame());
        moving.objectToWorld.translation = start + Vec3{0.01 * (frame - first), 0, 0};
        h.publishPlacements({moving});
        ASSERT_TRUE(test::waitFor(
            [&] { return (*client)->placementFrame(moving.object) == std::optional(frame); }, pump));
    }
    const double last = static_cast<double>(host.runtime.world().frame());
    for (const double back : {0.0, 30.0, 63.0, 100.0}) { // 100 frames back: 17 placements
        const std::optional<Frame> f = (*client)->placement(moving.object, last - back);
        ASSERT_TRUE(f);
        EXPECT_NEAR(f->translation.x, start.x + 0.01 * (last - back - first), 1e-3) << back << " frames back";
    }
}

// A client of the host on `world`, connected until the host took its snapshot (the client goes first each
// round, so it has read no chunk yet); null when that failed.
std::unique_ptr<net::NetClient> joining(test::NetHostRig& net, DestructionWorld& world) {
    auto client = net::NetClient::connect(world, net.config, "127.0.0.1", net.server->port());
    EXPECT_TRUE(client) << (client ? std::string() : client.error().message);
    if (!client)
        return nullptr;
    const bool taken = test::waitFor([&] { return net.server->stats().joins == 1; },
                                     [&] {
                                         const bool ok = static_cast<bool>((*client)->service(1));
                                         net.server->service(0);
                                         return ok;
                                     });
    EXPECT_TRUE(taken);
    return taken ? std::move(*client) : nullptr;
}

TEST(NetLoopback, OneLongServiceCallSendsASnapshotOfMoreThanOneBurst) {
    test::NetHostRig net;
    ASSERT_TRUE(net.server);
    net::NetHost& h = *net.server;
    net.rig.play(480);
    DestructionWorld world(net.config); // bare: the whole snapshot travels
    std::unique_ptr<net::NetClient> client = joining(net, world);
    ASSERT_TRUE(client);
    ASSERT_GT(h.stats().snapshotBytes, 2 * 96 * 1100) << "more chunks than the host sends in two bursts";
    // The client reads on its own thread while the game serves the network once, as it waits for its next
    // frame; every chunk goes out in that call, so the client gets the snapshot without another.
    bool joined = false;
    std::thread reader([&] {
        const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(10);
        while (!joined && std::chrono::steady_clock::now() < end && client->service(1))
            joined = client->stats().joined;
    });
    h.service(300);
    reader.join();
    EXPECT_TRUE(joined);
}

TEST(NetLoopback, AJoiningClientGetsTheLatestPlacementsAsSoonAsItHasItsSnapshot) {
    test::NetHostRig net;
    ASSERT_TRUE(net.server);
    net::NetHost& h = *net.server;
    net.rig.play(20); // the slab falls, pieces fly
    DestructionWorld world(net.config);
    std::unique_ptr<net::NetClient> client = joining(net, world);
    ASSERT_TRUE(client);
    const std::vector<ObjectPlacement> atSnapshot = net.rig.runtime.placements();
    net.rig.play(12);
    h.publish();
    const std::vector<ObjectPlacement> latest = net.rig.runtime.placements();
    h.publishPlacements(latest); // its snapshot is still on its way; the game publishes no more
    const double frame = static_cast<double>(net.rig.runtime.world().frame());
    std::vector<ObjectPlacement> moved;
    for (const ObjectPlacement& p : latest)
        for (const ObjectPlacement& q : atSnapshot)
            if (p.object == q.object && p.motion == BodyMotionState::Dynamic &&
                length(p.objectToWorld.translation - q.objectToWorld.translation) > 0.01)
                moved.push_back(p);
    ASSERT_FALSE(moved.empty());
    ASSERT_TRUE(test::waitFor(
        [&] {
            return std::all_of(moved.begin(), moved.end(), [&](const ObjectPlacement& p) {
                return client->placementFrame(p.object) == std::optional(frame);
            });
        },
        [&] {
            h.service(1);
            return static_cast<bool>(client->service(1));
        }));
    for (const ObjectPlacement& p : moved)
        EXPECT_LT(length(client->placement(p.object, frame)->translation - p.objectToWorld.translation),
                  1e-3);
}

TEST(NetLoopback, ClientsJoiningWithinHalfASecondShareOneSnapshotAndGetTheJournalSinceIt) {
    test::NetHostRig net;
    ASSERT_TRUE(net.server);
    net::NetHost& h = *net.server;
    net.rig.play(20);
    h.publish();
    DestructionWorld first(net.config), second(net.config);
    std::unique_ptr<net::NetClient> a = joining(net, first);
    ASSERT_TRUE(a);
    net.rig.play(15, 3); // shots between the two joins: journal events the second needs
    h.publish();
    auto b = net::NetClient::connect(second, net.config, "127.0.0.1", h.port());
    ASSERT_TRUE(b);
    const auto pump = [&] {
        h.service(1);
        return a->service(1) && (*b)->service(1);
    };
    ASSERT_TRUE(test::waitFor([&] { return h.stats().joins == 2; }, pump));
    EXPECT_EQ(h.stats().snapshotBuilds, 1) << "the second is given the first one's snapshot, 15 frames old";
    for (int frame = 0; frame < 30; ++frame) {
        net.rig.play(1, 3);
        h.publish();
        (void)pump();
    }
    net.rig.settle();
    h.publish();
    const std::uint64_t last = net.rig.runtime.world().frame();
    ASSERT_TRUE(test::waitFor([&] { return a->stats().frame == last && (*b)->stats().frame == last; }, pump));
    EXPECT_EQ(first.geometryHash(), net.rig.runtime.world().geometryHash());
    EXPECT_EQ(second.geometryHash(), net.rig.runtime.world().geometryHash());
    EXPECT_EQ(a->stats().mismatchedHashes, 0);
    EXPECT_EQ((*b)->stats().mismatchedHashes, 0);
    EXPECT_EQ(h.stats().mismatchedHashes, 0);
    EXPECT_GT((*b)->stats().events, 0);
}

TEST(NetLoopback, AJoinAfterTheHostWaitedCompressesNoObjectItHadCompressedAhead) {
    test::NetHostRig net;
    ASSERT_TRUE(net.server);
    net::NetHost& h = *net.server;
    h.setSnapshotCache(true);
    net.rig.play(40);
    net.rig.settle();
    h.publish();
    ASSERT_GT(net.rig.runtime.counters().fractures, 2);
    ASSERT_TRUE(test::waitFor(
        [&] {
            return h.stats().objectsWarmed >=
                   static_cast<long long>(net.rig.runtime.world().objects().size());
        },
        [&] {
            h.service(5); // the game waits for its next frame
            return true;
        }));
    DestructionWorld world(net.config);
    std::unique_ptr<net::NetClient> client = joining(net, world);
    ASSERT_TRUE(client);
    EXPECT_EQ(h.stats().snapshotObjectsPacked, 0) << "every object was compressed while the host waited";
    ASSERT_TRUE(test::waitFor([&] { return client->stats().joined && h.stats().acks > 0; },
                              [&] {
                                  h.service(1);
                                  return static_cast<bool>(client->service(1));
                              }));
    EXPECT_EQ(world.geometryHash(), net.rig.runtime.world().geometryHash());
    EXPECT_EQ(client->stats().mismatchedHashes, 0);
}

TEST(NetLoopback, AClientHashesItsObjectsForTheHelloWhileItConnects) {
    test::NetHostRig net;
    ASSERT_TRUE(net.server);
    net::NetHost& h = *net.server;
    net.rig.play(20);
    net.rig.settle();
    h.publish();
    std::unique_ptr<DestructionWorld> world = test::journalWorld(1); // the client loaded the scene
    auto connecting = net::NetClient::connect(*world, net.config, "127.0.0.1", h.port());
    ASSERT_TRUE(connecting);
    net::NetClient& client = **connecting;
    EXPECT_FALSE(client.stats().connected);
    EXPECT_GT(client.stats().helloMs, 0) << "its objects are hashed while the connection is being made";
    ASSERT_TRUE(test::waitFor([&] { return client.stats().joined && h.stats().acks > 0; },
                              [&] {
                                  h.service(1);
                                  return static_cast<bool>(client.service(1));
                              }));
    EXPECT_GT(h.stats().snapshotObjectsByReference, 0);
    EXPECT_EQ(world->geometryHash(), net.rig.runtime.world().geometryHash());
    EXPECT_EQ(client.stats().mismatchedHashes, 0);
    EXPECT_GT(client.stats().firstChunkMs, 0);
    EXPECT_LE(client.stats().snapshotDecodeMs, client.stats().snapshotLoadMs);
}

TEST(NetLoopback, AClientLongInOneServiceCallCuttingPiecesStillAnswersTheHost) {
    test::NetHostRig net;
    ASSERT_TRUE(net.server);
    net::NetHost& h = *net.server;
    h.setTimeout(2000); // a client silent for 2 s is dropped
    DestructionWorld world(net.config);
    std::unique_ptr<net::NetClient> client = joining(net, world);
    ASSERT_TRUE(client);
    client->setResyncFrames(0); // it cuts everything itself
    // Each piece it cuts takes 300 ms, as on a machine with little CPU to spare.
    client->setOnOutcome(
        [](const FractureOutcome&) { std::this_thread::sleep_for(std::chrono::milliseconds(300)); });
    std::atomic<bool> firing{true}, done{false};
    std::atomic<std::uint64_t> hostFrame{0};
    std::thread host([&] { // the host at 60 Hz in real time, firing for 1.5 s
        for (int frame = 0; !done; ++frame) {
            if (firing)
                net.rig.play(1, 6);
            else
                net.rig.runtime.stepFrame();
            h.publish();
            hostFrame = net.rig.runtime.world().frame();
            h.service(16);
            if (frame == 90)
                firing = false;
        }
    });
    Status st = Status::ok();
    const auto end = std::chrono::steady_clock::now() + std::chrono::minutes(2);
    while (st && std::chrono::steady_clock::now() < end && (firing || client->stats().frame + 30 < hostFrame))
        st = client->service(5);
    done = true;
    host.join();
    ASSERT_TRUE(st) << st.message();
    EXPECT_EQ(h.stats().clients, 1) << "the host kept it";
    EXPECT_GT(client->stats().keepAlives, 0);
    EXPECT_EQ(client->stats().mismatchedHashes, 0);
    EXPECT_EQ(h.stats().mismatchedHashes, 0);
}

TEST(NetLoopback, OnlyLoopbackAddressesAndDeterministicWorlds) {
    DestructionWorld::Config config = test::journalConfig(1).world;
    test::JournalRig host(1);
    DestructionWorld world(config);
    auto outside = net::NetHost::listen(host.runtime, config, "192.0.2.1", 0);
    ASSERT_FALSE(outside);
    EXPECT_NE(outside.error().message.find("not a loopback address"), std::string::npos);
    EXPECT_FALSE(net::NetClient::connect(world, config, "192.0.2.1", 7777));
    config.deterministic = false;
    EXPECT_FALSE(net::NetHost::listen(host.runtime, config, "127.0.0.1", 0));
}

} // namespace
} // namespace rubble
