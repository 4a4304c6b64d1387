#pragma once
/// \file JobSystem.hpp
/// The abstract job system fracture work runs on; ThreadPool is its default implementation.

#include <functional>

#include "rubble/core/Export.hpp"

namespace rubble {

/// Runs jobs off the calling thread. Implement this to run Rubble's work on a game's own scheduler.
class RUBBLE_API JobSystem {
public:
    virtual ~JobSystem() = default;
    /// Schedules job to run once on some worker thread. Must be thread-safe.
    virtual void submit(std::function<void()> job) = 0;
    /// Number of threads that run jobs concurrently.
    virtual int workerCount() const = 0;
};

} // namespace rubble
