#include "Events.hpp"

#include <cstring>

#include "Placements.hpp"
#include "Protocol.hpp"
#include "rubble/core/Random.hpp"

namespace rubble::net::detail {

namespace {

void putF32(std::vector<std::uint8_t>& out, float f) {
    std::uint32_t v;
    std::memcpy(&v, &f, 4);
    for (int i = 0; i < 4; ++i)
        out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}

} // namespace

std::uint8_t eventCheck(const JournalEvent& e) {
    return static_cast<std::uint8_t>(mixSeed(mixSeed(e.pattern, e.cells), e.seed));
}

std::vector<std::uint8_t> encodeEvents(std::uint64_t frame, const JournalEvent* events, std::size_t count) {
    std::vector<std::uint8_t> out{static_cast<std::uint8_t>(Message::Events)};
    putVarint(out, frame);
    putVarint(out, count);
    for (std::size_t i = 0; i < count; ++i) {
        const JournalEvent& e = events[i];
        const bool impact = e.kind == JournalEventKind::Impact;
        putVarint(out, std::uint64_t{e.object} << 1 | (impact ? 0 : 1));
        putVarint(out, frame - e.tick);
        if (!impact)
            continue;
        for (float f : e.point)
            putF32(out, f);
        for (float f : e.normal)
            putF32(out, f);
        putF32(out, e.impulse);
        out.push_back(eventCheck(e));
    }
    return out;
}

bool decodeEvents(const std::uint8_t* data, std::size_t size, std::vector<WireEvent>& out) {
    if (size < 1 || data[0] != static_cast<std::uint8_t>(Message::Events))
        return false;
    const std::uint8_t *p = data + 1, *end = data + size;
    std::uint64_t frame = 0, count = 0;
    if (!getVarint(p, end, frame) || !getVarint(p, end, count) || count > size)
        return false;
    std::vector<WireEvent> events;
    for (std::uint64_t i = 0; i < count; ++i) {
        std::uint64_t head = 0, back = 0;
        if (!getVarint(p, end, head) || !getVarint(p, end, back) || (head >> 1) > 0xFFFFFFFFu ||
            back > frame || frame - back > 0xFFFFFFFFu)
            return false;
        WireEvent w;
        w.event.object = static_cast<std::uint32_t>(head >> 1);
        w.event.tick = static_cast<std::uint32_t>(frame - back);
        w.event.kind = head & 1 ? JournalEventKind::Remove : JournalEventKind::Impact;
        if (w.event.kind == JournalEventKind::Impact) {
            if (end - p < 29)
                return false;
            float floats[7];
            for (float& f : floats) {
                f = readF32(p);
                p += 4;
            }
            w.event.point = {floats[0], floats[1], floats[2]};
            w.event.normal = {floats[3], floats[4], floats[5]};
            w.event.impulse = floats[6];
            w.check = *p++;
        }
        events.push_back(w);
    }
    if (p != end)
        return false;
    out.insert(out.end(), events.begin(), events.end());
    return true;
}

} // namespace rubble::net::detail
