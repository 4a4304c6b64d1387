#pragma once
/// \file PriorityJobs.hpp
/// The fracture workers' job system: rubble's ThreadPool whose worker threads run at a chosen niceness, so
/// that on a small machine fracture jobs run before software GL's rasteriser threads.

#include <atomic>
#include <functional>

#include "rubble/core/ThreadPool.hpp"

namespace demo {

/// A JobSystem over rubble::ThreadPool; each worker sets its niceness before its first job.
class PriorityJobs final : public rubble::JobSystem {
public:
    /// `workers` threads (<= 0: hardware threads − 1) at niceness `nice` (0: unchanged; below 0 needs
    /// CAP_SYS_NICE or RLIMIT_NICE, else the worker stays at 0).
    PriorityJobs(int workers, int nice);
    void submit(std::function<void()> job) override;
    int workerCount() const override { return pool_.workerCount(); }
    /// The niceness asked for.
    int nice() const { return nice_; }
    /// Workers that run at the asked niceness so far, and workers the system refused it.
    int raised() const { return raised_.load(); }
    int refused() const { return refused_.load(); }

private:
    void prepareThread();

    int nice_;
    std::atomic<int> raised_{0};
    std::atomic<int> refused_{0};
    rubble::ThreadPool pool_; // last: its workers stop before the counters go
};

} // namespace demo
