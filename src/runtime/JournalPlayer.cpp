#include "rubble/runtime/JournalPlayer.hpp"

#include <string>

namespace rubble {

JournalPlayer::JournalPlayer(DestructionWorld& world) : world_(world) {}

Status JournalPlayer::apply(const JournalEvent& event) {
    Status s = world_.applyJournalEvent(event);
    if (s)
        ++applied_;
    return s;
}

Status JournalPlayer::receive(const JournalEvent& event) {
    const std::uint64_t frame = world_.frame();
    if (event.tick < frame || (!pending_.empty() && event.tick < pending_.back().tick))
        return Error{ErrorCode::InvalidInput, "journal event of tick " + std::to_string(event.tick) +
                                                  " arrived after frame " + std::to_string(frame) +
                                                  " had begun (events must come in journal order)"};
    const std::uint64_t previous = pending_.empty() ? frame : pending_.back().tick;
    if (event.tick - previous > kMaxJournalTickGap)
        return Error{ErrorCode::InvalidInput,
                     "journal event of tick " + std::to_string(event.tick) + " comes " +
                         std::to_string(event.tick - previous) + " frames after " +
                         (pending_.empty() ? "frame " : "the event of tick ") + std::to_string(previous) +
                         ", more than the limit of " + std::to_string(kMaxJournalTickGap) +
                         " frames (the journal is damaged)"};
    if (event.tick == frame && pending_.empty())
        return apply(event);
    pending_.push_back(event);
    return Status::ok();
}

Status JournalPlayer::step() {
    world_.beginFrame();
    for (const FractureOutcome& o : world_.collect()) {
        world_.commit(o);
        if (onOutcome_)
            onOutcome_(o);
    }
    while (!pending_.empty() && pending_.front().tick == world_.frame()) {
        const JournalEvent e = pending_.front();
        pending_.pop_front();
        if (Status s = apply(e); !s)
            return s;
    }
    return Status::ok();
}

Status JournalPlayer::advanceTo(std::uint64_t tick) {
    while (world_.frame() < tick)
        if (Status s = step(); !s)
            return s;
    return Status::ok();
}

Status JournalPlayer::drain() {
    while (!pending_.empty() || world_.jobsInFlight() > 0)
        if (Status s = step(); !s)
            return s;
    return Status::ok();
}

} // namespace rubble
