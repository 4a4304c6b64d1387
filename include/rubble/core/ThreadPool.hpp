#pragma once
/// \file ThreadPool.hpp
/// The default JobSystem: a fixed set of std::thread workers taking jobs from one FIFO queue.

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include "rubble/core/Export.hpp"
#include "rubble/core/JobSystem.hpp"

namespace rubble {

/// A FIFO thread pool. Workers sleep on a condition variable (no busy waiting). Destruction finishes the jobs
/// that are running and DROPS the jobs still queued (their std::function is destroyed without being called),
/// so it never waits for a long backlog; call waitIdle() first to run everything.
class RUBBLE_API ThreadPool final : public JobSystem {
public:
    /// A pool with `workers` threads; workers <= 0 means hardware threads − 1, at least 1.
    explicit ThreadPool(int workers = -1);
    /// Finishes running jobs, drops queued ones, joins the workers.
    ~ThreadPool() override;
    ThreadPool(const ThreadPool&) = delete;
    ThreadPool& operator=(const ThreadPool&) = delete;

    /// Queues a job (FIFO). Thread-safe. Ignored after shutdown began.
    void submit(std::function<void()> job) override;
    /// Number of worker threads.
    int workerCount() const override;
    /// Blocks until the queue is empty and no job is running. Must not be called from a worker.
    void waitIdle();
    /// Jobs queued but not started.
    std::size_t queued() const;
    /// The default worker count: hardware threads − 1, at least 1.
    static int defaultWorkerCount();

private:
    void run();

    mutable std::mutex mutex_;
    std::condition_variable wake_;
    std::condition_variable idle_;
    std::deque<std::function<void()>> queue_;
    std::vector<std::thread> threads_;
    int running_ = 0;
    bool stopping_ = false;
};

} // namespace rubble
