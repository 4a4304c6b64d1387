#include "RasterThreads.hpp"

#include <sys/resource.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace demo {

std::vector<int> rasterizerThreads() {
    std::vector<int> out;
    std::error_code ec;
    for (const auto& task : std::filesystem::directory_iterator("/proc/self/task", ec)) {
        std::ifstream comm(task.path() / "comm");
        std::string name;
        if (!std::getline(comm, name) || name.rfind("llvmpipe", 0) != 0)
            continue;
        if (const int tid = std::atoi(task.path().filename().c_str()); tid > 0)
            out.push_back(tid);
    }
    return out;
}

namespace {

int renice(const std::vector<int>& threads, int niceness) {
    int changed = 0;
    for (const int tid : threads)
        if (setpriority(PRIO_PROCESS, static_cast<id_t>(tid), niceness) == 0)
            ++changed;
    return changed;
}

} // namespace

int setRasterizerNice(int niceness) {
    return renice(rasterizerThreads(), niceness);
}

void RasterYield::update(bool jobsInFlight) {
    if (busyNice_ == 0)
        return;
    if (!found_) {
        threads_ = rasterizerThreads();
        found_ = true;
    }
    if (jobsInFlight != yielding_) {
        renice(threads_, jobsInFlight ? busyNice_ : idleNice_);
        yielding_ = jobsInFlight;
    }
    yieldedFrames_ += yielding_ ? 1 : 0;
}

} // namespace demo
