#pragma once
/// \file Panel.hpp
/// The Dear ImGui panel (fracture parameters, workers, debug toggles, slow motion, live plots, counters),
/// collapsed by default to one HUD line, the in-game HUD (crosshair, speed, hints) and the key help overlay.

#include <string>
#include <utility>
#include <vector>

#include "Game.hpp"

namespace demo {

/// Every key of the game and what it does (the help overlay lists these).
const std::vector<std::pair<const char*, const char*>>& keyHelp();

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
    /// Draws the HUD (crosshair, speed, pause banner, key hints) and, when shown, the help overlay.
    void drawHud(const Game& game, bool paused, int width, int height);
    /// Scales the UI font with the window (1 at 720 lines, in quarter steps); call once per frame.
    void scaleToWindow(int height);
    /// Panel shown at all (--no-panel hides it until F1).
    bool visible = true;
    /// Full panel (F1); collapsed, it is one HUD line: fps, pieces, last fracture latency.
    bool expanded = false;
    /// Key help overlay (H).
    bool help = false;
    /// Toggles the full panel (F1).
    void toggle() {
        expanded = visible ? !expanded : true;
        visible = true;
    }

private:
    std::vector<float> frameMs_ = std::vector<float>(240, 0.0f);
    int frameCursor_ = 0;
    std::vector<float> latency_;
    float scale_ = 1.0f;
};

} // namespace demo
