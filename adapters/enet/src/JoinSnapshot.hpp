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
/// objectStateHash of objects by id, with the version it was taken at (an object changes only with its
/// version).
using StateHashes = std::map<ObjectId, std::pair<std::uint32_t, std::uint64_t>>;
/// objectStateHash(object), from `cache` when it holds the object's version (then kept there).
std::uint64_t stateHash(const ObjectState& object, StateHashes* cache);

/// An object's record in a snapshot's bytes, compressed on its own (a Zstandard frame), by version.
struct PackedObject {
    std::uint32_t version = 0;
    std::size_t raw = 0;            ///< bytes of the record
    std::uint32_t crc = 0;          ///< their CRC-32
    std::vector<std::uint8_t> zstd; ///< the frame
};
/// Packed objects by id: a snapshot compresses only objects it does not hold in their version.
using PackedObjects = std::map<ObjectId, PackedObject>;
/// Packs an object into `cache` unless it holds its version; false when compression failed.
bool packObject(const ObjectState& object, PackedObjects& cache);

/// A Hello message (type byte first): the world's objects and their state hashes; with `resync`, a Resync
/// message (a joined client far behind): its journal position first, then the same.
std::vector<std::uint8_t> encodeHello(const DestructionWorld& world, bool resync = false,
                                      StateHashes* cache = nullptr);
/// Decodes a Hello (with `resync`, a Resync, whose journal position goes to `position`) message; false (out
/// unchanged) for a malformed one.
bool decodeHello(const std::uint8_t* data, std::size_t size, KnownObjects& out, bool resync = false,
                 std::uint64_t* position = nullptr);

/// Sizes of a join snapshot, and the time its encoding took.
struct JoinSnapshotSize {
    std::size_t raw = 0;        ///< encodeSnapshot bytes of the objects sent
    std::size_t wire = 0;       ///< the message
    std::size_t referenced = 0; ///< objects sent by id
    std::size_t sent = 0;       ///< objects in the compressed snapshot
    std::size_t packed = 0;     ///< of those, compressed for this message (the rest came from the cache)
    double encodeMs = 0;        ///< encodeSnapshot (ms)
    double compressMs = 0;      ///< compressing it (ms)
};
/// How the rest of the snapshot is compressed.
enum class SnapshotCodec : std::uint8_t {
    Deflate = 0, ///< zlib, level 1
    Zstd = 1,    ///< Zstandard, level 3: a third smaller than Deflate, and faster
};
/// What a client that has `known` lacks of a world: the world's snapshot without objects, the objects it
/// lacks where the world keeps them (not copied), and the ids of those it has.
struct JoinCapture {
    Snapshot rest;                        ///< settings, counters, work and placements; no objects
    std::vector<const ObjectState*> sent; ///< the objects it lacks, ascending id: valid while they are
    std::vector<ObjectId> byId;           ///< the objects it has in the same state, ascending
    std::vector<ObjectState> owned;       ///< what `sent` points into when it is not a world
};
/// The capture for a client that has `known` (hashes from `cache`, when given): valid until the world
/// changes.
JoinCapture captureJoin(const DestructionWorld& world, const KnownObjects& known,
                        std::vector<ObjectPlacement> placements, StateHashes* cache = nullptr);
/// The Snapshot message of a capture (as encodeJoinSnapshot below).
std::vector<std::uint8_t> encodeJoin(JoinCapture capture, JoinSnapshotSize* size = nullptr,
                                     SnapshotCodec codec = SnapshotCodec::Zstd,
                                     PackedObjects* packed = nullptr);
/// A Snapshot message (type byte first) for a client that has `known` (hashes from `cache`, when given).
/// With `packed` (and Zstandard), the compressed snapshot is a Zstandard frame of the header, one per object
/// record, from `packed` when it holds the object's version (else packed and kept there), and one of the
/// rest: the same bytes once decompressed.
std::vector<std::uint8_t> encodeJoinSnapshot(Snapshot snapshot, const KnownObjects& known,
                                             JoinSnapshotSize* size = nullptr,
                                             SnapshotCodec codec = SnapshotCodec::Zstd,
                                             StateHashes* cache = nullptr, PackedObjects* packed = nullptr);
/// Decodes a Snapshot message, taking the objects sent by id from `world` (which must have them).
Result<Snapshot> decodeJoinSnapshot(const std::uint8_t* data, std::size_t size,
                                    const DestructionWorld& world);

} // namespace rubble::net::detail
