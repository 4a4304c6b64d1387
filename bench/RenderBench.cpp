// rubble-bench render: the demo renderer's CPU per frame and draw calls on fields of N resting pieces. The
// rendering lives in rubble-demo (`--render-bench`, OpenGL through libepoxy/EGL), which this runs as a child
// process, so that rubble-bench links no GL library (the library has none).
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "BenchUtil.hpp"
#include "Subcommand.hpp"

namespace {

struct BenchArgs {
    std::string pieces = "500,5000,20000";
    int frames = 60;
    int width = 1280;
    int height = 720;
    bool json = false;
    std::string demo; // rubble-demo (default: next to rubble-bench)
    std::string out;  // folder of render.csv / render_pieces.png (empty: print only)
    std::string label = "pieces";
};

// The new columns of render.csv (older rows leave them empty).
const std::vector<std::string> kNewColumns = {"pieces",      "cpu_ms_per_frame", "draw_calls",
                                              "mesh_pieces", "chip_pieces",      "main_cpu_ms_per_frame"};

double childCpuSeconds() {
    rusage u{};
    getrusage(RUSAGE_CHILDREN, &u);
    return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
           static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec) * 1e-6;
}

std::vector<std::string> splitCsvLine(const std::string& line) {
    std::vector<std::string> cells(1);
    bool quoted = false;
    for (const char c : line) {
        if (c == '"')
            quoted = !quoted;
        if (c == ',' && !quoted)
            cells.emplace_back();
        else
            cells.back() += c;
    }
    return cells;
}

// Appends rows (cells by column name) to render.csv, adding the new columns to its header (and empty cells
// to its older rows) when they are missing.
bool appendRows(const std::filesystem::path& csv,
                const std::vector<std::vector<std::pair<std::string, std::string>>>& rows) {
    std::vector<std::string> header, lines;
    if (std::ifstream in(csv); in) {
        std::string line;
        if (std::getline(in, line))
            header = splitCsvLine(line);
        while (std::getline(in, line))
            if (!line.empty())
                lines.push_back(line);
    }
    if (header.empty())
        header = {"date_utc",        "label",        "scene",
                  "renderer",        "quality",      "output",
                  "frames",          "frame_ms_p50", "demo_cpu_ms_per_frame",
                  "other_cpu_cores", "command"};
    const std::size_t before = header.size();
    for (const auto& c : kNewColumns)
        if (std::find(header.begin(), header.end(), c) == header.end())
            header.push_back(c);
    std::ostringstream text;
    for (std::size_t i = 0; i < header.size(); ++i)
        text << (i ? "," : "") << header[i];
    text << '\n';
    for (const auto& line : lines)
        text << line << std::string(header.size() - before, ',') << '\n';
    for (const auto& row : rows) {
        for (std::size_t i = 0; i < header.size(); ++i) {
            std::string cell;
            for (const auto& [name, value] : row)
                if (name == header[i])
                    cell = value;
            text << (i ? "," : "") << cell;
        }
        text << '\n';
    }
    std::filesystem::create_directories(csv.parent_path());
    std::ofstream out(csv);
    out << text.str();
    if (!out) {
        std::fprintf(stderr, "error: cannot write %s\n", csv.string().c_str());
        return false;
    }
    std::printf("rows appended to %s\n", csv.string().c_str());
    return true;
}

int runBench(const BenchArgs& a) {
    std::string demo = a.demo;
    if (demo.empty()) {
        std::error_code ec;
        demo = (std::filesystem::read_symlink("/proc/self/exe", ec).parent_path() / "rubble-demo").string();
    }
    if (access(demo.c_str(), X_OK) != 0) {
        std::fprintf(stderr, "error: --demo %s: not an executable (build the rubble-demo target)\n",
                     demo.c_str());
        return 1;
    }
    for (const char c : a.pieces)
        if (!(std::isdigit(static_cast<unsigned char>(c)) || c == ',')) {
            std::fprintf(stderr, "error: --pieces %s: expected counts separated by commas, e.g. 500,5000\n",
                         a.pieces.c_str());
            return 2;
        }
    const std::string command = "'" + demo + "' --render-bench " + a.pieces + " --bench-frames " +
                                std::to_string(a.frames) + " --width " + std::to_string(a.width) +
                                " --height " + std::to_string(a.height) + " --json";
    const rubble::bench::CpuMeter meter;
    const double child0 = childCpuSeconds();
    const auto t0 = std::chrono::steady_clock::now();
    std::string output;
    FILE* pipe = popen(command.c_str(), "r");
    if (!pipe) {
        std::fprintf(stderr, "error: cannot run %s\n", demo.c_str());
        return 1;
    }
    char buf[4096];
    for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, pipe)) > 0;)
        output.append(buf, n);
    const int status = pclose(pipe);
    const double wall = rubble::bench::msSince(t0) / 1000;
    if (status != 0) {
        std::fprintf(stderr, "error: rubble-demo --render-bench failed (status %d)\n", status);
        return 1;
    }
    nlohmann::json rows;
    try {
        rows = nlohmann::json::parse(output);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "error: rubble-demo --render-bench printed no JSON list: %s\n", e.what());
        return 1;
    }
    // the rest of the machine: all busy cores minus this process and the demo
    const rubble::bench::CpuMeter::Reading r = meter.read();
    const double childCores = wall > 0 ? (childCpuSeconds() - child0) / wall : 0;
    const double other = r.machine < 0 ? -1 : std::max(0.0, r.machine - r.own - childCores);
    for (auto& row : rows)
        row["other_cpu_cores"] = other;
    if (a.json) {
        std::printf("%s\n", rows.dump(1).c_str());
    } else {
        rubble::bench::Table t;
        t.header = {"pieces",    "cpu_ms_per_frame", "main_cpu_ms_per_frame", "draw_calls",
                    "triangles", "mesh_pieces",      "chip_pieces",           "other_cpu_cores"};
        for (const auto& row : rows)
            t.rows.push_back({std::to_string(row["pieces"].get<int>()),
                              rubble::bench::fixed(row["cpu_ms_per_frame"].get<double>(), 2),
                              rubble::bench::fixed(row["main_cpu_ms_per_frame"].get<double>(), 2),
                              std::to_string(row["draw_calls"].get<int>()),
                              std::to_string(row["triangles"].get<long long>()),
                              std::to_string(row["mesh_pieces"].get<int>()),
                              std::to_string(row["chip_pieces"].get<int>()), rubble::bench::fixed(other, 2)});
        rubble::bench::printTable(t);
    }
    if (a.out.empty())
        return 0;
    char date[32];
    const std::time_t now = std::time(nullptr);
    std::strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
    std::vector<std::vector<std::pair<std::string, std::string>>> csvRows;
    std::ostringstream data;
    for (const auto& row : rows) {
        const int n = row["pieces"].get<int>();
        const std::string size =
            std::to_string(row["width"].get<int>()) + "x" + std::to_string(row["height"].get<int>());
        std::string renderer = row["renderer"].get<std::string>();
        std::replace(renderer.begin(), renderer.end(), ',', ';');
        csvRows.push_back(
            {{"date_utc", date},
             {"label", a.label + "-" + std::to_string(n)},
             {"scene", "render-bench field"},
             {"renderer", renderer},
             {"quality", row["quality"].get<std::string>()},
             {"shadows", "0"},
             {"output", size},
             {"internal_p50", size},
             {"internal_min", size},
             {"frames", std::to_string(row["frames"].get<int>())},
             {"frame_ms_p50", rubble::bench::fixed(row["wall_ms_per_frame"].get<double>(), 2)},
             {"demo_cpu_ms_per_frame", rubble::bench::fixed(row["cpu_ms_per_frame"].get<double>(), 2)},
             {"other_cpu_cores", rubble::bench::fixed(other, 2)},
             {"command", "\"rubble-bench render --pieces " + std::to_string(n) + " --frames " +
                             std::to_string(a.frames) + " --width " + std::to_string(a.width) + " --height " +
                             std::to_string(a.height) + "\""},
             {"pieces", std::to_string(n)},
             {"cpu_ms_per_frame", rubble::bench::fixed(row["cpu_ms_per_frame"].get<double>(), 2)},
             {"draw_calls", std::to_string(row["draw_calls"].get<int>())},
             {"mesh_pieces", std::to_string(row["mesh_pieces"].get<int>())},
             {"chip_pieces", std::to_string(row["chip_pieces"].get<int>())},
             {"main_cpu_ms_per_frame", rubble::bench::fixed(row["main_cpu_ms_per_frame"].get<double>(), 2)}});
        data << n << ' ' << row["cpu_ms_per_frame"].get<double>() << ' '
             << row["main_cpu_ms_per_frame"].get<double>() << ' ' << row["draw_calls"].get<int>() << '\n';
    }
    if (!appendRows(std::filesystem::path(a.out) / "render.csv", csvRows))
        return 1;
    std::ostringstream plot;
    plot << "set title 'rubble-demo renderer, fields of N resting pieces + 64 moving, " << a.width << "x"
         << a.height << " offscreen, " << (rows.empty() ? "" : rows[0]["renderer"].get<std::string>())
         << "' noenhanced\nset logscale x\nset xlabel 'resting pieces'\nset ylabel 'CPU ms per frame'\n"
            "set y2label 'draw calls'\nset y2tics\nset ytics nomirror\nset yrange [0:*]\nset y2range [0:*]\n"
            "set key top left\nset grid\n"
            "plot $DATA u 1:2 w lp pt 7 title 'process CPU (llvmpipe threads included)', "
            "$DATA u 1:3 w lp pt 5 title 'main thread CPU', $DATA u 1:4 axes x1y2 w lp pt 9 title 'draw "
            "calls'\n";
    rubble::bench::plotPng(a.out, "render_pieces", data.str(), plot.str());
    return 0;
}

const rubble::tools::Registrar registrar{
    {"render", "Demo renderer: CPU per frame and draw calls against resting pieces (runs rubble-demo)",
     [](CLI::App& app) {
         auto args = std::make_shared<BenchArgs>();
         app.add_option("--pieces", args->pieces,
                        "resting piece counts, comma separated (default 500,5000,20000)");
         app.add_option("--frames", args->frames, "measured frames per count")->check(CLI::Range(1, 100000));
         app.add_option("--width", args->width, "offscreen width")->check(CLI::Range(16, 8192));
         app.add_option("--height", args->height, "offscreen height")->check(CLI::Range(16, 8192));
         app.add_flag("--json", args->json, "print the rows as a JSON list");
         app.add_option("--demo", args->demo, "rubble-demo executable (default: next to rubble-bench)");
         app.add_option(
             "--out", args->out,
             "append the rows to DIR/render.csv and draw DIR/render_pieces.png (default: print only)");
         app.add_option("--label", args->label, "label prefix of the CSV rows (default pieces)");
         return [args] { return runBench(*args); };
     }}};

} // namespace
