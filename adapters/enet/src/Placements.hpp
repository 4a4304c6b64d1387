#pragma once
// Private: placement compression (docs/netplay.md, 'Placements'): positions quantized to 1 mm, rotations as
// smallest-three quaternions in 32 bits, delta-coded against the latest state the client acknowledged, only
// for bodies whose quantized state changed, chosen by a priority accumulator within a byte budget.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <map>
#include <vector>

#include "rubble/core/Frame.hpp"
#include "rubble/runtime/DestructionWorld.hpp"

namespace rubble::net::detail {

/// A placement on the wire's grid: position in millimetres, rotation as smallest-three (2 + 3 × 10 bits).
struct Quantized {
    std::int64_t p[3] = {0, 0, 0};
    std::uint32_t q = 0;
    bool operator==(const Quantized&) const = default;
};

/// The grid point nearest a frame.
Quantized quantize(const Frame& f);
/// The frame of a grid point.
Frame dequantize(const Quantized& q);

/// Seqs a baseline may be old; older ones are not used (the state is sent whole).
inline constexpr std::uint32_t kBaselineWindow = 128;
/// Encodes after which a datagram not acknowledged counts as lost.
inline constexpr std::uint64_t kInFlightEncodes = 5;
/// Largest placements datagram (one UDP datagram on any link).
inline constexpr std::size_t kMaxPlacementDatagram = 1200;

/// A client's allowance of placement bytes per publish: `mean` on average, at most `peak` at once; what quiet
/// publishes leave unspent is saved, up to `reserve`, for when many bodies move. It starts full: a client
/// that just joined has every body that moved during its snapshot's transfer to catch up on.
class PlacementAllowance {
public:
    PlacementAllowance(std::size_t mean, std::size_t peak, std::size_t reserve)
        : mean_(mean), peak_(std::max(peak, mean)), reserve_(std::max(reserve, mean)), credit_(reserve_) {}
    /// Bytes the next publish may spend (its share added to the credit first).
    std::size_t next() {
        credit_ = std::min(credit_ + mean_, reserve_);
        return std::min(credit_, peak_);
    }
    /// What that publish spent.
    void spent(std::size_t bytes) { credit_ -= std::min(credit_, bytes); }

private:
    std::size_t mean_, peak_, reserve_;
    std::size_t credit_;
};

/// The host's side for one client: what it acknowledged, what is in flight, and each body's priority.
class PlacementEncoder {
public:
    /// A state the client has without being sent it (from its snapshot), at seq 0.
    void setBaseline(ObjectId id, const Quantized& q);
    /// The datagrams (message type byte first) for the bodies in `now` whose state differs from the
    /// client's acknowledged one, the largest errors first, within `budget` bytes in all. A body's error is
    /// its distance from the state the client has or is being sent (unless that datagram seems lost), and
    /// its priority accumulates 1 + that error in cm per encode until it is sent.
    std::vector<std::vector<std::uint8_t>>
    encode(std::uint64_t frame, const std::vector<std::pair<ObjectId, Quantized>>& now, std::size_t budget);
    /// The client acknowledged seq `latest` and, by bit i of mask, seq latest - 1 - i.
    void acked(std::uint32_t latest, std::uint32_t mask);
    /// Bodies whose state the client does not have yet.
    std::size_t behind() const { return behind_; }
    /// Of those, the bodies the last encode() left out for the budget.
    std::size_t deferred() const { return deferred_; }

private:
    struct Body {
        bool hasBase = false;
        std::uint32_t baseSeq = 0;
        Quantized base;
        double priority = 0;
        std::uint32_t sentSeq = 0; // the latest datagram it went in, unless acknowledged or lost (0: none)
        Quantized sent;            // the state it carried
        std::uint64_t sentAt = 0;  // the encode() that sent it
    };
    std::map<ObjectId, Body> bodies_;
    std::map<std::uint32_t, std::vector<std::pair<ObjectId, Quantized>>> pending_; // seq → states sent in it
    std::uint32_t seq_ = 0;
    std::uint64_t encodes_ = 0;
    std::size_t behind_ = 0;
    std::size_t deferred_ = 0;
};

/// One body's state decoded from a placements datagram.
struct DecodedPlacement {
    ObjectId id = 0;
    Quantized q;
};

/// The client's side: the states it received (the baselines the host may refer to) and its acknowledgements.
class PlacementDecoder {
public:
    /// A state it has without being sent it (from its snapshot), at seq 0.
    void setBaseline(ObjectId id, const Quantized& q);
    /// Decodes a placements datagram (type byte first). False for a malformed one, which changes nothing;
    /// records whose baseline it no longer has are left out (and the datagram is not acknowledged).
    bool decode(const std::uint8_t* data, std::size_t size, std::uint64_t& frame,
                std::vector<DecodedPlacement>& out);
    /// The latest seq received and whole.
    std::uint32_t latest() const { return latest_; }
    /// Bit i: seq latest - 1 - i was received whole.
    std::uint32_t mask() const { return mask_; }

private:
    std::map<ObjectId, std::map<std::uint32_t, Quantized>> history_;
    std::uint32_t latest_ = 0;
    std::uint32_t mask_ = 0;
    std::uint32_t pruned_ = 0; // latest_ at the last pruning
};

/// Appends an unsigned LEB128 varint.
void putVarint(std::vector<std::uint8_t>& out, std::uint64_t v);
/// Reads a varint at p (advancing it); false past end or beyond 10 bytes.
bool getVarint(const std::uint8_t*& p, const std::uint8_t* end, std::uint64_t& v);

} // namespace rubble::net::detail
