#include "RenderBench.hpp"

#include "GlContext.hpp"
#include "Renderer.hpp"
#include "RunReport.hpp"
#include "rubble/core/Random.hpp"
#include "rubble/rubble.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

namespace demo {

namespace {

constexpr float kPi = 3.14159265f;
constexpr float kDensity = 1.0f; // resting pieces per square metre of the debris field

double processCpuMs() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return (static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) * 1e3 +
            static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec) * 1e-3);
}

double threadCpuMs() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) * 1e-6;
}

// Debris templates: a 2.4 m concrete block shattered into about 64 pieces, each centred on its bounds.
std::vector<rubble::Mesh> debrisTemplates(std::string& error) {
    rubble::FractureParams params;
    params.pattern = rubble::CellPattern::Shatter;
    params.cells = 64;
    params.layout = rubble::ShatterLayout::Uniform;
    params.sizeLaw.base = 3.0;
    params.sizeLaw.scale = 0;
    params.uvScale = 0.25;
    const rubble::Mesh block = rubble::makeBox({-1.2, -1.2, -1.2}, {1.2, 1.2, 1.2});
    auto r = rubble::fracture(block, rubble::Impact{{0, 1.2, 0}, {0, 1, 0}, 1000}, params, 7);
    std::vector<rubble::Mesh> out;
    if (!r) {
        error = "fracture of the debris block failed: " + r.error().message;
        return out;
    }
    for (auto& piece : r.value().pieces) {
        if (piece.cell < 0)
            continue;
        out.push_back(piece.mesh.translated(-piece.mesh.bounds().center()));
    }
    if (out.empty())
        error = "the debris block gave no pieces";
    return out;
}

M4 placement(const V3& at, float yaw, float pitch) {
    const float cy = std::cos(yaw), sy = std::sin(yaw), cp = std::cos(pitch), sp = std::sin(pitch);
    M4 m; // yaw about y, then pitch about x
    m.m[0] = cy;
    m.m[1] = 0;
    m.m[2] = -sy;
    m.m[4] = sy * sp;
    m.m[5] = cp;
    m.m[6] = cy * sp;
    m.m[8] = sy * cp;
    m.m[9] = -sp;
    m.m[10] = cy * cp;
    m.m[12] = at.x;
    m.m[13] = at.y;
    m.m[14] = at.z;
    return m;
}

struct Row {
    int pieces = 0;
    double cpuMs = 0, mainCpuMs = 0, wallMs = 0;
    int drawCalls = 0;
    long long triangles = 0;
    int meshPieces = 0, chipPieces = 0;
};

} // namespace

bool parsePieceCounts(const std::string& text, std::vector<int>& out, std::string& error) {
    out.clear();
    std::size_t at = 0;
    while (at <= text.size()) {
        const std::size_t comma = std::min(text.find(',', at), text.size());
        const std::string item = text.substr(at, comma - at);
        char* end = nullptr;
        const long v = std::strtol(item.c_str(), &end, 10);
        if (item.empty() || *end != '\0' || v < 1 || v > 200000) {
            error =
                "--render-bench: '" + item + "' is not a piece count in 1..200000 (expected e.g. 500,5000)";
            return false;
        }
        out.push_back(static_cast<int>(v));
        at = comma + 1;
    }
    return true;
}

int runRenderBench(const RenderBenchOptions& o) {
    std::string error;
    auto gl = GlContext::create(o.width, o.height, true, error);
    if (!gl) {
        std::fprintf(stderr, "error: %s\n", error.c_str());
        return 1;
    }
    RenderQuality quality = RenderQuality::forRenderer(o.quality == "gpu" ? "gpu" : gl->renderer());
    if (o.quality == "software")
        quality = RenderQuality::forRenderer("llvmpipe");
    const std::vector<rubble::Mesh> templates = debrisTemplates(error);
    if (templates.empty()) {
        std::fprintf(stderr, "error: %s\n", error.c_str());
        return 1;
    }
    std::vector<Row> rows;
    for (const int n : o.pieces) {
        Renderer renderer;
        if (!renderer.init(quality, error)) {
            std::fprintf(stderr, "error: renderer: %s\n", error.c_str());
            return 1;
        }
        const int concrete = renderer.proceduralTexture("concrete");
        const int interior = renderer.materialInterior("concrete");
        const int ground = renderer.addMesh(rubble::makeBox({-500, -1, -500}, {500, 0, 500}),
                                            renderer.proceduralTexture("grid"), 0.8f, 0.8f, 0.8f);
        // resting pieces spread over a disc at constant density; moving ones tumble above its centre
        rubble::Rng rng(42);
        const float radius = std::sqrt(static_cast<float>(n) / (kPi * kDensity));
        struct Placed {
            int mesh;
            M4 model;
        };
        std::vector<Placed> resting;
        resting.reserve(static_cast<std::size_t>(n));
        for (int i = 0; i < n + o.moving; ++i) {
            const rubble::Mesh& t = templates[static_cast<std::size_t>(i) % templates.size()];
            const float shade = 0.8f + 0.2f * static_cast<float>(rng.uniform());
            const int id = renderer.addMesh(t, concrete, shade, shade, shade * 0.95f, interior);
            const float r = radius * std::sqrt(static_cast<float>(rng.uniform()));
            const float a = 2 * kPi * static_cast<float>(rng.uniform());
            const float lift = static_cast<float>(t.bounds().size().y) * 0.4f;
            resting.push_back({id, placement({r * std::cos(a), lift, r * std::sin(a)},
                                             2 * kPi * static_cast<float>(rng.uniform()), 0)});
        }
        FrameView fv;
        fv.width = gl->width();
        fv.height = gl->height();
        fv.fbo = gl->framebuffer();
        fv.eye = {0, 14, 22};
        fv.focus = {0, 0, -6};
        fv.view = lookAt(fv.eye, fv.focus, {0, 1, 0});
        fv.proj =
            perspective(1.05f, static_cast<float>(fv.width) / static_cast<float>(fv.height), 0.5f, 3000.0f);
        const M4 groundModel;
        auto frame = [&](int f) {
            renderer.beginFrame();
            renderer.drawMesh(ground, groundModel);
            for (int i = 0; i < n; ++i)
                renderer.drawMesh(resting[static_cast<std::size_t>(i)].mesh,
                                  resting[static_cast<std::size_t>(i)].model);
            for (int i = 0; i < o.moving; ++i) { // tumbling pieces falling through 12 m, a ring of them
                const float t = static_cast<float>(f + 7 * i) / 60.0f;
                const float a = 2 * kPi * static_cast<float>(i) / static_cast<float>(o.moving);
                const V3 at{6 * std::cos(a), 13 - std::fmod(t * 6, 12.0f), 6 * std::sin(a)};
                renderer.drawMesh(resting[static_cast<std::size_t>(n + i)].mesh, placement(at, t * 2, t * 3));
            }
            renderer.render(fv);
            glFinish();
        };
        for (int f = 0; f < 10; ++f)
            frame(f);
        const double cpu0 = processCpuMs(), main0 = threadCpuMs();
        const auto wall0 = std::chrono::steady_clock::now();
        for (int f = 0; f < o.frames; ++f)
            frame(10 + f);
        Row row;
        row.pieces = n;
        row.cpuMs = (processCpuMs() - cpu0) / o.frames;
        row.mainCpuMs = (threadCpuMs() - main0) / o.frames;
        row.wallMs =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - wall0).count() /
            o.frames;
        row.drawCalls = renderer.drawCalls();
        row.triangles = renderer.triangles();
        row.meshPieces = renderer.meshesDrawn();
        row.chipPieces = renderer.chipsDrawn();
        rows.push_back(row);
        if (!o.out.empty()) {
            std::string rgb;
            int w = 0, h = 0;
            gl->readPixels(rgb, w, h);
            std::filesystem::create_directories(o.out);
            const auto path = std::filesystem::path(o.out) / ("render_" + std::to_string(n) + ".png");
            if (!writePng(path, rgb, w, h)) {
                std::fprintf(stderr, "error: cannot write %s\n", path.string().c_str());
                return 1;
            }
        }
        renderer.shutdown();
        if (!o.json)
            std::fprintf(stderr, "render-bench: %d pieces done\n", n);
    }

    nlohmann::json list = nlohmann::json::array();
    for (const Row& r : rows)
        list.push_back({{"pieces", r.pieces},
                        {"moving", o.moving},
                        {"cpu_ms_per_frame", r.cpuMs},
                        {"main_cpu_ms_per_frame", r.mainCpuMs},
                        {"wall_ms_per_frame", r.wallMs},
                        {"draw_calls", r.drawCalls},
                        {"triangles", r.triangles},
                        {"mesh_pieces", r.meshPieces},
                        {"chip_pieces", r.chipPieces},
                        {"width", gl->width()},
                        {"height", gl->height()},
                        {"frames", o.frames},
                        {"renderer", gl->renderer()},
                        {"quality", quality.name()}});
    if (o.json) {
        std::printf("%s\n", list.dump(1).c_str());
    } else {
        std::printf("%8s %16s %21s %17s %10s %10s %11s %11s\n", "pieces", "cpu_ms_per_frame",
                    "main_cpu_ms_per_frame", "wall_ms_per_frame", "draw_calls", "triangles", "mesh_pieces",
                    "chip_pieces");
        for (const Row& r : rows)
            std::printf("%8d %16.2f %21.2f %17.2f %10d %10lld %11d %11d\n", r.pieces, r.cpuMs, r.mainCpuMs,
                        r.wallMs, r.drawCalls, r.triangles, r.meshPieces, r.chipPieces);
    }
    return 0;
}

} // namespace demo
