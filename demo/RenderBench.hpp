#pragma once
/// \file RenderBench.hpp
/// `rubble-demo --render-bench N,...`: the renderer alone, offscreen, on fields of N resting fractured pieces
/// and a few moving ones; one row per N with the CPU per frame and the draw calls (docs/rendering.md).

#include <string>
#include <vector>

namespace demo {

/// What the render bench runs.
struct RenderBenchOptions {
    std::vector<int> pieces;      ///< resting piece counts, one row each
    int width = 1280;             ///< offscreen target width
    int height = 720;             ///< offscreen target height
    int frames = 60;              ///< measured frames per row (after 10 warm-up frames)
    int moving = 64;              ///< pieces that move every frame, besides the resting ones
    bool json = false;            ///< print a JSON list instead of a table
    std::string quality = "auto"; ///< auto, software or gpu
    std::string out;              ///< folder for a picture of each row's last frame (empty: none)
};

/// Parses "500,5000,20000" into counts; false with a message naming the bad value.
bool parsePieceCounts(const std::string& text, std::vector<int>& out, std::string& error);

/// Runs the bench (creates its own headless GL context); returns the process exit status.
int runRenderBench(const RenderBenchOptions& options);

} // namespace demo
