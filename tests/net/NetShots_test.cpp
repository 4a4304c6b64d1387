// Clients change the world only through shots the host checks: malformed, implausible and too frequent shots
// are refused and counted; accepted ones are fired by the host, and every client sees their fractures.
#include "rubble/enet/NetClient.hpp"
#include "rubble/enet/NetHost.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>

#include "JournalScene.hpp"
#include "NetWait.hpp"

namespace rubble {
namespace {

TEST(NetShots, TheHostFiresOnlyTheShotsThatPassItsRules) {
    test::JournalRig host(1);
    const DestructionWorld::Config config = test::journalConfig(1).world;
    auto server = net::NetHost::listen(host.runtime, config, "127.0.0.1", 0);
    ASSERT_TRUE(server) << server.error().message;
    net::NetHost& h = **server;
    DestructionWorld world(config);
    auto client = net::NetClient::connect(world, config, "127.0.0.1", h.port());
    ASSERT_TRUE(client);
    net::NetClient& c = **client;
    const auto until = [&](const auto& done) {
        return test::waitFor(done, [&] {
            h.service(1);
            return static_cast<bool>(c.service(1));
        });
    };
    ASSERT_TRUE(until([&] { return c.stats().joined; }));
    const auto counted = [&] { return h.stats().shotsAccepted + h.stats().shotsRefused; };

    // Without a handler the host takes no shot at all.
    const Vec3 at{-12, 1.5, 0}, fast{120, 0, 0};
    ASSERT_TRUE(c.shoot(at, fast));
    ASSERT_TRUE(until([&] { return counted() == 1; }));
    EXPECT_EQ(h.stats().shotsRefused, 1);

    std::vector<net::ShotRequest> queued;
    net::ShotRules rules;
    rules.perSecond = 10;
    rules.burst = 10;
    rules.maxSpeed = 200;
    rules.maxDistance = 100;
    h.setShotHandler([&](const net::ShotRequest& r) { queued.push_back(r); }, rules);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    ASSERT_TRUE(c.shoot({nan, 0, 0}, fast));  // not a number
    ASSERT_TRUE(c.shoot(at, {1e4, 0, 0}));    // faster than any gun
    ASSERT_TRUE(c.shoot({5000, 0, 0}, fast)); // from outside the world
    ASSERT_TRUE(c.shoot(at, {0, 0, 0}));      // no shot at all
    for (int i = 0; i < 30; ++i)              // a burst of 30 within one frame: 10 pass
        ASSERT_TRUE(c.shoot({-12, 0.5 + 0.1 * i, -1.5 + 0.1 * i}, fast));
    ASSERT_TRUE(until([&] { return counted() == 35; }));
    EXPECT_EQ(h.stats().shotsAccepted, 10);
    EXPECT_EQ(h.stats().shotsRefused, 25);
    ASSERT_EQ(queued.size(), 10u);
    EXPECT_EQ(queued[0].client, 0u);
    EXPECT_NEAR(queued[0].origin.y, 0.5, 1e-6) << "the first of the burst";

    // The host fires what it accepted; the client sees the fractures.
    const std::uint64_t before = host.runtime.world().geometryHash();
    for (const net::ShotRequest& r : queued)
        host.runtime.fireProjectile(r.origin, r.velocity, 5, 0.1);
    for (int frame = 0; frame < 120; ++frame) {
        host.runtime.stepFrame();
        h.publish();
        h.service(0);
        ASSERT_TRUE(c.service(0));
    }
    host.settle();
    h.publish();
    const std::uint64_t last = host.runtime.world().frame();
    ASSERT_TRUE(until([&] { return c.stats().frame == last; }));
    EXPECT_GT(host.runtime.counters().fractures, 0);
    EXPECT_NE(host.runtime.world().geometryHash(), before);
    EXPECT_EQ(world.geometryHash(), host.runtime.world().geometryHash());
    EXPECT_EQ(c.stats().mismatchedHashes, 0);

    // 120 frames later the bucket is full again: 10 more pass, the rest not.
    const long long accepted = h.stats().shotsAccepted;
    for (int i = 0; i < 12; ++i)
        ASSERT_TRUE(c.shoot(at, fast));
    ASSERT_TRUE(until([&] { return counted() == 47; }));
    EXPECT_EQ(h.stats().shotsAccepted - accepted, 10);
}

} // namespace
} // namespace rubble
