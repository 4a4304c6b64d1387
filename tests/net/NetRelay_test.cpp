// Multiplayer on a network that misbehaves: three clients, each through its own seeded relay (delay, jitter,
// burst loss, reordering, duplication), one of them partitioned and healed, one killed and replaced; and a
// host that rogue traffic neither crashes nor changes; a host gone silent is noticed after the client's
// timeout; a handshake lost for seconds gets through soon after the link returns. Every wait is for a
// condition, with a deadline.
#include "rubble/enet/NetClient.hpp"
#include "rubble/enet/NetHost.hpp"
#include "rubble/enet/UdpRelay.hpp"

#include <arpa/inet.h>
#include <enet/enet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>

#include "JournalScene.hpp"
#include "NetRig.hpp"
#include "NetWait.hpp"

namespace rubble {
namespace {

using Clock = std::chrono::steady_clock;

net::LinkProfile badLink() {
    net::LinkProfile p;
    p.delayMs = 15;
    p.jitterMs = 4;
    p.loss = 0.03;
    p.burstLength = 2;
    p.reorder = 0.02;
    p.duplicate = 0.01;
    return p;
}

// A client with its own world, behind its own relay.
struct Follower {
    Follower(std::uint16_t hostPort, std::uint64_t seed) {
        auto r = net::UdpRelay::start(hostPort, badLink(), badLink(), seed);
        EXPECT_TRUE(r) << r.error().message;
        relay = std::move(*r);
        world = std::make_unique<DestructionWorld>(test::journalConfig(1).world);
        auto c = net::NetClient::connect(*world, test::journalConfig(1).world, "127.0.0.1", relay->port());
        EXPECT_TRUE(c) << c.error().message;
        client = std::move(*c);
    }
    std::unique_ptr<net::UdpRelay> relay;
    std::unique_ptr<DestructionWorld> world;
    std::unique_ptr<net::NetClient> client;
};

TEST(NetRelay, ClientsThroughMisbehavingLinksConvergeAfterAPartitionAndAReplacement) {
    test::NetHostRig net;
    ASSERT_TRUE(net.server);
    test::JournalRig& host = net.rig;
    net::NetHost& h = *net.server;
    std::vector<std::unique_ptr<Follower>> live;
    live.push_back(std::make_unique<Follower>(h.port(), 1));
    live.push_back(std::make_unique<Follower>(h.port(), 2));
    std::unique_ptr<Follower> killed;
    const auto pump = [&] {
        h.service(0);
        for (auto& f : live)
            ASSERT_TRUE(f->client->service(0));
    };
    const auto until = [&](const auto& done) {
        return test::waitFor(done, [&] {
            h.service(1);
            for (auto& f : live)
                if (Status st = f->client->service(1); !st) {
                    ADD_FAILURE() << st.message();
                    return false;
                }
            return true;
        });
    };
    ASSERT_TRUE(until([&] { return live[0]->client->stats().joined && live[1]->client->stats().joined; }));
    Clock::time_point healAt{};
    bool partitioned = false;
    for (int frame = 0; frame < 300; ++frame) {
        host.play(1);
        h.publish();
        if (frame % 6 == 0)
            h.publishPlacements(host.runtime.placements());
        const auto next = Clock::now() + std::chrono::milliseconds(5);
        while (Clock::now() < next) {
            pump();
            std::this_thread::sleep_for(std::chrono::milliseconds(1));
        }
        if (frame == 60) { // the first client drops off the network for 1.5 s, while the host fires
            live[0]->relay->setPartitioned(true);
            partitioned = true;
            healAt = Clock::now() + std::chrono::milliseconds(1500);
        }
        if (partitioned && Clock::now() >= healAt) {
            live[0]->relay->setPartitioned(false);
            partitioned = false;
        }
        if (frame == 100) // a third joins late
            live.push_back(std::make_unique<Follower>(h.port(), 3));
        if (frame == 150) { // the second is killed: its link goes dead, it says no goodbye
            live[1]->relay->setPartitioned(true);
            killed = std::move(live[1]);
            live.erase(live.begin() + 1);
        }
        if (frame == 170) // and someone joins in its place
            live.push_back(std::make_unique<Follower>(h.port(), 4));
    }
    if (partitioned)
        live[0]->relay->setPartitioned(false);
    host.settle();
    h.publish();
    const std::uint64_t last = host.runtime.world().frame();
    ASSERT_TRUE(until([&] {
        for (auto& f : live)
            if (f->client->stats().frame != last)
                return false;
        return true;
    })) << "frames "
        << live[0]->client->stats().frame << " " << live[1]->client->stats().frame << " "
        << live[2]->client->stats().frame << " of " << last;
    // Placements: what the host last published reaches everyone through the loss (delta-coded, sent again
    // until acknowledged).
    const std::vector<ObjectPlacement> placements = host.runtime.placements();
    // A second past the last frame, where a client holds every body at its newest placement.
    const double settled = static_cast<double>(last) + 60;
    // The first placement not yet where the host put it; empty once every one is.
    const auto missing = [&] {
        for (const ObjectPlacement& p : placements)
            for (std::size_t i = 0; i < live.size(); ++i) {
                const auto at = live[i]->client->placement(p.object, settled);
                if (!at)
                    return "client " + std::to_string(i) + ": object " + std::to_string(p.object) + " none";
                const double off = length(at->translation - p.objectToWorld.translation);
                if (off > 0.5e-3 * std::sqrt(3.0) + 1e-9)
                    return "client " + std::to_string(i) + ": object " + std::to_string(p.object) +
                           " off by " + std::to_string(off);
            }
        return std::string();
    };
    int sends = 0;
    ASSERT_TRUE(until([&] {
        if (missing().empty())
            return true;
        if (sends++ % 20 == 0)
            h.publishPlacements(placements);
        return false;
    })) << missing()
        << " after " << sends << " tries";
    const std::uint64_t hash = host.runtime.world().geometryHash();
    EXPECT_GT(host.runtime.counters().fractures, 5);
    for (auto& f : live) {
        EXPECT_EQ(f->world->geometryHash(), hash);
        EXPECT_EQ(f->client->stats().mismatchedHashes, 0);
        // At least the last frame's (its frame is the host's last): the checks above are not vacuous. How
        // many more depends on how fast it joined, which a loaded machine decides.
        EXPECT_GE(f->client->stats().syncs, 1);
    }
    EXPECT_EQ(h.stats().mismatchedHashes, 0);
    EXPECT_EQ(h.stats().joins, 4);
    EXPECT_GT(live[0]->relay->down().partitionDrops, 0);
    long long lost = 0, duplicated = 0;
    for (auto& f : live) {
        lost += f->relay->down().lost + f->relay->up().lost;
        duplicated += f->relay->down().duplicated;
    }
    EXPECT_GT(lost, 0);
    EXPECT_GT(duplicated, 0);
}

TEST(NetRelay, AClientCutOffIsSentASyncOnlyNowAndThenAndTheLatestWhenHeardAgain) {
    test::NetHostRig net;
    ASSERT_TRUE(net.server);
    test::JournalRig& host = net.rig;
    net::NetHost& h = *net.server;
    Follower f(h.port(), 41);
    const auto pump = [&] {
        h.service(1);
        return static_cast<bool>(f.client->service(1));
    };
    ASSERT_TRUE(test::waitFor([&] { return f.client->stats().joined; }, pump));
    host.play(1);
    h.publish();
    ASSERT_TRUE(test::waitFor([&] { return h.stats().acks > 0; }, pump)) << "its snapshot is in, syncs flow";
    f.relay->setPartitioned(true);
    const auto quiet = Clock::now() + std::chrono::milliseconds(400); // longer than the host's 300 ms
    ASSERT_TRUE(test::waitFor([&] { return Clock::now() >= quiet; }, pump));
    const long long before = h.stats().syncs;
    for (int frame = 0; frame < 120; ++frame) { // 2 s of frames, published at once
        host.play(1);
        h.publish();
        h.service(0);
    }
    EXPECT_GE(h.stats().syncs - before, 120 / 30);
    EXPECT_LE(h.stats().syncs - before, 120 / 30 + 1) << "a sync every 30 frames while it is cut off";
    f.relay->setPartitioned(false);
    const std::uint64_t last = host.runtime.world().frame();
    ASSERT_TRUE(test::waitFor([&] { return f.client->stats().frame == last; }, pump))
        << "it is sent the latest sync once heard again; at frame " << f.client->stats().frame << " of "
        << last;
    EXPECT_EQ(f.world->geometryHash(), host.runtime.world().geometryHash());
    EXPECT_EQ(f.client->stats().mismatchedHashes, 0);
    EXPECT_EQ(h.stats().mismatchedHashes, 0);
}

TEST(NetRelay, AClientFarBehindAfterAnOutageGetsTheWorldWithItsOwnObjectsByIdInsteadOfCuttingTheBacklog) {
    test::NetHostRig net;
    ASSERT_TRUE(net.server);
    test::JournalRig& host = net.rig;
    net::NetHost& h = *net.server;
    Follower f(h.port(), 51);
    long long cutUnsynced = 0; // fractures the client adopted itself before any resync
    f.client->setOnOutcome([&](const FractureOutcome&) { cutUnsynced += f.client->stats().resyncs == 0; });
    std::string failure; // why the client's service failed, if it did
    const auto pump = [&] {
        h.service(1);
        const Status s = f.client->service(1);
        if (!s)
            failure = s.message();
        return static_cast<bool>(s);
    };
    const auto fireAndFollow = [&](int frames) { // the host fires, and the client reaches its last frame
        for (int frame = 0; frame < frames; ++frame) {
            host.play(1);
            h.publish();
            h.service(0);
        }
        host.settle();
        h.publish();
        const std::uint64_t last = host.runtime.world().frame();
        return test::waitFor([&] { return f.client->stats().frame == last; }, pump);
    };
    ASSERT_TRUE(test::waitFor([&] { return f.client->stats().joined; }, pump)) << failure;
    ASSERT_TRUE(fireAndFollow(30)) << failure; // a few breaks before the outage, which it cuts itself
    f.relay->setPartitioned(true);
    const auto healAt = Clock::now() + std::chrono::milliseconds(1300); // longer than the client's 1 s
    const long long fractured = host.runtime.counters().fractures, cutBefore = cutUnsynced;
    const auto step = [&](int fireEvery) { // the host goes on at its pace (0: without firing)
        if (fireEvery > 0)
            host.play(1, fireEvery);
        else
            host.runtime.stepFrame();
        h.publish();
        if (host.runtime.world().frame() % 6 == 0)
            h.publishPlacements(host.runtime.placements());
        return pump();
    };
    for (int frame = 0; frame < 150; ++frame) // 2.5 s of fire while it hears nothing
        ASSERT_TRUE(step(7)) << failure;
    ASSERT_TRUE(test::waitFor([&] { return Clock::now() >= healAt; }, [&] { return step(0); })) << failure;
    const long long missed = host.runtime.counters().fractures - fractured;
    ASSERT_GT(missed, 3);
    f.relay->setPartitioned(false);
    const std::uint64_t healed = host.runtime.world().frame();
    // The host fires every other frame meanwhile: events it records after a sync of their frame reach the
    // client while its resync is on its way, and must follow that sync.
    long long objectsWhenBuilt = -1;
    ASSERT_TRUE(test::waitFor([&] { return f.client->stats().frame >= healed + 30; },
                              [&] {
                                  const bool ok = step(2);
                                  if (objectsWhenBuilt < 0 && h.stats().resyncs > 0) // built in that step
                                      objectsWhenBuilt =
                                          static_cast<long long>(host.runtime.world().objects().size());
                                  return ok;
                              }))
        << "at frame " << f.client->stats().frame << " of " << healed << ": " << failure;
    host.settle();
    h.publish();
    const std::uint64_t last = host.runtime.world().frame();
    ASSERT_TRUE(test::waitFor([&] { return f.client->stats().frame == last; }, pump)) << failure;
    EXPECT_EQ(f.client->stats().resyncs, 1);
    EXPECT_EQ(h.stats().resyncs, 1);
    EXPECT_LT(cutUnsynced - cutBefore, missed) << "the outage's pieces came by the resync, not cut by it";
    EXPECT_GT(h.stats().resyncObjectsSent, 0);
    EXPECT_LT(h.stats().resyncObjectsSent, objectsWhenBuilt) << "what it had unchanged went by id";
    EXPECT_EQ(f.world->geometryHash(), host.runtime.world().geometryHash());
    ASSERT_TRUE(fireAndFollow(60)) << failure; // and it follows the journal from there
    EXPECT_EQ(f.world->geometryHash(), host.runtime.world().geometryHash());
    EXPECT_EQ(f.client->stats().mismatchedHashes, 0);
    EXPECT_EQ(h.stats().mismatchedHashes, 0);
}

TEST(NetRelay, AClientsHelloTravelsWithTheConnectionSoThatAJitteryLinkNeverDelaysIt) {
    test::NetHostRig net;
    ASSERT_TRUE(net.server);
    net::NetHost& h = *net.server;
    h.publish();
    net::LinkProfile jittery; // no loss: datagrams sent together arrive in either order
    jittery.delayMs = 30;
    jittery.jitterMs = 15;
    for (std::uint64_t seed = 1; seed <= 6; ++seed) {
        auto relay = net::UdpRelay::start(h.port(), jittery, jittery, seed);
        ASSERT_TRUE(relay) << relay.error().message;
        DestructionWorld world(net.config);
        auto client = net::NetClient::connect(world, net.config, "127.0.0.1", (*relay)->port());
        ASSERT_TRUE(client) << client.error().message;
        ASSERT_TRUE(test::waitFor([&] { return (*client)->stats().joined; },
                                  [&] {
                                      h.service(1);
                                      return static_cast<bool>((*client)->service(1));
                                  }));
        // A Hello that overtook ENet's acknowledgement of the connection was dropped by the host and sent
        // again after ENet's retransmission timeout.
        EXPECT_EQ((*client)->stats().reliableResent, 0) << "client " << seed;
    }
}

TEST(NetRelay, AHandshakeLostForSecondsIsSentAgainEveryHalfSecondNotAfterDoublingTimers) {
    test::NetHostRig net;
    ASSERT_TRUE(net.server);
    net::NetHost& h = *net.server;
    h.publish();
    constexpr double kLostS =
        8; // seconds the handshake is lost in one direction (docs/netplay.md, "Outages")
    net::LinkProfile cut;
    cut.partitionStartS = 0;
    cut.partitionS = kLostS;
    struct Joiner {
        std::unique_ptr<net::UdpRelay> relay;
        std::unique_ptr<DestructionWorld> world;
        std::unique_ptr<net::NetClient> client;
    };
    std::vector<Joiner> joiners(2); // the client's connect lost; the host's answers lost
    for (std::size_t i = 0; i < joiners.size(); ++i) {
        auto relay = net::UdpRelay::start(h.port(), i == 0 ? cut : net::LinkProfile{},
                                          i == 0 ? net::LinkProfile{} : cut, 7);
        ASSERT_TRUE(relay) << relay.error().message;
        joiners[i].relay = std::move(*relay);
        joiners[i].world = std::make_unique<DestructionWorld>(net.config);
        auto c =
            net::NetClient::connect(*joiners[i].world, net.config, "127.0.0.1", joiners[i].relay->port());
        ASSERT_TRUE(c) << c.error().message;
        joiners[i].client = std::move(*c);
        joiners[i].client->setTimeout(30000);
    }
    std::string failure;
    ASSERT_TRUE(test::waitFor(
        [&] {
            return std::all_of(joiners.begin(), joiners.end(),
                               [](const Joiner& j) { return j.client->stats().joined; });
        },
        [&] {
            h.service(1);
            for (Joiner& j : joiners)
                if (Status st = j.client->service(1); !st) {
                    failure = st.message();
                    return false;
                }
            return true;
        }))
        << failure;
    for (std::size_t i = 0; i < joiners.size(); ++i) {
        const net::UdpRelay& relay = *joiners[i].relay;
        const char* what = i == 0 ? "connect lost" : "answers lost";
        EXPECT_GE((i == 0 ? relay.up() : relay.down()).partitionDrops, 3) << what; // the cut held it back
        EXPECT_LT(joiners[i].client->stats().connectMs, (kLostS + 4) * 1000) << what;
    }
}

TEST(NetRelay, AClientNoticesAHostThatStoppedAnsweringAfterItsTimeout) {
    test::NetHostRig net;
    ASSERT_TRUE(net.server);
    net::NetHost& h = *net.server;
    h.publish();
    Follower f(h.port(), 31);
    ASSERT_TRUE(test::waitFor([&] { return h.stats().acks > 0; },
                              [&] {
                                  h.service(1);
                                  return static_cast<bool>(f.client->service(1));
                              }));
    f.client->setTimeout(1000); // once joined: over the lossy link a 1 s timeout can expire while joining
    // The host goes silent as if killed (no goodbye): every datagram is dropped from now on.
    f.relay->setPartitioned(true);
    Status st = Status::ok();
    for (const auto end = Clock::now() + std::chrono::seconds(12); st && Clock::now() < end;) {
        h.service(1);
        st = f.client->service(1);
    }
    ASSERT_FALSE(st) << "still waiting 12 s after the host went silent, with a 1 s timeout";
    EXPECT_EQ(st.error().code, ErrorCode::IoError);
    EXPECT_NE(st.message().find("stopped answering"), std::string::npos) << st.message();
}

TEST(NetRelay, RogueTrafficNeitherCrashesTheHostNorChangesItsWorld) {
    test::NetHostRig net;
    ASSERT_TRUE(net.server);
    test::JournalRig &host = net.rig, reference(1);
    const DestructionWorld::Config& config = net.config;
    net::NetHost& h = *net.server;
    DestructionWorld world(config);
    auto honest = net::NetClient::connect(world, config, "127.0.0.1", h.port());
    ASSERT_TRUE(honest);

    // Raw datagrams of any size and content at the host's port.
    const int raw = socket(AF_INET, SOCK_DGRAM, 0);
    sockaddr_in to{};
    to.sin_family = AF_INET;
    to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    to.sin_port = htons(h.port());
    // An ENet peer that sends every message type with any payload, on both channels.
    ENetHost* rogue = enet_host_create(nullptr, 1, 2, 0, 0);
    ASSERT_NE(rogue, nullptr);
    ENetAddress a{};
    enet_address_set_host(&a, "127.0.0.1");
    a.port = h.port();
    ENetPeer* peer = enet_host_connect(rogue, &a, 2, 0);
    ASSERT_NE(peer, nullptr);
    Rng rng(99);
    bool rogueConnected = false;
    long long rogueSent = 0;
    std::vector<std::uint8_t> big(1 << 20, 0xAB);
    for (int frame = 0; frame < 200; ++frame) {
        host.play(1);
        reference.play(1);
        h.publish();
        for (int k = 0; k < 10; ++k) {
            std::vector<std::uint8_t> junk(static_cast<std::size_t>(rng.below(frame == 7 ? 65000 : 1500)));
            for (auto& b : junk)
                b = static_cast<std::uint8_t>(rng.next());
            if (!junk.empty() && rng.uniform() < 0.5)
                junk[0] = static_cast<std::uint8_t>(rng.below(8)); // a message type, or none
            (void)sendto(raw, junk.data(), junk.size(), 0, reinterpret_cast<sockaddr*>(&to), sizeof to);
            if (rogueConnected) {
                const bool huge = frame == 50 && k == 0;
                ENetPacket* p =
                    enet_packet_create(huge ? big.data() : junk.data(), huge ? big.size() : junk.size(),
                                       rng.uniform() < 0.5 ? ENET_PACKET_FLAG_RELIABLE : 0);
                if (enet_peer_send(peer, static_cast<enet_uint8>(rng.below(2)), p) != 0)
                    enet_packet_destroy(p);
                else
                    ++rogueSent;
            }
        }
        ENetEvent e;
        while (enet_host_service(rogue, &e, 0) > 0) {
            rogueConnected = rogueConnected || e.type == ENET_EVENT_TYPE_CONNECT;
            if (e.type == ENET_EVENT_TYPE_RECEIVE)
                enet_packet_destroy(e.packet);
        }
        h.service(1);
        Status st = (*honest)->service(0);
        ASSERT_TRUE(st) << st.message();
    }
    host.settle();
    reference.settle();
    h.publish();
    const std::uint64_t last = host.runtime.world().frame();
    for (const auto end = Clock::now() + std::chrono::minutes(2);
         (*honest)->stats().frame != last && Clock::now() < end;) {
        h.service(1);
        ASSERT_TRUE((*honest)->service(1));
        ENetEvent e;
        while (enet_host_service(rogue, &e, 0) > 0)
            if (e.type == ENET_EVENT_TYPE_RECEIVE)
                enet_packet_destroy(e.packet);
    }
    EXPECT_GT(rogueSent, 500);
    EXPECT_EQ(host.runtime.world().geometryHash(), reference.runtime.world().geometryHash())
        << "the host's world is what its own shots made it";
    EXPECT_EQ(host.runtime.world().journalPosition(), reference.runtime.world().journalPosition());
    EXPECT_EQ((*honest)->stats().frame, last);
    EXPECT_EQ(world.geometryHash(), host.runtime.world().geometryHash());
    EXPECT_EQ((*honest)->stats().mismatchedHashes, 0);
    enet_host_destroy(rogue);
    close(raw);
}

} // namespace
} // namespace rubble
