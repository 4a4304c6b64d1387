#pragma once
/// \file JobSeed.hpp
/// The seed of a fracture job, as a DestructionWorld derives it: a journal records it, and whoever replays a
/// world's events (a JournalPlayer, a netplay client) derives the same one.

#include <cstdint>

#include "rubble/core/Random.hpp"

namespace rubble {

/// The seed of the next fracture job on an object (its id and version) in a world of seed `worldSeed`.
inline std::uint64_t jobSeed(std::uint64_t worldSeed, std::uint32_t object, std::uint32_t version) {
    return mixSeed(mixSeed(worldSeed, object), version);
}

} // namespace rubble
