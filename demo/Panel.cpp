#include "Panel.hpp"

#include <imgui.h>

#include <algorithm>
#include <cstdio>

#include "RunReport.hpp"

namespace demo {

void Panel::pushFrameMs(float ms) {
    frameMs_[static_cast<size_t>(frameCursor_)] = ms;
    frameCursor_ = (frameCursor_ + 1) % static_cast<int>(frameMs_.size());
}

void Panel::pushLatencies(const std::vector<double>& ms) {
    for (double v : ms)
        latency_.push_back(static_cast<float>(v));
    if (latency_.size() > 200)
        latency_.erase(latency_.begin(), latency_.begin() + static_cast<long>(latency_.size() - 200));
}

bool Panel::draw(Game& game, GameSettings& pending, bool paused, const std::string& sceneName,
                 const std::string& rendererName, int drawCalls, long long triangles) {
    if (!visible)
        return false;
    bool restart = false;
    const ImGuiIO& io = ImGui::GetIO();
    ImGui::SetNextWindowPos(ImVec2(io.DisplaySize.x - 330, 10), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowSize(ImVec2(320, 0), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowBgAlpha(0.78f);
    ImGui::Begin("Rubble", nullptr, ImGuiWindowFlags_AlwaysAutoResize);
    const GameCounters& c = game.counters();
    ImGui::Text("%s", sceneName.c_str());
    ImGui::TextDisabled("%s", rendererName.c_str());
    ImGui::TextDisabled("fracture: DestructionWorld runtime + Bullet adapter");

    // Frame time plot.
    std::vector<float> ordered;
    ordered.reserve(frameMs_.size());
    for (size_t i = 0; i < frameMs_.size(); ++i)
        ordered.push_back(frameMs_[(static_cast<size_t>(frameCursor_) + i) % frameMs_.size()]);
    float avg = 0;
    for (float v : ordered)
        avg += v;
    avg /= static_cast<float>(ordered.size());
    char label[64];
    std::snprintf(label, sizeof label, "%.1f ms  (%.0f fps)", static_cast<double>(avg),
                  avg > 0 ? 1000.0 / static_cast<double>(avg) : 0.0);
    ImGui::PlotLines("frame", ordered.data(), static_cast<int>(ordered.size()), 0, label, 0.0f, 50.0f,
                     ImVec2(230, 50));
    if (latency_.empty()) {
        ImGui::TextDisabled("impact -> adopted: no fracture yet");
    } else {
        std::vector<double> d(latency_.begin(), latency_.end());
        std::snprintf(label, sizeof label, "p50 %.1f ms  p99 %.1f", quantile(d, 0.5), quantile(d, 0.99));
        const float mx = *std::max_element(latency_.begin(), latency_.end());
        ImGui::PlotHistogram("latency", latency_.data(), static_cast<int>(latency_.size()), 0, label, 0.0f,
                             std::max(mx, 20.0f), ImVec2(230, 50));
    }

    if (ImGui::CollapsingHeader("Counters", ImGuiTreeNodeFlags_DefaultOpen)) {
        ImGui::Text("bodies %d   pieces %d   jobs queued %d", c.bodies, c.pieces, c.jobs);
        ImGui::Text("shots %d   impacts %d   fractures %d", c.shots, c.impacts, c.fractures);
        ImGui::Text("draw calls %d   triangles %lld", drawCalls, triangles);
        ImGui::Text("frame %llu%s", static_cast<unsigned long long>(c.frame), paused ? "  (paused)" : "");
    }

    GameSettings& live = game.settings();
    if (ImGui::CollapsingHeader("View and debug", ImGuiTreeNodeFlags_DefaultOpen)) {
        ImGui::SliderFloat("slow motion", &live.timeScale, 0.05f, 1.0f, "%.2fx");
        ImGui::Checkbox("collision shapes", &live.debugShapes);
        ImGui::SameLine();
        ImGui::Checkbox("AABBs", &live.debugAabbs);
        ImGui::Checkbox("impact points", &live.debugImpacts);
        ImGui::SameLine();
        ImGui::Checkbox("shadows", &live.shadows);
        ImGui::Checkbox("bonds by stress", &live.debugBonds);
        if (const rubble::DestructionRuntime* rt = game.runtime(); rt && live.structure)
            ImGui::Text("bonds %zu   broken %lld", rt->structureBonds().size(), rt->counters().bondsBroken);
        ImGui::SliderFloat("shot speed", &live.projectileSpeed, 40.0f, 400.0f, "%.0f m/s");
        ImGui::SliderFloat("shot mass", &live.projectileMass, 0.5f, 40.0f, "%.1f kg");
    }
    if (ImGui::CollapsingHeader("Fracture (applies on restart)")) {
        int pattern = pending.fracture.pattern == rubble::CellPattern::Shatter ? 1 : 0;
        ImGui::RadioButton("single cell", &pattern, 0);
        ImGui::SameLine();
        ImGui::RadioButton("shatter", &pattern, 1);
        pending.fracture.pattern = pattern ? rubble::CellPattern::Shatter : rubble::CellPattern::SingleCell;
        ImGui::SliderInt("cells K", &pending.fracture.cells, 2, 32);
        ImGui::SliderInt("seed points", &pending.fracture.seedPoints, 4, 64);
        float base = static_cast<float>(pending.fracture.sizeLaw.base);
        float scale = static_cast<float>(pending.fracture.sizeLaw.scale);
        float expo = static_cast<float>(pending.fracture.sizeLaw.exponent);
        float maxs = static_cast<float>(pending.fracture.sizeLaw.maxSize);
        ImGui::TextDisabled("cell size = base + scale * impulse^exp");
        ImGui::SliderFloat("base", &base, 0.1f, 20.0f);
        ImGui::SliderFloat("scale", &scale, 0.0f, 2.0f);
        ImGui::SliderFloat("exp", &expo, 0.1f, 1.0f);
        ImGui::SliderFloat("max size", &maxs, 1.0f, 80.0f);
        pending.fracture.sizeLaw.base = base;
        pending.fracture.sizeLaw.scale = scale;
        pending.fracture.sizeLaw.exponent = expo;
        pending.fracture.sizeLaw.maxSize = maxs;
        float thr = static_cast<float>(pending.impulseThreshold);
        ImGui::SliderFloat("impulse threshold", &thr, 0.0f, 2000.0f, "%.0f N*s");
        pending.impulseThreshold = thr;
        float coll = static_cast<float>(pending.collisionImpulse);
        ImGui::SliderFloat("crash threshold", &coll, 100.0f, 20000.0f, "%.0f N*s");
        pending.collisionImpulse = coll;
        ImGui::SliderInt("workers (-1 auto)", &pending.workers, -1, 8);
        ImGui::SliderFloat("debris below", &pending.minPieceVolume, 0.0f, 1.0f, "%.3f m3");
        ImGui::SliderInt("awake debris", &pending.maxAwake, 50, 2000);
        // live: takes effect at the next fracture, and is kept across restarts
        if (ImGui::Checkbox("collapse unsupported (live)", &live.collapseUnsupported))
            pending.collapseUnsupported = live.collapseUnsupported;
        ImGui::Checkbox("structure: stress solver", &pending.structure);
        if (ImGui::Button("Apply and restart scene"))
            restart = true;
    }
    ImGui::End();
    return restart;
}

void Panel::drawHud(const Game& game, bool paused, int width, int height) {
    ImDrawList* dl = ImGui::GetForegroundDrawList();
    const float cx = static_cast<float>(width) * 0.5f, cy = static_cast<float>(height) * 0.42f;
    const ImU32 col = IM_COL32(255, 255, 255, 170);
    dl->AddCircle(ImVec2(cx, cy), 9.0f, col, 24, 1.5f);
    dl->AddLine(ImVec2(cx - 18, cy), ImVec2(cx - 11, cy), col, 1.5f);
    dl->AddLine(ImVec2(cx + 11, cy), ImVec2(cx + 18, cy), col, 1.5f);
    dl->AddLine(ImVec2(cx, cy - 18), ImVec2(cx, cy - 11), col, 1.5f);
    dl->AddLine(ImVec2(cx, cy + 11), ImVec2(cx, cy + 18), col, 1.5f);
    char buf[160];
    V3 pos, fwd, up;
    game.vehicleFrame(pos, fwd, up);
    std::snprintf(buf, sizeof buf, "SPEED %3.0f m/s   ALT %4.0f m   HITS %d   FRACTURES %d",
                  static_cast<double>(game.speed()), static_cast<double>(pos.y - game.groundY()),
                  game.counters().impacts, game.counters().fractures);
    dl->AddRectFilled(ImVec2(12, static_cast<float>(height) - 40),
                      ImVec2(470, static_cast<float>(height) - 12), IM_COL32(0, 0, 0, 110), 6.0f);
    dl->AddText(ImVec2(22, static_cast<float>(height) - 33), IM_COL32(255, 255, 255, 230), buf);
    dl->AddText(ImVec2(12, 10), IM_COL32(255, 255, 255, 190),
                "W/S pitch  A/D roll  Q/E yaw  Z/X speed  Space fire  P pause  F1 panel  Esc quit");
    if (paused) {
        const char* msg = "PAUSED - press Space";
        const ImVec2 ts = ImGui::CalcTextSize(msg);
        dl->AddRectFilled(ImVec2(cx - ts.x * 0.5f - 16, cy - 60), ImVec2(cx + ts.x * 0.5f + 16, cy - 30),
                          IM_COL32(0, 0, 0, 150), 6.0f);
        dl->AddText(ImVec2(cx - ts.x * 0.5f, cy - 52), IM_COL32(255, 230, 120, 255), msg);
    }
}

} // namespace demo
