#pragma once
/// \file Panel.hpp
/// The Dear ImGui panel (fracture parameters, workers, debug toggles, slow motion, live plots, counters)
/// and the in-game HUD (crosshair, speed, hints).

#include <string>
#include <vector>

#include "Game.hpp"

namespace demo {

/// Live plot data and panel state.
class Panel {
public:
    /// Records a frame time (ms) for the plot.
    void pushFrameMs(float ms);
    /// Records impact → adopted latencies (ms) for the plot.
    void pushLatencies(const std::vector<double>& ms);
    /// Draws the panel; returns true when the user asked to restart the scene with the edited settings.
    bool draw(Game& game, GameSettings& pending, bool paused, const std::string& sceneName,
              const std::string& rendererName, int drawCalls, long long triangles);
    /// Draws the HUD (crosshair, speed, pause banner, key hints).
    void drawHud(const Game& game, bool paused, int width, int height);
    /// Panel visibility.
    bool visible = true;

private:
    std::vector<float> frameMs_ = std::vector<float>(240, 0.0f);
    int frameCursor_ = 0;
    std::vector<float> latency_;
};

} // namespace demo
