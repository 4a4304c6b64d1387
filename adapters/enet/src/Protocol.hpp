#pragma once
// Private: the messages of loopback multiplayer (docs/netplay.md) and ENet helpers.

#include <enet/enet.h>

#include <cstdint>
#include <string>
#include <vector>

#include "rubble/Result.hpp"

namespace rubble::net::detail {

/// Message types (first byte of every packet; all on channel 0, reliable and ordered).
enum class Message : std::uint8_t {
    Snapshot = 1, ///< the snapshot bytes (rubble/Snapshot.hpp)
    Events = 2,   ///< u32 count, then count × 48-byte journal events
    Sync = 3,     ///< u64 frame, u64 journal position, u64 geometry hash
    Ack = 4,      ///< client → host: u64 frame, u64 its geometry hash after that sync
};

/// Little-endian u64 at p.
inline std::uint64_t readU64(const std::uint8_t* p) {
    std::uint64_t v = 0;
    for (int i = 0; i < 8; ++i)
        v |= static_cast<std::uint64_t>(p[i]) << (8 * i);
    return v;
}
/// Appends a little-endian u64.
inline void appendU64(std::vector<std::uint8_t>& out, std::uint64_t v) {
    for (int i = 0; i < 8; ++i)
        out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}

/// Sends bytes reliably on channel 0.
inline bool sendReliable(ENetPeer* peer, const std::vector<std::uint8_t>& bytes) {
    ENetPacket* p = enet_packet_create(bytes.data(), bytes.size(), ENET_PACKET_FLAG_RELIABLE);
    if (!p)
        return false;
    if (enet_peer_send(peer, 0, p) != 0) {
        enet_packet_destroy(p);
        return false;
    }
    return true;
}

/// Resolves a loopback address (127.0.0.0/8, "localhost"); anything else is refused.
inline Result<ENetAddress> loopbackAddress(const std::string& name, std::uint16_t port) {
    ENetAddress a{};
    if (enet_address_set_host(&a, name.c_str()) != 0)
        return Error{ErrorCode::InvalidInput, "cannot resolve " + name};
    const auto* b = reinterpret_cast<const std::uint8_t*>(&a.host); // network byte order
    if (b[0] != 127)
        return Error{ErrorCode::InvalidInput,
                     name + " is not a loopback address: netplay sends only to 127.0.0.0/8"};
    a.port = port;
    return a;
}

/// Initialises ENet once per process.
inline void initialiseEnet() {
    static const int once = [] {
        const int r = enet_initialize();
        std::atexit(enet_deinitialize);
        return r;
    }();
    (void)once;
}

} // namespace rubble::net::detail
