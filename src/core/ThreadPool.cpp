#include "rubble/core/ThreadPool.hpp"

#include <algorithm>

namespace rubble {

int ThreadPool::defaultWorkerCount() {
    const int hw = static_cast<int>(std::thread::hardware_concurrency());
    return std::max(1, hw - 1);
}

ThreadPool::ThreadPool(int workers) {
    const int n = workers > 0 ? workers : defaultWorkerCount();
    threads_.reserve(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i)
        threads_.emplace_back([this] { run(); });
}

ThreadPool::~ThreadPool() {
    std::deque<std::function<void()>> dropped;
    {
        std::lock_guard lock(mutex_);
        stopping_ = true;
        dropped.swap(queue_);
    }
    wake_.notify_all();
    for (auto& t : threads_)
        t.join();
    idle_.notify_all();
    // `dropped` is destroyed here, outside the lock: captured state of never-run jobs is released.
}

void ThreadPool::submit(std::function<void()> job) {
    if (!job)
        return;
    {
        std::lock_guard lock(mutex_);
        if (stopping_)
            return;
        queue_.push_back(std::move(job));
    }
    wake_.notify_one();
}

int ThreadPool::workerCount() const {
    return static_cast<int>(threads_.size());
}

std::size_t ThreadPool::queued() const {
    std::lock_guard lock(mutex_);
    return queue_.size();
}

void ThreadPool::waitIdle() {
    std::unique_lock lock(mutex_);
    idle_.wait(lock, [this] { return (queue_.empty() && running_ == 0) || stopping_; });
}

void ThreadPool::run() {
    for (;;) {
        std::function<void()> job;
        {
            std::unique_lock lock(mutex_);
            wake_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
            if (stopping_)
                return;
            job = std::move(queue_.front());
            queue_.pop_front();
            ++running_;
        }
        try {
            job();
        } catch (...) {
            // A job must not take a worker down; errors are reported through the job's own result.
        }
        job = nullptr;
        {
            std::lock_guard lock(mutex_);
            --running_;
            if (queue_.empty() && running_ == 0)
                idle_.notify_all();
        }
    }
}

} // namespace rubble
