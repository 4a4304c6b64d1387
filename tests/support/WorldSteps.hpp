#pragma once
// A world without an engine: its splits are committed as soon as they are collected.

#include <vector>

#include "rubble/runtime/DestructionWorld.hpp"

namespace rubble {

/// DestructionWorld::collect(), each split committed at once; returns the splits.
inline std::vector<FractureOutcome> collectAndCommit(DestructionWorld& world) {
    std::vector<FractureOutcome> splits = world.collect();
    for (const FractureOutcome& s : splits)
        world.commit(s);
    return splits;
}

} // namespace rubble
