#include "RunReport.hpp"

#include <stb_image_write.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

namespace demo {

double quantile(std::vector<double> v, double q) {
    if (v.empty())
        return 0;
    std::sort(v.begin(), v.end());
    const size_t i = static_cast<size_t>(std::ceil(q * static_cast<double>(v.size()))) - 1;
    return v[std::min(i, v.size() - 1)];
}

bool writePng(const std::filesystem::path& path, const std::string& rgb, int w, int h) {
    return stbi_write_png(path.string().c_str(), w, h, 3, rgb.data(), w * 3) != 0;
}

bool RunReport::write(const std::filesystem::path& dir, const std::string& scene, const RenderInfo& render,
                      const std::vector<double>& latencies, int screenshots, std::string& summary) const {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    std::ofstream csv(dir / "frames.csv");
    if (!csv)
        return false;
    csv << "frame,sim_time_s,frame_ms,step_ms,draw_calls,bodies,pieces,jobs,shots,impacts,fractures,render_w,"
           "render_h,awake,frozen\n";
    std::vector<double> ms, widths, heights;
    for (const auto& f : frames_) {
        csv << f.frame << ',' << f.simTime << ',' << f.frameMs << ',' << f.stepMs << ',' << f.drawCalls << ','
            << f.counters.bodies << ',' << f.counters.pieces << ',' << f.counters.jobs << ','
            << f.counters.shots << ',' << f.counters.impacts << ',' << f.counters.fractures << ','
            << f.renderWidth << ',' << f.renderHeight << ',' << f.counters.awake << ',' << f.counters.frozen
            << '\n';
        ms.push_back(f.frameMs);
        widths.push_back(f.renderWidth);
        heights.push_back(f.renderHeight);
    }
    // Skip the first frames (shader compilation, first uploads) for the summary.
    std::vector<double> steady(ms.begin() + static_cast<long>(std::min<size_t>(ms.size(), 10)), ms.end());
    if (steady.empty())
        steady = ms;
    const double p50 = quantile(steady, 0.5), p99 = quantile(steady, 0.99);
    const double minW = widths.empty() ? 0 : *std::min_element(widths.begin(), widths.end());
    const double minH = heights.empty() ? 0 : *std::min_element(heights.begin(), heights.end());
    const GameCounters last = frames_.empty() ? GameCounters{} : frames_.back().counters;
    nlohmann::json j;
    j["scene"] = scene;
    j["renderer"] = render.renderer;
    j["quality"] = render.quality;
    j["shadows"] = render.shadows;
    j["output"] = {{"width", render.outputWidth}, {"height", render.outputHeight}};
    // internal render resolution (dynamic resolution): median and smallest over the run
    j["internal_resolution"] = {{"width_p50", quantile(widths, 0.5)},
                                {"height_p50", quantile(heights, 0.5)},
                                {"width_min", minW},
                                {"height_min", minH}};
    j["frames"] = frames_.size();
    j["sim_seconds"] = frames_.empty() ? 0.0 : frames_.back().simTime;
    j["frame_ms"] = {{"p50", p50}, {"p99", p99}, {"max", quantile(steady, 1.0)}};
    j["fps"] = {{"p50", p50 > 0 ? 1000.0 / p50 : 0.0}, {"p99", p99 > 0 ? 1000.0 / p99 : 0.0}};
    j["shots"] = last.shots;
    j["impacts"] = last.impacts;
    j["impacts_submitted"] = last.submitted;
    j["fractures"] = last.fractures;
    j["pieces_created"] = last.piecesCreated;
    j["blast_thrown"] = last.blastThrown;
    j["collisions_over_budget"] = last.collisionsOverBudget;
    j["pieces_live"] = last.pieces;
    j["pieces_awake"] = last.awake;
    j["pieces_frozen"] = last.frozen;
    j["pieces_light"] = last.light;
    j["pieces_retired_to_particles"] = last.retired;
    j["pieces_retired_by"] = {{"dust", last.retiredBy[0]},
                              {"awake", last.retiredBy[1]},
                              {"triangles", last.retiredBy[2]},
                              {"faded", last.retiredBy[3]},
                              {"fell_out", last.retiredBy[4]}};
    j["bodies_collapsed"] = last.collapsed;
    j["bonds_broken"] = last.bondsBroken;
    j["latency_ms"] = {{"count", latencies.size()},
                       {"p50", quantile(latencies, 0.5)},
                       {"p99", quantile(latencies, 0.99)},
                       {"max", quantile(latencies, 1.0)}};
    j["visible_ms"] = {{"count", visible_.size()},
                       {"p50", quantile(visible_, 0.5)},
                       {"p99", quantile(visible_, 0.99)},
                       {"max", quantile(visible_, 1.0)}};
    for (int w = 0; w < kWeaponCount; ++w) // fractures credited to the weapon whose impact caused them
        j["weapons"][weaponSpec(static_cast<Weapon>(w)).name] = {
            {"shots", last.weaponShots[static_cast<std::size_t>(w)]},
            {"fractures", last.weaponFractures[static_cast<std::size_t>(w)]}};
    j["audio"] = {{"device", audioDevice_},
                  {"impacts", last.sounds[static_cast<std::size_t>(SoundKind::Impact)]},
                  {"breaks", last.sounds[static_cast<std::size_t>(SoundKind::Break)]},
                  {"debris", last.sounds[static_cast<std::size_t>(SoundKind::Debris)]},
                  {"collapses", last.sounds[static_cast<std::size_t>(SoundKind::Collapse)]},
                  {"events", audio_.events},
                  {"played", audio_.played},
                  {"quiet", audio_.quiet},
                  {"stolen", audio_.stolen},
                  {"refused", audio_.refused},
                  {"max_voices", maxVoices_},
                  {"peak_voices", audio_.peakVoices},
                  {"peak_level", audio_.peakLevel}};
    j["threads"] = {{"fracture_workers", threads_.workers},      {"worker_nice", threads_.workerNice},
                    {"workers_at_nice", threads_.workersAtNice}, {"workers_refused", threads_.workersRefused},
                    {"raster_threads", threads_.rasterThreads},  {"adopt_ready", threads_.adoptReady},
                    {"adopt_wait_ms", threads_.adoptWaitMs},     {"jobs_busy_ms", threads_.jobsBusyMs},
                    {"jobs_cpu_ms", threads_.jobsCpuMs},         {"yielded_frames", threads_.yieldedFrames}};
    j["screenshots"] = screenshots;
    j["fracture_runtime"] = Game::fractureAvailable();
    std::ofstream js(dir / "report.json");
    js << j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) << '\n'; // any scene file name
    std::ostringstream s;
    s.precision(3);
    s << "frames " << frames_.size() << ", fps p50 " << (p50 > 0 ? 1000.0 / p50 : 0.0) << " / p99 "
      << (p99 > 0 ? 1000.0 / p99 : 0.0) << " (frame ms p50 " << p50 << ", p99 " << p99 << "), shots "
      << last.shots << ", impacts " << last.impacts << ", fractures " << last.fractures << ", latency ms p50 "
      << quantile(latencies, 0.5) << " p99 " << quantile(latencies, 0.99) << " (visible p50 "
      << quantile(visible_, 0.5) << " p99 " << quantile(visible_, 0.99) << "), internal resolution p50 "
      << quantile(widths, 0.5) << 'x' << quantile(heights, 0.5) << " (min " << minW << 'x' << minH << ")";
    summary = s.str();
    return static_cast<bool>(js);
}

} // namespace demo
