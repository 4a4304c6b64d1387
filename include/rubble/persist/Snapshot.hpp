#pragma once
/// \file Snapshot.hpp
/// Snapshots of a destroyed world: a versioned, checksummed binary format holding every object's mesh,
/// convex parts, mass properties, material and fracture settings, the world's decomposition settings, the
/// bodies' placements and velocities, the runtime's volume ledger and structure (each node's solid, material
/// and root state; each bond's health and broken state), the unadopted work and the journal position (layout
/// in docs/journal.md).

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "rubble/core/Export.hpp"
#include "rubble/core/Result.hpp"
#include "rubble/persist/WorldState.hpp"

namespace rubble {

/// A saved world.
struct RUBBLE_API Snapshot {
    WorldState world;                        ///< settings, objects, frame, ids, journal position, work
    std::vector<ObjectPlacement> placements; ///< bodies (empty for a world without an engine)
    VolumeLedger volumes;     ///< where removed volume went (retired, dust, dropped; live unused)
    StructureState structure; ///< the stress solver's nodes and bonds (saved false: none, rebuilt fresh)
};

/// The snapshot of a world (and of its bodies, when placements are given).
RUBBLE_API Snapshot takeSnapshot(const DestructionWorld& world, std::vector<ObjectPlacement> placements = {});
/// The snapshot of a runtime: its world, its bodies' placements, its volume ledger and its structure.
RUBBLE_API Snapshot takeSnapshot(const DestructionRuntime& runtime);
/// Loads a snapshot into a world (any worker count; the world adopts the snapshot's settings); fails,
/// changing nothing, when the state is inconsistent (restoreState).
RUBBLE_API Status restoreSnapshot(DestructionWorld& world, Snapshot snapshot);
/// Loads a snapshot into a runtime (restoreState of the runtime): its world and the bodies of its objects;
/// fails, changing nothing, like restoreSnapshot(world, ...) or when the placements do not match the objects.
RUBBLE_API Status restoreSnapshot(DestructionRuntime& runtime, Snapshot snapshot);

/// A 64-bit hash of everything a snapshot stores of an object (its bytes there): two states with equal hashes
/// are interchangeable, e.g. a scene object a joining client loaded itself (netplay).
RUBBLE_API std::uint64_t objectStateHash(const ObjectState& object);
/// The snapshot's bytes.
RUBBLE_API std::vector<std::uint8_t> encodeSnapshot(const Snapshot& snapshot);
/// Parses a snapshot; a truncated, corrupted, wrong-version or hostile input gives an error naming source,
/// offset and field (checksum first, then every count against the bytes left, every index and number).
RUBBLE_API Result<Snapshot> decodeSnapshot(const std::uint8_t* data, std::size_t size,
                                           const std::string& source);
/// Writes a snapshot atomically (temporary file, fsync, rename).
RUBBLE_API Status saveSnapshot(const std::filesystem::path& path, const Snapshot& snapshot);
/// Reads a snapshot file: a regular file of at most 2 GiB (devices, FIFOs and sockets are refused without
/// blocking).
RUBBLE_API Result<Snapshot> loadSnapshot(const std::filesystem::path& path);

} // namespace rubble
