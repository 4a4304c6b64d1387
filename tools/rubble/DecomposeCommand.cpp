// `rubble decompose MESH [--max-parts N] [--concavity C] [--json] [-o PARTS.json]`
//
// Approximate convex decomposition of a closed mesh. Prints the number of convex parts, the mesh and hull
// volumes, the excess (hull − mesh) / mesh, the concavity (rubble/collision/PartConcavity.hpp) and the time
// taken;
// --json prints {"parts","mesh_volume","hull_volume","excess","concavity","ms"}. -o writes the parts
// (rubble/io/DecompositionFile.hpp); as MESH's stem.parts.json beside it, a scene loads them instead of
// decomposing. Exit codes: 0 success, 1 the mesh cannot be decomposed (e.g. open or inside out) or the parts
// cannot be written, 2 unreadable file or usage error, 130 cancelled (Ctrl-C). With --json a failure prints
// {"file","error"}. On a terminal, progress is drawn on stderr; --threads shares the search between threads.
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <thread>

#include <nlohmann/json.hpp>

#include "JsonText.hpp"
#include "Subcommand.hpp"
#include "rubble/collision/ConvexDecomposition.hpp"
#include "rubble/collision/DecomposeControl.hpp"
#include "rubble/collision/PartConcavity.hpp"
#include "rubble/core/ThreadPool.hpp"
#include "rubble/io/DecompositionFile.hpp"
#include "rubble/io/MeshIO.hpp"

namespace {

/// Exit code of a decomposition cancelled by Ctrl-C (128 + SIGINT, as a shell reports it).
constexpr int kExitCancelled = 130;

/// Set by SIGINT while a decomposition runs.
std::atomic<bool> interrupted{false};
static_assert(std::atomic<bool>::is_always_lock_free);

extern "C" void onInterrupt(int) {
    interrupted.store(true);
}

/// Routes SIGINT to `interrupted` while alive; restores the previous handler after.
class InterruptToCancel {
public:
    InterruptToCancel() { previous_ = std::signal(SIGINT, onInterrupt); }
    ~InterruptToCancel() { std::signal(SIGINT, previous_); }
    InterruptToCancel(const InterruptToCancel&) = delete;
    InterruptToCancel& operator=(const InterruptToCancel&) = delete;

private:
    void (*previous_)(int) = SIG_DFL;
};

/// Draws "decomposing [====    ]  42%" on stderr.
void drawProgress(double fraction) {
    const int width = 30;
    const int filled = static_cast<int>(fraction * width);
    std::fprintf(stderr, "\rdecomposing [%s%s] %3d%%", std::string(filled, '=').c_str(),
                 std::string(width - filled, ' ').c_str(), static_cast<int>(fraction * 100));
    std::fflush(stderr);
}

struct DecomposeArgs {
    std::string file;
    int maxParts = rubble::DecompositionParams{}.maxParts;
    double concavity = rubble::DecompositionParams{}.concavity;
    bool json = false;
    std::string output;
    std::size_t proxyAbove = rubble::DecompositionParams{}.proxyAboveTriangles;
    std::size_t maxPartFaces = rubble::DecompositionParams{}.maxPartFaces;
    int threads = 0; // 0: hardware threads
};

int runDecompose(const DecomposeArgs& args) {
    // A failure prints its message on stderr and, with --json, {"file","error"} on stdout.
    auto failed = [&](int code, const std::string& message) {
        std::cerr << "rubble decompose: " << message << "\n";
        if (args.json)
            std::cout << rubble::tools::dumpJson({{"file", rubble::tools::utf8Escaped(args.file)},
                                                  {"error", rubble::tools::utf8Escaped(message)}})
                      << "\n";
        return code;
    };
    auto mesh = rubble::readMesh(args.file);
    if (!mesh)
        return failed(2, mesh.error().message);
    rubble::DecompositionParams params;
    params.maxParts = args.maxParts;
    params.concavity = args.concavity;
    params.proxyAboveTriangles = args.proxyAbove;
    params.maxPartFaces = args.maxPartFaces;
    const int threads =
        args.threads > 0 ? args.threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    std::optional<rubble::ThreadPool> pool;
    rubble::DecomposeControl control;
    if (threads > 1) {
        pool.emplace(threads - 1);
        control.jobs = &*pool;
    }
    const bool drawn = ::isatty(STDERR_FILENO) == 1;
    if (drawn)
        control.progress = [](double fraction) {
            drawProgress(fraction);
            return true;
        };
    control.cancel = &interrupted;
    const auto t0 = std::chrono::steady_clock::now();
    auto d = [&] {
        const InterruptToCancel routed;
        return rubble::decompose(mesh.value(), params, control);
    }();
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    if (drawn)
        std::fprintf(stderr, "\n");
    if (!d && d.error().code == rubble::ErrorCode::Cancelled)
        return failed(kExitCancelled, args.file + ": cancelled, nothing written");
    if (!d)
        return failed(1, args.file + ": " + d.error().message);
    if (!args.output.empty()) {
        const rubble::DecompositionFile file{mesh->hash(), d->meshVolume, d->parts};
        if (const rubble::Status s = rubble::writeDecompositionFile(args.output, file); !s)
            return failed(1, s.message());
    }
    const double concavity = rubble::partConcavity(mesh.value(), d->parts);
    if (args.json) {
        nlohmann::json j;
        j["parts"] = d->parts.size();
        j["mesh_volume"] = d->meshVolume;
        j["hull_volume"] = d->hullVolume;
        j["excess"] = d->excess();
        j["concavity"] = concavity;
        j["ms"] = ms;
        std::cout << rubble::tools::dumpJson(j) << "\n";
    } else {
        std::cout << args.file << ": " << d->parts.size()
                  << (d->parts.size() == 1 ? " convex part" : " convex parts") << "\n  mesh volume  "
                  << d->meshVolume << "\n  hull volume  " << d->hullVolume << "\n  excess       "
                  << d->excess() << "\n  concavity    " << concavity << " of the diagonal\n  time         "
                  << ms << " ms\n";
    }
    return 0;
}

const rubble::tools::Registrar registrar{
    {"decompose", "Approximate convex decomposition of a closed mesh (collision shapes)", [](CLI::App& app) {
         auto args = std::make_shared<DecomposeArgs>();
         app.footer(
             "Exit codes: 0 success, 1 the mesh cannot be decomposed (open or inside out) or the parts "
             "cannot be written, 2 unreadable file or usage error, 130 cancelled by Ctrl-C (nothing "
             "written).");
         app.add_option("mesh", args->file, "mesh file (.obj, .off, .stl, .ply, .3ds, .gltf, .glb)")
             ->required();
         app.add_option("--max-parts", args->maxParts, "at most this many convex parts")
             ->check(CLI::Range(1, rubble::kMaxConvexParts))
             ->capture_default_str();
         app.add_option("--concavity", args->concavity,
                        "stop splitting below this depth, as a fraction of the bounding-box diagonal")
             ->check(rubble::tools::finiteNumber())
             ->check(CLI::Range(0.0, 1.0));
         app.add_option("--proxy-above", args->proxyAbove,
                        "search meshes with more triangles through a bounded proxy (default 20000)");
         app.add_option("--max-part-faces", args->maxPartFaces, "bound parts with more faces (default 512)")
             ->check(CLI::Range(std::size_t{8}, std::size_t{1} << 30));
         app.add_option("--threads", args->threads, "threads that share the search (default: all cores)")
             ->check(CLI::Range(1, 256));
         app.add_option("-o,--output", args->output,
                        "write the parts as JSON (MESH-stem.parts.json beside the mesh is loaded by scenes)");
         app.add_flag("--json", args->json,
                      "print {\"parts\",\"mesh_volume\",\"hull_volume\",\"excess\",\"concavity\",\"ms\"} as "
                      "JSON");
         return [args] { return runDecompose(*args); };
     }}};

} // namespace
