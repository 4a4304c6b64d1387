#include "PriorityJobs.hpp"

#include <pthread.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

namespace demo {

PriorityJobs::PriorityJobs(int workers, int nice) : nice_(nice), pool_(workers) {}

void PriorityJobs::submit(std::function<void()> job) {
    pool_.submit([this, job = std::move(job)] {
        prepareThread();
        job();
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
