// Placement compression: the grid's error bounds, delta coding against acknowledged baselines under loss,
// bodies at rest costing nothing, the byte budget with a priority accumulator and a reserve, bodies on their
// way not sent twice, malformed datagrams.
#include "Placements.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "rubble/core/Random.hpp"

namespace rubble {
namespace {

using net::detail::DecodedPlacement;
using net::detail::dequantize;
using net::detail::PlacementDecoder;
using net::detail::PlacementEncoder;
using net::detail::quantize;
using net::detail::Quantized;

using State = std::vector<std::pair<ObjectId, Quantized>>;

TEST(Placements, TheGridErrsByAtMostHalfAMillimetrePerAxisAndAFewMilliradians) {
    Rng rng(5);
    double worstAngle = 0;
    for (int i = 0; i < 20000; ++i) {
        Frame f;
        f.rotation = rng.rotation();
        f.translation = rng.inBox({-500, -500, -500}, {500, 500, 500});
        const Frame g = dequantize(quantize(f));
        for (int k = 0; k < 3; ++k)
            ASSERT_LE(std::abs(g.translation[k] - f.translation[k]), 0.5e-3 + 1e-12);
        for (const Vec3& axis : {Vec3{1, 0, 0}, Vec3{0, 1, 0}, Vec3{0, 0, 1}})
            worstAngle = std::max(worstAngle, length(g.rotation * axis - f.rotation * axis));
        const Quantized a = quantize(f), b = quantize(g);
        ASSERT_TRUE(a.p[0] == b.p[0] && a.p[1] == b.p[1] && a.p[2] == b.p[2]) << "a grid point is its own";
    }
    // Three components of step √2/1023, each off by at most half a step: |Δq| ≤ 1.7e-3 with the fourth's
    // change, and an axis turns by at most about 2|Δq|.
    EXPECT_LT(worstAngle, 4e-3);
    EXPECT_GT(worstAngle, 1e-4);
}

// A host with n bodies on a random walk, some of them at rest, and a client following it.
struct Link {
    explicit Link(int n, int resting) : rng(3) {
        for (int i = 0; i < n; ++i) {
            Frame f;
            f.rotation = rng.rotation();
            f.translation = rng.inBox({-50, 0, -50}, {50, 10, 50});
            frames.push_back(f);
            moving.push_back(i >= resting);
            const ObjectId id = static_cast<ObjectId>(100 + 3 * i);
            ids.push_back(id);
            host.setBaseline(id, quantize(f)); // from the snapshot
            client.setBaseline(id, quantize(f));
        }
    }
    State step() {
        State s;
        for (std::size_t i = 0; i < frames.size(); ++i) {
            if (moving[i]) {
                frames[i].translation =
                    frames[i].translation + rng.inBox({-0.2, -0.2, -0.2}, {0.2, 0.2, 0.2});
                frames[i].rotation = frames[i].rotation * Rng(rng.next()).rotation();
            }
            s.emplace_back(ids[i], quantize(frames[i]));
        }
        return s;
    }
    Rng rng;
    std::vector<Frame> frames;
    std::vector<bool> moving;
    std::vector<ObjectId> ids;
    PlacementEncoder host;
    PlacementDecoder client;
};

TEST(Placements, BodiesAtRestCostNothingAndMovingOnesArriveExactly) {
    Link link(300, 250);
    const State now = link.step();
    auto datagrams = link.host.encode(1, now, 100000);
    ASSERT_FALSE(datagrams.empty());
    std::map<ObjectId, Quantized> got;
    std::size_t bytes = 0;
    for (const auto& d : datagrams) {
        EXPECT_LE(d.size(), net::detail::kMaxPlacementDatagram);
        bytes += d.size();
        std::uint64_t frame = 0;
        std::vector<DecodedPlacement> out;
        ASSERT_TRUE(link.client.decode(d.data(), d.size(), frame, out));
        EXPECT_EQ(frame, 1u);
        for (const auto& r : out)
            got[r.id] = r.q;
    }
    EXPECT_EQ(got.size(), 50u) << "only the moving bodies";
    for (const auto& [id, q] : now)
        if (got.count(id)) {
            EXPECT_EQ(got[id], q);
        }
    link.host.acked(link.client.latest(), link.client.mask());
    EXPECT_TRUE(link.host.encode(2, now, 100000).empty()) << "nothing changed since the acknowledged state";
    EXPECT_EQ(link.host.behind(), 0u);
    // Against the snapshot's baselines, 20 cm steps cost fewer bytes than whole states (no baselines).
    PlacementEncoder whole;
    std::size_t wholeBytes = 0;
    for (const auto& d : whole.encode(1, now, 100000))
        wholeBytes += d.size();
    EXPECT_LT(double(bytes) / 50, double(wholeBytes) / 300 - 2);
    EXPECT_LT(double(bytes) / 50, 14);
}

TEST(Placements, DeltasDecodeExactlyUnderLossOfDatagramsAndAcknowledgements) {
    Link link(120, 20);
    Rng loss(17);
    std::map<ObjectId, Quantized> client;
    std::map<std::uint64_t, State> sent; // frame → host state
    int lostDatagrams = 0, deltas = 0;
    for (std::uint64_t frame = 1; frame <= 300; ++frame) {
        const State now = link.step();
        sent[frame] = now;
        const bool clean = frame > 280; // a clean link at the end
        for (const auto& d : link.host.encode(frame, now, 1200)) {
            if (!clean && loss.uniform() < 0.3) {
                ++lostDatagrams;
                continue;
            }
            std::uint64_t f = 0;
            std::vector<DecodedPlacement> out;
            ASSERT_TRUE(link.client.decode(d.data(), d.size(), f, out));
            ASSERT_EQ(f, frame);
            std::map<ObjectId, Quantized> truth(sent[f].begin(), sent[f].end());
            for (const auto& r : out) {
                ASSERT_EQ(r.q, truth[r.id]) << "object " << r.id << " at frame " << frame;
                client[r.id] = r.q;
            }
            deltas += static_cast<int>(out.size());
            if (clean || loss.uniform() >= 0.3)
                link.host.acked(link.client.latest(), link.client.mask());
        }
    }
    EXPECT_GT(lostDatagrams, 50);
    EXPECT_GT(deltas, 1000);
    // The budget lets 1200 bytes through per frame: once the link is clean, everyone catches up.
    const State last = link.step();
    for (int round = 0; round < 40; ++round) {
        for (const auto& d : link.host.encode(400 + round, last, 1200)) {
            std::uint64_t f = 0;
            std::vector<DecodedPlacement> out;
            ASSERT_TRUE(link.client.decode(d.data(), d.size(), f, out));
            for (const auto& r : out)
                client[r.id] = r.q;
            link.host.acked(link.client.latest(), link.client.mask());
        }
    }
    EXPECT_EQ(link.host.behind(), 0u);
    for (const auto& [id, q] : last)
        if (client.count(id)) {
            EXPECT_EQ(client[id], q) << id;
        }
}

TEST(Placements, TheBudgetIsKeptAndEveryBodyGetsItsTurn) {
    Link link(1000, 0);
    std::map<ObjectId, int> lastSent;
    int worstWait = 0;
    for (int frame = 1; frame <= 60; ++frame) {
        const State now = link.step();
        std::size_t bytes = 0;
        for (const auto& d : link.host.encode(static_cast<std::uint64_t>(frame), now, 1500)) {
            bytes += d.size();
            std::uint64_t f = 0;
            std::vector<DecodedPlacement> out;
            ASSERT_TRUE(link.client.decode(d.data(), d.size(), f, out));
            for (const auto& r : out) {
                worstWait = std::max(worstWait, frame - lastSent[r.id]);
                lastSent[r.id] = frame;
            }
            link.host.acked(link.client.latest(), link.client.mask());
        }
        EXPECT_LE(bytes, 1500u);
        EXPECT_GT(bytes, 1000u);
    }
    EXPECT_EQ(lastSent.size(), 1000u) << "nobody starves";
    // About 100 records fit in a frame's budget, so a body waits about 10 frames; the accumulator favours
    // the bodies that moved most, but no one waits much longer.
    EXPECT_LT(worstWait, 25);
}

TEST(Placements, TheAllowanceSavesWhatQuietPublishesLeaveForWhenManyBodiesMove) {
    net::detail::PlacementAllowance busy(1200, 3600, 24000);
    std::size_t total = 0, first = 0;
    for (int i = 0; i < 100; ++i) { // always something to send: the full reserve, then the mean
        const std::size_t bytes = busy.next();
        EXPECT_LE(bytes, 3600u);
        busy.spent(bytes);
        total += bytes;
        first = i == 0 ? bytes : first;
    }
    EXPECT_EQ(first, 3600u) << "a client that just joined catches up at the peak";
    EXPECT_LE(total, 24000u + 100 * 1200);
    EXPECT_GE(total, 24000u + 99 * 1200);
    net::detail::PlacementAllowance quiet(1200, 3600, 24000);
    for (int i = 0; i < 40; ++i) // nothing moves for 4 s
        (void)quiet.next();
    std::size_t burst = 0;
    int full = 0;
    for (int i = 0; i < 30; ++i) { // then a collapse: 3 s with more to send than the mean
        const std::size_t bytes = quiet.next();
        full += bytes == 3600;
        quiet.spent(bytes);
        burst += bytes;
    }
    EXPECT_GE(full, 8) << "the reserve is spent at the peak rate";
    EXPECT_LE(burst, 24000u + 30 * 1200);
    EXPECT_GE(burst, 24000u + 29 * 1200);
    net::detail::PlacementAllowance fixed(1200, 1200, 1200); // no reserve: the old fixed budget
    for (int i = 0; i < 40; ++i)
        (void)fixed.next();
    EXPECT_EQ(fixed.next(), 1200u);
}

TEST(Placements, ABodyOnItsWayIsNotSentAgainUnlessItsDatagramIsLost) {
    Link link(200, 0);
    const State now = link.step();
    const auto first = link.host.encode(1, now, 100000);
    ASSERT_FALSE(first.empty());
    EXPECT_TRUE(link.host.encode(2, now, 100000).empty()) << "every state is on its way: nothing to send";
    // The client got all but the first datagram and says so: the bodies in that one go again.
    std::vector<DecodedPlacement> out;
    for (std::size_t i = 1; i < first.size(); ++i) {
        std::uint64_t f = 0;
        ASSERT_TRUE(link.client.decode(first[i].data(), first[i].size(), f, out));
    }
    link.host.acked(link.client.latest(), link.client.mask());
    std::set<ObjectId> got, again;
    for (const auto& r : out)
        got.insert(r.id);
    for (const auto& d : link.host.encode(3, now, 100000)) {
        std::uint64_t f = 0;
        std::vector<DecodedPlacement> more;
        ASSERT_TRUE(link.client.decode(d.data(), d.size(), f, more));
        for (const auto& r : more)
            again.insert(r.id);
    }
    EXPECT_EQ(got.size() + again.size(), 200u);
    for (ObjectId id : again)
        EXPECT_FALSE(got.count(id)) << id << " arrived and was sent again";
    // No acknowledgement at all (the acks are lost): after a few publishes the host sends them again.
    PlacementEncoder silent;
    ASSERT_FALSE(silent.encode(1, now, 100000).empty());
    std::size_t resent = 0;
    for (std::uint64_t f = 2; f < 2 + net::detail::kInFlightEncodes + 1; ++f)
        for (const auto& d : silent.encode(f, now, 100000))
            resent += d.size();
    EXPECT_GT(resent, 0u);
}

TEST(Placements, MalformedDatagramsAreRefusedAndChangeNothing) {
    Link link(40, 0);
    const State now = link.step();
    const auto datagrams = link.host.encode(9, now, 100000);
    ASSERT_EQ(datagrams.size(), 1u);
    const std::vector<std::uint8_t>& d = datagrams[0];
    for (std::size_t n = 0; n < d.size(); ++n) {
        std::uint64_t f = 0;
        std::vector<DecodedPlacement> out;
        EXPECT_FALSE(link.client.decode(d.data(), n, f, out)) << "truncated to " << n;
        EXPECT_TRUE(out.empty());
    }
    std::vector<std::uint8_t> longer = d;
    longer.push_back(0);
    std::uint64_t f = 0;
    std::vector<DecodedPlacement> out;
    EXPECT_FALSE(link.client.decode(longer.data(), longer.size(), f, out));
    EXPECT_EQ(link.client.latest(), 0u) << "nothing acknowledged";
    const PlacementDecoder pristine = link.client;
    Rng rng(1);
    for (int i = 0; i < 20000; ++i) { // flipped bytes: refused or decoded, never a crash
        std::vector<std::uint8_t> bad = d;
        bad[1 + rng.below(bad.size() - 1)] ^= static_cast<std::uint8_t>(1 + rng.below(255));
        out.clear();
        (void)link.client.decode(bad.data(), bad.size(), f, out);
    }
    PlacementDecoder again = pristine;
    out.clear();
    ASSERT_TRUE(again.decode(d.data(), d.size(), f, out));
    ASSERT_EQ(out.size(), 40u);
    for (std::size_t i = 0; i < out.size(); ++i)
        EXPECT_EQ(out[i].q, now[i].second);
}

} // namespace
} // namespace rubble
