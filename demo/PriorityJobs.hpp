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
    /// Wall-clock and thread CPU time the workers spent in jobs so far (ms): their ratio is the share of a
    /// core a running job got.
    double busyMs() const { return static_cast<double>(busyUs_.load()) / 1000.0; }
    double cpuMs() const { return static_cast<double>(cpuUs_.load()) / 1000.0; }

private:
    void prepareThread();

    int nice_;
    std::atomic<int> raised_{0};
    std::atomic<int> refused_{0};
    std::atomic<long long> busyUs_{0};
    std::atomic<long long> cpuUs_{0};
    rubble::ThreadPool pool_; // last: its workers stop before the counters go
};

} // namespace demo
