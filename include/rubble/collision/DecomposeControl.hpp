#pragma once
/// \file DecomposeControl.hpp
/// Threads, progress and cancelling for a long decomposition (rubble/collision/ConvexDecomposition.hpp).

#include <atomic>
#include <functional>

#include "rubble/collision/ConvexDecomposition.hpp"
#include "rubble/core/Export.hpp"
#include "rubble/core/JobSystem.hpp"

namespace rubble {

/// How decompose() shares its work, reports progress and learns that it should stop.
struct RUBBLE_API DecomposeControl {
    /// Runs the candidate cuts, depth measures and final part shapes in parallel with the calling thread
    /// (null: the calling thread alone). The parts do not depend on it; busy workers, or the pool the caller
    /// itself runs on, never make the call wait (the caller does what no worker took).
    JobSystem* jobs = nullptr;
    /// Called on the calling thread with the fraction done: non-decreasing, in [0, 1], 1 last on success.
    /// Returning false cancels.
    std::function<bool(double)> progress;
    /// Cancels when it becomes true (it may be set from any thread or a signal handler).
    const std::atomic<bool>* cancel = nullptr;
};

/// decompose() under control: ErrorCode::Cancelled when cancelled (nothing else is changed or returned).
RUBBLE_API Result<Decomposition> decompose(const Mesh& mesh, const DecompositionParams& params,
                                           const DecomposeControl& control);

} // namespace rubble
