#pragma once
// Private: a world's snapshot that reads its objects where the world keeps them instead of copying them
// (netplay: a join snapshot of the objects a client lacks).

#include <cstdint>
#include <vector>

#include "rubble/persist/Snapshot.hpp"

namespace rubble::detail {

/// A world's state with its objects in place: valid until the world changes.
struct StateInPlace {
    WorldState rest; ///< captureState(world) without its objects
    std::vector<const ObjectState*>
        objects; ///< the world's objects, ascending id, as captureState gives them
};
/// The world's state, its objects not copied (their mesh hashes computed first, as captureState does).
StateInPlace captureInPlace(const DestructionWorld& world);
/// encodeSnapshot(snapshot) with `objects` as its objects (snapshot.world.objects is not read): the same
/// bytes.
std::vector<std::uint8_t> encodeSnapshotWith(const Snapshot& snapshot,
                                             const std::vector<const ObjectState*>& objects);

} // namespace rubble::detail
