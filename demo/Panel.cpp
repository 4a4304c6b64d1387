#include "Panel.hpp"

#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "RunReport.hpp"

namespace demo {

// The HUD's key line, top left.
constexpr const char* kKeyLine = "W/S pitch  A/D roll  Q/E yaw  Z/X speed  Space fire  1-3 weapon  H help";

const std::vector<std::pair<const char*, const char*>>& keyHelp() {
    static const std::vector<std::pair<const char*, const char*>> keys = {
        {"W / S", "pitch down / up"},
        {"A / D", "roll left / right"},
        {"Q / E", "yaw left / right"},
        {"Z / X", "speed up / slow down"},
        {"Space", "fire (hold for continuous fire); unpause"},
        {"1 / 2 / 3", "weapon: cannon / heavy shell / demolition charge"},
        {"R", "respawn the jet (it also respawns 2 s after a crash)"},
        {"L", "auto-level assist on/off (wings level when no roll key is held)"},
        {"N", "next scene (the demolition, the thesis's scenes, world.cfg)"},
        {"P", "pause"},
        {"H", "this help"},
        {"F1", "full panel / compact HUD line"},
        {"F2", "screenshot (needs --out)"},
        {"F3", "debug overlay (shapes, AABBs, impacts)"},
        {"F5 / F9", "quick save / quick load"},
        {"Esc", "quit"},
    };
    return keys;
}

void Panel::scaleToWindow(int height) {
    scale_ = std::clamp(std::round(static_cast<float>(height) / 720.0f * 4.0f) / 4.0f, 1.0f, 4.0f);
    ImGui::GetIO().FontGlobalScale = scale_;
}

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
    if (!expanded) { // one line in the top right corner: fps, pieces, last fracture latency
        float avg = 0;
        int n = 0;
        for (int i = 1; i <= 30; ++i) {
            const float v =
                frameMs_[(static_cast<size_t>(frameCursor_) + frameMs_.size() - static_cast<size_t>(i)) %
                         frameMs_.size()];
            if (v > 0)
                avg += v, ++n;
        }
        avg = n > 0 ? avg / static_cast<float>(n) : 0.0f;
        char line[160];
        const int pieces = game.counters().pieces;
        if (latency_.empty())
            std::snprintf(line, sizeof line, "%.0f fps   pieces %d   last fracture -   F1 panel  H help",
                          avg > 0 ? 1000.0 / static_cast<double>(avg) : 0.0, pieces);
        else
            std::snprintf(line, sizeof line,
                          "%.0f fps   pieces %d   last fracture %.0f ms   F1 panel  H help",
                          avg > 0 ? 1000.0 / static_cast<double>(avg) : 0.0, pieces,
                          static_cast<double>(latency_.back()));
        ImDrawList* dl = ImGui::GetForegroundDrawList();
        const float size = ImGui::GetFontSize();
        const ImVec2 ts = ImGui::GetFont()->CalcTextSizeA(size, 1e9f, 0.0f, line);
        ImVec2 at(io.DisplaySize.x - ts.x - 18 * scale_, 10 * scale_);
        const float keyLineEnd = 12 * scale_ + ImGui::GetFont()->CalcTextSizeA(size, 1e9f, 0.0f, kKeyLine).x;
        if (keyLineEnd + 16 * scale_ > at.x) // a narrow window: below the key line instead of over it
            at.y += ts.y + 10 * scale_;
        dl->AddRectFilled(ImVec2(at.x - 8 * scale_, at.y - 4 * scale_),
                          ImVec2(at.x + ts.x + 8 * scale_, at.y + ts.y + 4 * scale_), IM_COL32(0, 0, 0, 110),
                          5 * scale_);
        dl->AddText(ImGui::GetFont(), size, at, IM_COL32(255, 255, 255, 230), line);
        return false;
    }
    ImGui::SetNextWindowPos(ImVec2(io.DisplaySize.x - 330 * scale_, 10), ImGuiCond_Appearing);
    ImGui::SetNextWindowSize(ImVec2(320 * scale_, 0), ImGuiCond_Appearing);
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
                     ImVec2(230 * scale_, 50 * scale_));
    if (latency_.empty()) {
        ImGui::TextDisabled("impact -> adopted: no fracture yet");
    } else {
        std::vector<double> d(latency_.begin(), latency_.end());
        std::snprintf(label, sizeof label, "p50 %.1f ms  p99 %.1f", quantile(d, 0.5), quantile(d, 0.99));
        const float mx = *std::max_element(latency_.begin(), latency_.end());
        ImGui::PlotHistogram("latency", latency_.data(), static_cast<int>(latency_.size()), 0, label, 0.0f,
                             std::max(mx, 20.0f), ImVec2(230 * scale_, 50 * scale_));
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
        int pattern = static_cast<int>(pending.fracture.pattern);
        ImGui::RadioButton("single cell", &pattern, 0);
        ImGui::SameLine();
        ImGui::RadioButton("shatter", &pattern, 1);
        ImGui::SameLine();
        ImGui::RadioButton("adaptive", &pattern, 2);
        pending.fracture.pattern = static_cast<rubble::CellPattern>(pattern);
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
    ImFont* font = ImGui::GetFont();
    const float fs = ImGui::GetFontSize(), k = scale_;
    const float h = static_cast<float>(height);
    const float cx = static_cast<float>(width) * 0.5f, cy = h * 0.42f;
    const ImU32 col = IM_COL32(255, 255, 255, 170);
    dl->AddCircle(ImVec2(cx, cy), 9.0f * k, col, 24, 1.5f * k);
    dl->AddLine(ImVec2(cx - 18 * k, cy), ImVec2(cx - 11 * k, cy), col, 1.5f * k);
    dl->AddLine(ImVec2(cx + 11 * k, cy), ImVec2(cx + 18 * k, cy), col, 1.5f * k);
    dl->AddLine(ImVec2(cx, cy - 18 * k), ImVec2(cx, cy - 11 * k), col, 1.5f * k);
    dl->AddLine(ImVec2(cx, cy + 11 * k), ImVec2(cx, cy + 18 * k), col, 1.5f * k);
    char buf[224];
    V3 pos, fwd, up;
    game.vehicleFrame(pos, fwd, up);
    const GameCounters& c = game.counters();
    std::snprintf(buf, sizeof buf,
                  "[%d] %s   SPEED %3.0f m/s   ALT %4.0f m   HITS %d   FRACTURES %d   PIECES %d (AWAKE %d, "
                  "FROZEN %d)",
                  static_cast<int>(game.weapon()) + 1, weaponSpec(game.weapon()).name,
                  static_cast<double>(game.speed()), static_cast<double>(pos.y - game.groundY()), c.impacts,
                  c.fractures, c.pieces, c.awake, c.frozen);
    const ImVec2 ts = font->CalcTextSizeA(fs, 1e9f, 0.0f, buf);
    dl->AddRectFilled(ImVec2(12 * k, h - ts.y - 26 * k), ImVec2(32 * k + ts.x, h - 12 * k),
                      IM_COL32(0, 0, 0, 110), 6.0f * k);
    dl->AddText(font, fs, ImVec2(22 * k, h - ts.y - 19 * k), IM_COL32(255, 255, 255, 230), buf);
    dl->AddText(font, fs, ImVec2(12 * k, 10 * k), IM_COL32(255, 255, 255, 190), kKeyLine);
    if (paused) {
        const char* msg = "PAUSED - press Space";
        const ImVec2 ms = font->CalcTextSizeA(fs, 1e9f, 0.0f, msg);
        dl->AddRectFilled(ImVec2(cx - ms.x * 0.5f - 16 * k, cy - 60 * k - ms.y),
                          ImVec2(cx + ms.x * 0.5f + 16 * k, cy - 44 * k), IM_COL32(0, 0, 0, 150), 6.0f * k);
        dl->AddText(font, fs, ImVec2(cx - ms.x * 0.5f, cy - 52 * k - ms.y), IM_COL32(255, 230, 120, 255),
                    msg);
    }
    if (help) { // every key, in a box in the middle of the screen
        float keyW = 0, rowH = fs * 1.35f, textW = 0;
        for (const auto& [key, what] : keyHelp()) {
            keyW = std::max(keyW, font->CalcTextSizeA(fs, 1e9f, 0.0f, key).x);
            textW = std::max(textW, font->CalcTextSizeA(fs, 1e9f, 0.0f, what).x);
        }
        const float boxW = keyW + textW + 60 * k;
        const float boxH = rowH * static_cast<float>(keyHelp().size() + 2) + 24 * k;
        const ImVec2 a(cx - boxW * 0.5f, h * 0.5f - boxH * 0.5f);
        dl->AddRectFilled(a, ImVec2(a.x + boxW, a.y + boxH), IM_COL32(10, 14, 22, 215), 8 * k);
        dl->AddText(font, fs, ImVec2(a.x + 20 * k, a.y + 12 * k), IM_COL32(255, 230, 120, 255),
                    "Keys (H closes)");
        float y = a.y + 12 * k + rowH * 1.5f;
        for (const auto& [key, what] : keyHelp()) {
            dl->AddText(font, fs, ImVec2(a.x + 20 * k, y), IM_COL32(255, 230, 120, 255), key);
            dl->AddText(font, fs, ImVec2(a.x + 40 * k + keyW, y), IM_COL32(235, 235, 235, 255), what);
            y += rowH;
        }
    }
}

} // namespace demo
