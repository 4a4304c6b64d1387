#pragma once
// Private: journal events on the wire (docs/netplay.md, 'Events'): ids and ticks as varints, the impact's
// seven floats as they are, and one check byte in place of the fields a client can compute itself.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "rubble/runtime/Journal.hpp"

namespace rubble::net::detail {

/// A journal event as a client receives it: pattern, cells and seed are left for it to fill in when it
/// applies the event, and `check` must then match them.
struct WireEvent {
    JournalEvent event;
    std::uint8_t check = 0;
};

/// One byte of the fields a client fills in itself (pattern, cells, next job seed).
std::uint8_t eventCheck(const JournalEvent& e);
/// An Events message (type byte first) for events whose ticks are at most `frame`.
std::vector<std::uint8_t> encodeEvents(std::uint64_t frame, const JournalEvent* events, std::size_t count);
/// Decodes an Events message; false (and nothing added) for a malformed one.
bool decodeEvents(const std::uint8_t* data, std::size_t size, std::vector<WireEvent>& out);

} // namespace rubble::net::detail
