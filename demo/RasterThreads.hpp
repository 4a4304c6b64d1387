#pragma once
/// \file RasterThreads.hpp
/// llvmpipe's rasteriser threads in this process: found by name, and their scheduling priority.

#include <vector>

namespace demo {

/// Thread ids of llvmpipe's rasteriser threads (named llvmpipe-N) in this process.
std::vector<int> rasterizerThreads();

/// Sets the niceness of llvmpipe's rasteriser threads (above 0 the fracture workers run first on a small
/// machine); returns how many threads took it.
int setRasterizerNice(int niceness);

/// While fracture jobs are in flight, llvmpipe's rasteriser threads run at a higher niceness, so that the
/// workers get the cores; back at `idleNice` once none is.
class RasterYield {
public:
    /// busyNice 0: off (update() does nothing).
    RasterYield(int busyNice, int idleNice) : busyNice_(busyNice), idleNice_(idleNice) {}
    /// Called once a frame, before drawing, with whether a job is queued or running.
    void update(bool jobsInFlight);
    /// Frames that began with the rasteriser threads yielding.
    long yieldedFrames() const { return yieldedFrames_; }

private:
    int busyNice_;
    int idleNice_;
    bool yielding_ = false;
    long yieldedFrames_ = 0;
    std::vector<int> threads_; // found at the first update (llvmpipe makes them with the context)
    bool found_ = false;
};

} // namespace demo
