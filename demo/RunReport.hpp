#pragma once
/// \file RunReport.hpp
/// Per-frame timing records of a run, written as CSV and summarised as JSON; PNG screenshots.

#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "Game.hpp"

namespace demo {

/// Collects frame records and writes the report files.
class RunReport {
public:
    /// One frame.
    struct Frame {
        std::uint64_t frame = 0; ///< simulation frame
        double simTime = 0;      ///< seconds of simulated time
        double frameMs = 0;      ///< wall-clock time of the whole frame
        double stepMs = 0;       ///< wall-clock time of the simulation step
        GameCounters counters;   ///< counters after the frame
        int drawCalls = 0;       ///< draw calls
        int renderWidth = 0;     ///< internal render resolution (dynamic resolution)
        int renderHeight = 0;    ///< internal render height
    };
    /// What drew the run.
    struct RenderInfo {
        std::string renderer; ///< GL_RENDERER
        std::string quality;  ///< "software" or "gpu"
        bool shadows = false; ///< shadow map on
        int outputWidth = 0;  ///< window / framebuffer size
        int outputHeight = 0; ///< window / framebuffer height
    };
    /// Adds a frame.
    void add(const Frame& f) { frames_.push_back(f); }
    /// The audio mixer's totals at the end of the run, and whether they reached a device.
    void setAudio(const MixerStats& stats, int maxVoices, bool device) {
        audio_ = stats;
        maxVoices_ = maxVoices;
        audioDevice_ = device;
    }
    /// Who ran the fracture jobs and who rasterised.
    struct Threads {
        int workers = 0;        ///< fracture worker threads
        int workerNice = 0;     ///< their niceness asked for
        int workersAtNice = 0;  ///< workers that got it
        int workersRefused = 0; ///< workers the system refused it
        int rasterThreads = 0;  ///< llvmpipe's rasteriser threads
        bool adoptReady = true; ///< results adopted when ready (false: deterministic, 2 frames after)
        double adoptWaitMs = 0; ///< how long a frame waited before drawing for a job in flight, at most
        double jobsBusyMs = 0;  ///< wall-clock time the workers spent in jobs
        double jobsCpuMs = 0;   ///< CPU time they got meanwhile
        long yieldedFrames =
            0; ///< frames drawn with the rasteriser threads yielding to jobs (--raster-yield)
    };
    void setThreads(const Threads& t) { threads_ = t; }
    /// Impact → visible times (ms): impact → adopted plus the wait for the frame that draws the pieces.
    void setVisibleLatencies(std::vector<double> ms) { visible_ = std::move(ms); }
    /// Number of frames recorded.
    std::size_t size() const { return frames_.size(); }
    /// Writes frames.csv and report.json into dir; latencies are impact → adopted in ms.
    bool write(const std::filesystem::path& dir, const std::string& scene, const RenderInfo& render,
               const std::vector<double>& latencies, int screenshots, std::string& summary) const;

private:
    std::vector<Frame> frames_;
    MixerStats audio_;
    int maxVoices_ = 0;
    bool audioDevice_ = false;
    Threads threads_;
    std::vector<double> visible_;
};

/// Writes tightly packed RGB rows (top first) as PNG.
bool writePng(const std::filesystem::path& path, const std::string& rgb, int w, int h);

/// The q-quantile (0..1) of values (nearest rank); 0 for an empty set.
double quantile(std::vector<double> values, double q);

} // namespace demo
