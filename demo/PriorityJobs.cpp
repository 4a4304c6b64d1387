#include "PriorityJobs.hpp"

#include <pthread.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

#include <chrono>

namespace demo {

namespace {

/// This thread's CPU time (µs).
long long threadCpuUs() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return static_cast<long long>(t.tv_sec) * 1000000 + t.tv_nsec / 1000;
}

} // namespace

PriorityJobs::PriorityJobs(int workers, int nice) : nice_(nice), pool_(workers) {}

void PriorityJobs::submit(std::function<void()> job) {
    pool_.submit([this, job = std::move(job)] {
        prepareThread();
        const auto wall0 = std::chrono::steady_clock::now();
        const long long cpu0 = threadCpuUs();
        job();
        cpuUs_ += threadCpuUs() - cpu0;
        busyUs_ +=
            std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now() - wall0)
                .count();
    });
}

void PriorityJobs::prepareThread() {
    thread_local const PriorityJobs* prepared = nullptr;
    if (prepared == this)
        return;
    prepared = this;
    pthread_setname_np(pthread_self(), "rubble-fracture"); // as ps and /proc name it
    if (nice_ == 0)
        return;
    const auto tid = static_cast<id_t>(syscall(SYS_gettid));
    if (setpriority(PRIO_PROCESS, tid, nice_) == 0)
        ++raised_;
    else
        ++refused_;
}

} // namespace demo
