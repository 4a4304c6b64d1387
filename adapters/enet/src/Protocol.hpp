#pragma once
// Private: the messages of loopback multiplayer (docs/netplay.md) and ENet helpers.

#include <enet/enet.h>
#include <enet/time.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "rubble/core/Frame.hpp"
#include "rubble/core/Result.hpp"

namespace rubble::net::detail {

/// Message types (first byte of every packet; on channel 0, reliable and ordered, unless said).
enum class Message : std::uint8_t {
    Snapshot = 1,     ///< objects sent by id, then the compressed snapshot (JoinSnapshot.hpp)
    Events = 2,       ///< u32 count, then count × 48-byte journal events
    Sync = 3,         ///< u64 frame, u64 journal position, u64 geometry hash
    Ack = 4,          ///< client → host: u64 frame, u64 its geometry hash after that sync
    Placements = 5,   ///< channel 1, unreliable: u32 seq, then varints and records (Placements.hpp)
    PlacementAck = 6, ///< client → host, channel 1, unreliable: u32 latest seq, u32 mask of the 32 before
    Shot = 7,  ///< client → host: 3 f32 origin, 3 f32 velocity (the host checks it, then fires it or not)
    Hello = 8, ///< client → host, first: the objects it has (JoinSnapshot.hpp); the host answers a Snapshot
    SnapshotChunk =
        9, ///< channel 1: u32 transfer, u32 index, u32 total bytes, then a piece of a Snapshot message
    SnapshotAck = 10, ///< client → host, channel 1: u32 transfer, then one bit per chunk it has
    Resync = 11,      ///< client → host, once joined and far behind: as Hello; the host answers a Snapshot
    Frame = 12,       ///< channel 1, to a client not heard lately, every frame: u64 the host's frame
};

/// Appends a little-endian float.
inline void appendF32(std::vector<std::uint8_t>& out, float f) {
    std::uint32_t v;
    std::memcpy(&v, &f, 4);
    for (int i = 0; i < 4; ++i)
        out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}
/// Little-endian u32 at p.
inline std::uint32_t readU32(const std::uint8_t* p) {
    return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
           static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24;
}
/// Little-endian float at p.
inline float readF32(const std::uint8_t* p) {
    const std::uint32_t v = readU32(p);
    float f;
    std::memcpy(&f, &v, 4);
    return f;
}

/// Unit quaternion (x, y, z, w) of a rotation matrix.
inline std::array<double, 4> toQuaternion(const Mat3& r) {
    const auto& m = r.m;
    const double t = m[0][0] + m[1][1] + m[2][2];
    std::array<double, 4> q{};
    if (t > 0) {
        const double s = 0.5 / std::sqrt(t + 1);
        q = {(m[2][1] - m[1][2]) * s, (m[0][2] - m[2][0]) * s, (m[1][0] - m[0][1]) * s, 0.25 / s};
    } else if (m[0][0] > m[1][1] && m[0][0] > m[2][2]) {
        const double s = 2 * std::sqrt(1 + m[0][0] - m[1][1] - m[2][2]);
        q = {0.25 * s, (m[0][1] + m[1][0]) / s, (m[0][2] + m[2][0]) / s, (m[2][1] - m[1][2]) / s};
    } else if (m[1][1] > m[2][2]) {
        const double s = 2 * std::sqrt(1 + m[1][1] - m[0][0] - m[2][2]);
        q = {(m[0][1] + m[1][0]) / s, 0.25 * s, (m[1][2] + m[2][1]) / s, (m[0][2] - m[2][0]) / s};
    } else {
        const double s = 2 * std::sqrt(1 + m[2][2] - m[0][0] - m[1][1]);
        q = {(m[0][2] + m[2][0]) / s, (m[1][2] + m[2][1]) / s, 0.25 * s, (m[1][0] - m[0][1]) / s};
    }
    return q;
}

/// Rotation matrix of a quaternion (normalised first).
inline Mat3 fromQuaternion(std::array<double, 4> q) {
    const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    for (double& c : q)
        c = n > 0 ? c / n : 0;
    if (n == 0)
        q[3] = 1;
    const double x = q[0], y = q[1], z = q[2], w = q[3];
    Mat3 r;
    r.m[0][0] = 1 - 2 * (y * y + z * z);
    r.m[0][1] = 2 * (x * y - z * w);
    r.m[0][2] = 2 * (x * z + y * w);
    r.m[1][0] = 2 * (x * y + z * w);
    r.m[1][1] = 1 - 2 * (x * x + z * z);
    r.m[1][2] = 2 * (y * z - x * w);
    r.m[2][0] = 2 * (x * z - y * w);
    r.m[2][1] = 2 * (y * z + x * w);
    r.m[2][2] = 1 - 2 * (x * x + y * y);
    return r;
}

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

/// Sends bytes unreliably (and unsequenced) on channel 1.
inline bool sendUnreliable(ENetPeer* peer, const std::vector<std::uint8_t>& bytes) {
    ENetPacket* p = enet_packet_create(bytes.data(), bytes.size(), ENET_PACKET_FLAG_UNSEQUENCED);
    if (!p)
        return false;
    if (enet_peer_send(peer, 1, p) != 0) {
        enet_packet_destroy(p);
        return false;
    }
    return true;
}

/// Bytes of a Snapshot message per SnapshotChunk (one datagram each).
inline constexpr std::size_t kSnapshotChunk = 1100;

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

/// Milliseconds without an answer after which a peer counts as gone (a partition shorter than this is
/// survived; a process killed without saying goodbye is noticed this late).
inline constexpr enet_uint32 kPeerTimeoutMs = 10000;
/// The data of a disconnect that a side sends on purpose (a timeout carries 0).
inline constexpr enet_uint32 kGoodbye = 1;

/// A peer for a link that misbehaves: unreliable packets are not throttled (placements keep their own byte
/// budget), and it counts as gone after timeoutMs without an answer.
inline void configurePeer(ENetPeer* peer, enet_uint32 timeoutMs = kPeerTimeoutMs) {
    enet_peer_timeout(peer, 0, timeoutMs, timeoutMs);
    enet_peer_throttle_configure(peer, ENET_PEER_PACKET_THROTTLE_INTERVAL, 0, 0);
}

/// How often a connection being made sends its handshake again while no answer comes (retryEvery).
inline constexpr enet_uint32 kHandshakeRetryMs = 500;

/// The peer's unacknowledged reliable commands go out again `everyMs` after they were last sent (at the
/// first service from then), instead of after ENet's timers, which double at every loss.
inline void retryEvery(ENetPeer* peer, enet_uint32 everyMs) {
    for (ENetListIterator it = enet_list_begin(&peer->sentReliableCommands);
         it != enet_list_end(&peer->sentReliableCommands); it = enet_list_next(it)) {
        auto* c = reinterpret_cast<ENetOutgoingCommand*>(it);
        c->roundTripTimeout = std::min(c->roundTripTimeout, everyMs);
        if (ENET_TIME_LESS(c->sentTime + c->roundTripTimeout, peer->nextTimeout))
            peer->nextTimeout = c->sentTime + c->roundTripTimeout; // when ENet looks at its timers again
    }
}

/// After an outage, the peer's unacknowledged reliable commands are sent again at the next service instead
/// of after their timers, which doubled at every retransmission during the outage.
inline void retransmitSoon(ENetPeer* peer) {
    retryEvery(peer, 1);
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
