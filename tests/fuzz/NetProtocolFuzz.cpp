// Fuzz target: the netplay message decoders (adapters/enet: placements, journal events, placement acks,
// hello, join snapshot). The first byte picks what the rest is: a placements datagram for a decoder that
// holds baselines, an events message, or acknowledgements for an encoder with datagrams in flight (byte % 3);
// from 250 on, a client's hello (even) or a host's snapshot message for an empty world (odd). Decoding must
// never crash; an accepted placements datagram must decode the same again, and accepted events must encode
// back to the same bytes when their fields are in range.
#include <cstdint>
#include <cstdio>
#include <vector>

#include "Events.hpp"
#include "FuzzInput.hpp"
#include "JoinSnapshot.hpp"
#include "Placements.hpp"
#include "Protocol.hpp"

namespace {

using namespace rubble;
using namespace rubble::net::detail;

[[noreturn]] void fail(const char* what) {
    std::fprintf(stderr, "NetProtocolFuzz: %s\n", what);
    __builtin_trap();
}

Quantized state(std::uint32_t i) {
    Quantized q;
    q.p[0] = i * 1000;
    q.p[1] = -static_cast<std::int64_t>(i);
    q.p[2] = 7;
    q.q = i * 2654435761u;
    return q;
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    fuzz::FuzzInput in(data, size);
    const std::uint8_t first = in.byte();
    const int mode = first >= 250 ? 3 + first % 2 : first % 3;
    const std::uint8_t* body = data + (size > 0 ? 1 : 0);
    const std::size_t n = size > 0 ? size - 1 : 0;
    if (mode == 0) {
        PlacementDecoder decoder;
        for (std::uint32_t id = 1; id <= 8; ++id)
            decoder.setBaseline(id, state(id));
        const PlacementDecoder before = decoder;
        std::uint64_t frame = 0;
        std::vector<DecodedPlacement> out;
        if (decoder.decode(body, n, frame, out)) {
            PlacementDecoder again = before;
            std::uint64_t frame2 = 0;
            std::vector<DecodedPlacement> out2;
            if (!again.decode(body, n, frame2, out2) || frame2 != frame || out2.size() != out.size())
                fail("an accepted placements datagram decodes differently the second time");
            for (const DecodedPlacement& r : out)
                (void)dequantize(r.q);
        } else if (!out.empty()) {
            fail("a refused placements datagram added placements");
        }
    } else if (mode == 1) {
        std::vector<WireEvent> out;
        if (decodeEvents(body, n, out)) {
            std::vector<JournalEvent> events;
            for (const WireEvent& w : out)
                events.push_back(w.event);
            if (n >= 2 && !events.empty()) {
                std::uint64_t frame = 0;
                const std::uint8_t* p = body + 1;
                (void)getVarint(p, body + n, frame);
                (void)encodeEvents(frame, events.data(), events.size());
            }
        } else if (!out.empty()) {
            fail("a refused events message added events");
        }
    } else if (mode == 3) {
        KnownObjects known, again;
        const bool resync = n > 0 && body[0] == static_cast<std::uint8_t>(Message::Resync); // as a Hello
        if (decodeHello(body, n, known, resync) && (!decodeHello(body, n, again, resync) || again != known))
            fail("an accepted hello decodes differently the second time");
    } else if (mode == 4) {
        static DestructionWorld empty([] {
            DestructionWorld::Config c;
            c.workers = 1;
            c.deterministic = true;
            return c;
        }());
        (void)decodeJoinSnapshot(body, n, empty);
    } else {
        PlacementEncoder encoder;
        std::vector<std::pair<ObjectId, Quantized>> now;
        for (std::uint32_t id = 1; id <= 200; ++id)
            now.emplace_back(id, state(id + in.byte()));
        for (int round = 0; round < 4; ++round)
            (void)encoder.encode(static_cast<std::uint64_t>(round), now, 1 + in.u64() % 5000);
        while (in.more()) { // a client's acknowledgements: any values
            const auto latest = static_cast<std::uint32_t>(in.u64());
            encoder.acked(latest, static_cast<std::uint32_t>(in.u64()));
        }
        (void)encoder.encode(9, now, 3000);
    }
    return 0;
}
