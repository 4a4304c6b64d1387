#pragma once
/// \file JournalPlayer.hpp
/// Drives a DestructionWorld from journal events: a replay, or a network client following a host.

#include <cstdint>
#include <deque>
#include <functional>

#include "rubble/core/Export.hpp"
#include "rubble/runtime/DestructionWorld.hpp"
#include "rubble/runtime/Journal.hpp"

namespace rubble {

/// Most frames between a journal event and the one before it (or the frame a replay starts from): 2^22, about
/// 19 hours at 60 frames per second. A larger gap is a damaged journal: stepping through 2^32 frames takes
/// hours.
inline constexpr std::uint64_t kMaxJournalTickGap = std::uint64_t{1} << 22;

/// Applies journal events to a world at the frames they were recorded in. The world must be built from the
/// same scene with the same Config (deterministic, same seed and delayFrames) as the one that recorded them.
/// An event of tick t was recorded while the recording world's frame() was t, after that frame's collect();
/// the player reproduces that order, so the geometry is the same on any worker count.
class RUBBLE_API JournalPlayer {
public:
    /// A player for world (which it steps; nothing else should step it meanwhile).
    explicit JournalPlayer(DestructionWorld& world);

    /// Takes the next event in journal order: applied now when its tick is the world's frame, kept until
    /// advanceTo() reaches it when later. An event of an earlier tick, one more than kMaxJournalTickGap
    /// frames after the previous event (or the world's frame), or one the world refuses
    /// (DestructionWorld::applyJournalEvent), is an error and changes nothing.
    Status receive(const JournalEvent& event);
    /// Steps the world (beginFrame, collect and commit, then the kept events of the new frame) until frame()
    /// == tick.
    Status advanceTo(std::uint64_t tick);
    /// Steps until no job is in flight and no event is kept.
    Status drain();
    /// Events applied so far.
    std::uint64_t applied() const { return applied_; }
    /// Events kept for a later frame.
    std::size_t pending() const { return pending_.size(); }
    /// Called for every outcome collected while stepping (its pieces are in the world already).
    void setOnOutcome(std::function<void(const FractureOutcome&)> callback) {
        onOutcome_ = std::move(callback);
    }

private:
    Status step();
    Status apply(const JournalEvent& event);

    DestructionWorld& world_;
    std::deque<JournalEvent> pending_;
    std::uint64_t applied_ = 0;
    std::function<void(const FractureOutcome&)> onOutcome_;
};

} // namespace rubble
