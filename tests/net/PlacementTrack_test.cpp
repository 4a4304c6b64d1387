// Where a client shows a body between and after the placements it received: carried on at its last velocity
// while no later publish has arrived, held once one has shown it at rest, and held before it began to move
// when every publish in between arrived without it.
#include "Track.hpp"

#include <gtest/gtest.h>

namespace rubble {
namespace {

using net::detail::PublishLog;
using net::detail::Track;

Frame at(double x) {
    Frame f;
    f.translation = {x, 0, 0};
    return f;
}

// A body moving 1 m per 6-frame publish along x, placed at frames 0, 6 and 12 (seqs 1-3).
struct Moving {
    Moving() {
        for (std::uint32_t k = 0; k < 3; ++k) {
            log.received(k + 1, 6.0 * k);
            track.add(6.0 * k, at(k), &log);
        }
    }
    PublishLog log;
    Track track;
};

TEST(PlacementTrack, ABodyShownPastItsNewestPlacementMovesOnUntilALaterPublishArrives) {
    Moving m;
    EXPECT_EQ(m.log.period(), 6);
    EXPECT_NEAR(m.track.at(9, &m.log).translation.x, 1.5, 1e-12) << "between two placements";
    EXPECT_NEAR(m.track.at(15, &m.log).translation.x, 2.5, 1e-12) << "no later publish yet: carried on";
    EXPECT_NEAR(m.track.at(24, &m.log).translation.x, 4.0, 1e-12) << "for two periods";
    EXPECT_NEAR(m.track.at(100, &m.log).translation.x, 2.0, 1e-12) << "then it has most likely stopped";
    EXPECT_NEAR(m.track.at(15).translation.x, 2.0, 1e-12) << "without the log: held";
    // The publish of frame 18 arrives without it, and the one of 24: it did not move, it is held.
    m.log.received(4, 18);
    m.log.received(5, 24);
    EXPECT_NEAR(m.track.at(15, &m.log).translation.x, 2.0, 1e-12);
    // Had the datagram of frame 18 been lost, it might be moving still.
    Moving lost;
    lost.log.received(5, 24);
    EXPECT_NEAR(lost.track.at(15, &lost.log).translation.x, 2.5, 1e-12);
}

TEST(PlacementTrack, ABodyThatStartsMovingIsHeldUntilThePublishBeforeIt) {
    // At rest at x = 0 from frame 0; publishes at 6, 12, 18 and 24 came without it; at 30 it is at x = 1.
    PublishLog log;
    Track track;
    log.received(1, 0);
    track.add(0, at(0), &log);
    for (std::uint32_t k = 1; k <= 4; ++k)
        log.received(k + 1, 6.0 * k);
    log.received(6, 30);
    track.add(30, at(1), &log);
    EXPECT_NEAR(track.at(27, &log).translation.x, 0.5, 1e-12) << "it moved between 24 and 30";
    EXPECT_NEAR(track.at(12, &log).translation.x, 0.0, 1e-12);
    // When one of those publishes was lost, it may have moved earlier: interpolated over the whole gap.
    PublishLog gap;
    Track spread;
    gap.received(1, 0);
    spread.add(0, at(0), &gap);
    gap.received(2, 6);
    gap.received(4, 18);
    gap.received(5, 24);
    gap.received(6, 30);
    spread.add(30, at(1), &gap);
    EXPECT_NEAR(spread.at(27, &gap).translation.x, 0.9, 1e-12);
}

TEST(PlacementTrack, TheLogKnowsWhichDatagramsArrived) {
    PublishLog log;
    EXPECT_EQ(log.period(), 0);
    EXPECT_EQ(log.newest(), -1);
    log.received(1, 0);
    log.received(2, 6);
    log.received(3, 6); // a second datagram of the same publish
    log.received(5, 12);
    EXPECT_EQ(log.period(), 6);
    EXPECT_EQ(log.newest(), 12);
    EXPECT_TRUE(log.arrivedAll(0, 6));
    EXPECT_FALSE(log.arrivedAll(6, 12)) << "seq 4 is missing";
    EXPECT_FALSE(log.arrivedAll(0, 20)) << "nothing arrived at or after 20 yet";
    log.received(4, 12); // late, reordered
    EXPECT_TRUE(log.arrivedAll(0, 12));
}

} // namespace
} // namespace rubble
