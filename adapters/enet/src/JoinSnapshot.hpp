#pragma once
// Private: what a joining client announces (Hello) and the snapshot it gets back (docs/netplay.md, 'Late
// join'): objects the client has already, in the same state, go by id; the rest is the snapshot, compressed.

#include <cstddef>
#include <cstdint>
#include <map>
#include <vector>

#include "rubble/core/Result.hpp"
#include "rubble/persist/Snapshot.hpp"
#include "rubble/runtime/DestructionWorld.hpp"

namespace rubble::net::detail {

/// Objects a client has: id → objectStateHash.
using KnownObjects = std::map<ObjectId, std::uint64_t>;

/// A Hello message (type byte first): the world's objects and their state hashes.
std::vector<std::uint8_t> encodeHello(const DestructionWorld& world);
/// Decodes a Hello message; false (out unchanged) for a malformed one.
bool decodeHello(const std::uint8_t* data, std::size_t size, KnownObjects& out);

/// Sizes of a join snapshot.
struct JoinSnapshotSize {
    std::size_t raw = 0;        ///< encodeSnapshot bytes of the objects sent
    std::size_t wire = 0;       ///< the message
    std::size_t referenced = 0; ///< objects sent by id
};
/// How the rest of the snapshot is compressed.
enum class SnapshotCodec : std::uint8_t {
    Deflate = 0, ///< zlib, level 1
    Zstd = 1,    ///< Zstandard, level 3: a third smaller than Deflate, and faster
};
/// A Snapshot message (type byte first) for a client that has `known`.
std::vector<std::uint8_t> encodeJoinSnapshot(Snapshot snapshot, const KnownObjects& known,
                                             JoinSnapshotSize* size = nullptr,
                                             SnapshotCodec codec = SnapshotCodec::Zstd);
/// Decodes a Snapshot message, taking the objects sent by id from `world` (which must have them).
Result<Snapshot> decodeJoinSnapshot(const std::uint8_t* data, std::size_t size,
                                    const DestructionWorld& world);

} // namespace rubble::net::detail
