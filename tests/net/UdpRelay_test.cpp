// The seeded link model's statistics (loss rate and bursts, delay distribution, reordering, duplication,
// bandwidth cap, partition window) and the UDP relay that applies it between real sockets on 127.0.0.1.
#include "rubble/enet/UdpRelay.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <thread>

namespace rubble {
namespace {

using net::LinkModel;
using net::LinkProfile;

// Sends n datagrams of `bytes` every `gap` seconds; returns each one's delivery times.
std::vector<std::vector<double>> drive(LinkModel& link, int n, double gap = 0.001, std::size_t bytes = 100) {
    std::vector<std::vector<double>> out;
    for (int i = 0; i < n; ++i)
        out.push_back(link.send(i * gap, bytes));
    return out;
}

// Mean length of the runs of consecutive lost datagrams.
double meanBurst(const std::vector<std::vector<double>>& fates) {
    long long bursts = 0, lost = 0;
    for (std::size_t i = 0; i < fates.size(); ++i)
        if (fates[i].empty()) {
            ++lost;
            bursts += i == 0 || !fates[i - 1].empty();
        }
    return bursts ? double(lost) / double(bursts) : 0;
}

TEST(LinkModel, IndependentLossHasTheRequestedRate) {
    LinkProfile p;
    p.loss = 0.05;
    LinkModel link(p, 7);
    const auto fates = drive(link, 200000);
    const double rate = double(link.stats().lost) / double(link.stats().sent);
    EXPECT_NEAR(rate, 0.05, 0.003);
    EXPECT_NEAR(meanBurst(fates), 1 / (1 - 0.05), 0.03); // geometric runs
    EXPECT_EQ(link.stats().partitionDrops + link.stats().queueDrops, 0);
}

TEST(LinkModel, BurstLossKeepsTheRateAndLengthensTheRuns) {
    LinkProfile p;
    p.loss = 0.05;
    p.burstLength = 4;
    LinkModel link(p, 7);
    const auto fates = drive(link, 400000);
    EXPECT_NEAR(double(link.stats().lost) / double(link.stats().sent), 0.05, 0.005);
    EXPECT_NEAR(meanBurst(fates), 4, 0.3);
}

TEST(LinkModel, DelayHasTheRequestedMeanAndJitter) {
    LinkProfile p;
    p.delayMs = 50;
    p.jitterMs = 10;
    LinkModel link(p, 3);
    const int n = 100000;
    const auto fates = drive(link, n);
    double sum = 0, sum2 = 0, lo = 1, hi = 0;
    for (int i = 0; i < n; ++i) {
        ASSERT_EQ(fates[i].size(), 1u);
        const double d = fates[i][0] - i * 0.001;
        sum += d;
        sum2 += d * d;
        lo = std::min(lo, d);
        hi = std::max(hi, d);
    }
    const double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
    EXPECT_NEAR(mean, 0.050, 0.0003);
    EXPECT_NEAR(sd, 0.010 * 0.987, 0.0003); // a normal cut at ±3σ keeps 98.7 % of its σ
    EXPECT_GE(lo, 0.020 - 1e-12);
    EXPECT_LE(hi, 0.080 + 1e-12);
}

TEST(LinkModel, ReorderingHoldsBackTheRequestedShare) {
    LinkProfile p;
    p.delayMs = 10;
    p.reorder = 0.1;
    p.reorderMs = 5;
    LinkModel link(p, 5);
    const int n = 50000;
    const auto fates = drive(link, n);
    int overtaken = 0;
    for (int i = 0; i + 1 < n; ++i)
        overtaken += fates[i + 1][0] < fates[i][0];
    EXPECT_NEAR(double(link.stats().reordered) / n, 0.1, 0.006);
    // Sent 1 ms apart and held back 5 ms: a held-back datagram is overtaken by the next one unless it is
    // held back too.
    EXPECT_NEAR(double(overtaken) / n, 0.1 * 0.9, 0.006);
}

TEST(LinkModel, DuplicationDeliversTheRequestedShareTwice) {
    LinkProfile p;
    p.delayMs = 5;
    p.duplicate = 0.03;
    LinkModel link(p, 9);
    const int n = 100000;
    const auto fates = drive(link, n);
    long long copies = 0;
    for (const auto& f : fates)
        copies += static_cast<long long>(f.size());
    EXPECT_NEAR(double(copies - n) / n, 0.03, 0.002);
    EXPECT_EQ(copies - n, link.stats().duplicated);
}

TEST(LinkModel, BandwidthCapLimitsThroughputAndDropsWhatQueuesTooLong) {
    LinkProfile p;
    p.kbps = 100;    // 12,500 bytes/s
    p.queueMs = 200; // at most 2.5 kB waiting
    LinkModel link(p, 1);
    const int n = 2000; // 1000-byte datagrams every 40 ms: 200 kbps offered for 80 s
    const auto fates = drive(link, n, 0.040, 1000);
    double last = 0;
    long long delivered = 0;
    for (const auto& f : fates)
        for (double t : f) {
            last = std::max(last, t);
            ++delivered;
        }
    const double kbps = double(delivered) * 8.0 / last; // bytes · 8 / 1000 / s
    EXPECT_NEAR(kbps, 100, 1);
    EXPECT_NEAR(double(link.stats().queueDrops) / n, 0.5, 0.01);
}

TEST(LinkModel, PartitionDropsEverythingInItsWindowAndNothingOutside) {
    LinkProfile p;
    p.delayMs = 30;
    p.partitionStartS = 1;
    p.partitionS = 2;
    LinkModel link(p, 2);
    const auto fates = drive(link, 4000); // 4 s, 1 ms apart
    int inside = 0, caught = 0;
    for (int i = 0; i < 4000; ++i) {
        const double t = i * 0.001;
        if (t >= 1 && t < 3) {
            EXPECT_TRUE(fates[i].empty()) << t;
            ++inside;
        } else {
            ASSERT_EQ(fates[i].size(), 1u) << t;
            // In flight when the window opens: lost too.
            const bool arrives = link.deliver(fates[i][0], 100);
            EXPECT_EQ(arrives, !(fates[i][0] >= 1 && fates[i][0] < 3)) << t;
            caught += !arrives;
        }
    }
    EXPECT_EQ(inside, 2000);
    EXPECT_NEAR(caught, 30, 1); // sent in the last 30 ms before the window
    EXPECT_EQ(link.stats().partitionDrops, inside + caught);
    link.setPartitioned(true);
    EXPECT_TRUE(link.send(10, 100).empty());
    link.setPartitioned(false);
    EXPECT_EQ(link.send(10, 100).size(), 1u);
}

TEST(LinkModel, TheSameSeedGivesTheSameFates) {
    LinkProfile p;
    p.delayMs = 40;
    p.jitterMs = 8;
    p.loss = 0.1;
    p.burstLength = 3;
    p.duplicate = 0.05;
    p.reorder = 0.05;
    LinkModel a(p, 42), b(p, 42), c(p, 43);
    const auto fa = drive(a, 5000), fb = drive(b, 5000), fc = drive(c, 5000);
    EXPECT_EQ(fa, fb);
    EXPECT_NE(fa, fc);
}

// A UDP socket on 127.0.0.1 with a free port.
struct Socket {
    Socket() {
        fd = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK, 0);
        sockaddr_in a{};
        a.sin_family = AF_INET;
        a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        EXPECT_EQ(bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
        socklen_t len = sizeof a;
        getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
        port = ntohs(a.sin_port);
    }
    ~Socket() { close(fd); }
    void sendTo(std::uint16_t to, const void* data, std::size_t n) const {
        sockaddr_in a{};
        a.sin_family = AF_INET;
        a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        a.sin_port = htons(to);
        (void)sendto(fd, data, n, 0, reinterpret_cast<sockaddr*>(&a), sizeof a);
    }
    int fd = -1;
    std::uint16_t port = 0;
};

TEST(UdpRelay, ForwardsBothWaysThroughItsLinksOnLoopback) {
    Socket server, client;
    LinkProfile up, down;
    up.delayMs = down.delayMs = 5;
    up.jitterMs = 2;
    up.loss = 0.2;
    down.duplicate = 0.1;
    auto relay = net::UdpRelay::start(server.port, up, down, 11);
    ASSERT_TRUE(relay) << relay.error().message;
    const int n = 300;
    std::vector<int> echoed(n, 0);
    int received = 0;
    // The server echoes what arrives; the client counts the echoes. Waits for conditions, not for times.
    const auto pump = [&] {
        std::uint8_t buf[2048];
        sockaddr_in from{};
        socklen_t len = sizeof from;
        for (ssize_t k;
             (k = recvfrom(server.fd, buf, sizeof buf, 0, reinterpret_cast<sockaddr*>(&from), &len)) > 0;
             len = sizeof from)
            (void)sendto(server.fd, buf, static_cast<std::size_t>(k), 0, reinterpret_cast<sockaddr*>(&from),
                         len);
        for (ssize_t k; (k = recv(client.fd, buf, sizeof buf, 0)) > 0;) {
            ASSERT_EQ(k, 64);
            int i;
            std::memcpy(&i, buf, sizeof i);
            ASSERT_TRUE(i >= 0 && i < n);
            for (ssize_t b = sizeof i; b < k; ++b)
                ASSERT_EQ(buf[b], static_cast<std::uint8_t>(i + b)) << "payload changed";
            ++echoed[static_cast<std::size_t>(i)];
            ++received;
        }
    };
    const auto until = [&](const auto& done) {
        for (const auto end = std::chrono::steady_clock::now() + std::chrono::minutes(1); !done();) {
            if (std::chrono::steady_clock::now() > end)
                return false;
            pump();
            std::this_thread::sleep_for(std::chrono::milliseconds(1));
        }
        return true;
    };
    for (int i = 0; i < n; ++i) {
        std::uint8_t msg[64];
        std::memcpy(msg, &i, sizeof i);
        for (std::size_t b = sizeof i; b < sizeof msg; ++b)
            msg[b] = static_cast<std::uint8_t>(i + static_cast<int>(b));
        client.sendTo((*relay)->port(), msg, sizeof msg);
        // One at a time, so that no socket buffer overflows on a loaded machine.
        ASSERT_TRUE(until([&] { return (*relay)->up().sent == i + 1; }));
    }
    net::UdpRelay& r = **relay;
    ASSERT_TRUE(until([&] {
        const net::LinkStats u = r.up(), d = r.down();
        return u.sent == n && u.lost + u.delivered == n && d.sent == u.delivered &&
               d.delivered == d.sent + d.duplicated && received == d.delivered;
    })) << r.up().sent
        << " " << r.down().sent << " " << received;
    EXPECT_GT(r.up().lost, n / 10);
    EXPECT_GT(r.down().duplicated, 0);
    EXPECT_EQ(*std::max_element(echoed.begin(), echoed.end()), 2);

    // Partitioned: nothing passes; healed: it passes again.
    r.setPartitioned(true);
    for (int i = 0; i < 50; ++i) {
        std::uint8_t msg[64] = {};
        client.sendTo(r.port(), msg, sizeof msg);
    }
    ASSERT_TRUE(until([&] { return r.up().sent == n + 50; }));
    EXPECT_EQ(r.up().partitionDrops, 50);
    const int before = received;
    r.setPartitioned(false);
    std::uint8_t msg[64];
    const int i = 0;
    std::memcpy(msg, &i, sizeof i);
    for (std::size_t b = sizeof i; b < sizeof msg; ++b)
        msg[b] = static_cast<std::uint8_t>(static_cast<int>(b));
    ASSERT_TRUE(until([&] {
        if (received > before)
            return true;
        client.sendTo(r.port(), msg, sizeof msg); // the up link loses some
        return false;
    }));
}

TEST(UdpRelay, RefusesPortZero) {
    EXPECT_FALSE(net::UdpRelay::start(0, {}, {}, 1));
}

} // namespace
} // namespace rubble
