// `rubble fracture MESH... --impact X,Y,Z [--impulse F] [--cells K] [--seed S] [--backend corefine|nef|fast]
//                  -o DIR [--json] [--format obj|gltf]`
//
// Fractures closed meshes at an impact point (in each mesh's coordinates) like the runtime does: cells around
// the impact, booleans, islands, mass properties, then each piece's convex parts by the incremental update of
// the parent's decomposition. Writes DIR/piece_000.obj (+ .mtl, cut faces in the material "interior") ... or,
// with --format gltf, DIR/pieces.gltf (one node per piece at its centre of mass). Several meshes are
// fractured in parallel (batch pre-fracture), each into DIR/<mesh stem>/.
//
// Everything is computed before anything is written, and the output is staged in a sibling folder renamed to
// DIR at the end, so that an error leaves no partial output. SIGINT and SIGTERM are held back while the
// staging folder exists; staging folders of killed runs (".DIR.rubble-tmp-PID" of a dead PID) are removed.
// Exit codes: 0 every mesh fractured and written; 1 a fracture or a write failed (the other meshes are
// written); 2 unreadable or invalid mesh, or a usage error (nothing written); 3 the impact misses a mesh (no
// pieces for it; the other meshes are written).
// --json prints
// {"input":{"volume","triangles","closed"},"cut","dropped_volume","pieces":[{"volume","triangles",
// "closed","oriented","center_of_mass":[x,y,z],"convex_parts"}],"timings_ms":{"cell","boolean","islands",
// "decomposition","total"}} (with "error" added when the fracture failed); "cut" is false when no piece has a
// cut face (the one piece is the input), "dropped_volume" the volume of pieces below the drop fraction. With
// several meshes {"results":[...]} with one such object per mesh plus "file".
#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>
#include <thread>

#include <unistd.h>

#include <nlohmann/json.hpp>

#include "JsonText.hpp"
#include "Staging.hpp"
#include "Subcommand.hpp"
#include "rubble/ConvexDecomposition.hpp"
#include "rubble/Fracture.hpp"
#include "rubble/MeshCheck.hpp"
#include "rubble/MeshIO.hpp"
#include "rubble/ThreadPool.hpp"

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

constexpr int kExitOk = 0;
constexpr int kExitFailed = 1;
constexpr int kExitUsage = 2;
constexpr int kExitMissed = 3;

struct FractureArgs {
    std::vector<std::string> files;
    std::string impact;
    double impulse = rubble::Impact{}.impulse;
    int cells = 1;
    std::uint64_t seed = 1;
    std::string backend; // empty: the library's default
    std::string output;
    bool json = false;
    std::string format = "obj";
};

struct PieceOut {
    rubble::Mesh mesh;
    rubble::MassProperties mass;
    bool closed = false;
    bool oriented = false;
    std::size_t convexParts = 0;
};

enum class Outcome { Fractured, Missed, Failed, Invalid };

// Everything one mesh produced; written to disk only after every mesh is done.
struct MeshJob {
    std::string file;
    std::string folder; // sub-folder of DIR ("" for a single mesh)
    rubble::Mesh input;
    double inputVolume = 0;
    bool inputClosed = false;
    Outcome outcome = Outcome::Fractured;
    std::string message;
    std::vector<PieceOut> pieces;
    rubble::FractureTimings timings;
    double decompositionMs = 0; // the incremental update
    double parentDecompositionMs = 0;
    double droppedVolume = 0; // pieces below the drop fraction
    bool cut = false;         // some piece has a cut face (else the one piece is the input itself)
};

double msSince(Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

std::optional<rubble::Vec3> parsePoint(const std::string& text) {
    double v[3];
    const char* p = text.data();
    const char* end = text.data() + text.size();
    for (int i = 0; i < 3; ++i) {
        while (p < end && *p == ' ')
            ++p;
        const auto [next, ec] = std::from_chars(p, end, v[i]);
        if (ec != std::errc() || !std::isfinite(v[i]))
            return std::nullopt;
        p = next;
        while (p < end && *p == ' ')
            ++p;
        if (i < 2) {
            if (p == end || *p != ',')
                return std::nullopt;
            ++p;
        }
    }
    if (p != end)
        return std::nullopt;
    return rubble::Vec3{v[0], v[1], v[2]};
}

std::string num(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
}

std::string pieceName(std::size_t i) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "piece_%03zu", i);
    return buf;
}

// Fractures one validated mesh and updates its decomposition (runs on a worker).
void runJob(MeshJob& job, const rubble::Impact& impact, const rubble::FractureParams& params,
            std::uint64_t seed) {
    const auto tp = Clock::now();
    auto parent = rubble::decompose(job.input); // a game computes this once, at load time
    job.parentDecompositionMs = msSince(tp);
    auto fr = rubble::fracture(job.input, impact, params, seed);
    if (!fr) {
        job.outcome = fr.error().code == rubble::ErrorCode::NoIntersection ? Outcome::Missed
                      : fr.error().code == rubble::ErrorCode::InvalidInput ? Outcome::Invalid
                                                                           : Outcome::Failed;
        job.message = fr.error().message;
        return;
    }
    job.timings = fr->timings;
    job.droppedVolume = fr->droppedVolume;
    for (const rubble::Piece& piece : fr->pieces)
        job.cut = job.cut || std::find(piece.mesh.materials.begin(), piece.mesh.materials.end(),
                                       rubble::kInteriorMaterial) != piece.mesh.materials.end();
    const auto td = Clock::now();
    const std::vector<rubble::ConvexPolytope> none;
    const auto parts = rubble::updateDecomposition(parent ? parent->parts : none, *fr);
    job.decompositionMs = msSince(td);
    rubble::CheckOptions noSelfIntersections;
    noSelfIntersections.selfIntersections = false;
    for (std::size_t i = 0; i < fr->pieces.size(); ++i) {
        PieceOut out;
        const rubble::MeshReport r = rubble::checkMesh(fr->pieces[i].mesh, noSelfIntersections);
        out.closed = r.closed && r.manifold();
        out.oriented = r.oriented && r.outward;
        out.convexParts = i < parts.size() ? parts[i].size() : 0;
        out.mass = fr->pieces[i].mass;
        out.mesh = std::move(fr->pieces[i].mesh);
        job.pieces.push_back(std::move(out));
    }
}

nlohmann::json jsonOf(const MeshJob& job, bool withFile) {
    nlohmann::json j;
    if (withFile)
        j["file"] = rubble::tools::utf8Escaped(job.file);
    j["input"] = {
        {"volume", job.inputVolume}, {"triangles", job.input.triangleCount()}, {"closed", job.inputClosed}};
    j["cut"] = job.cut;
    j["dropped_volume"] = job.droppedVolume;
    j["pieces"] = nlohmann::json::array();
    for (const PieceOut& p : job.pieces) {
        const rubble::Vec3& c = p.mass.centerOfMass;
        j["pieces"].push_back({{"volume", p.mass.volume},
                               {"triangles", p.mesh.triangleCount()},
                               {"closed", p.closed},
                               {"oriented", p.oriented},
                               {"center_of_mass", {c.x, c.y, c.z}},
                               {"convex_parts", p.convexParts}});
    }
    j["timings_ms"] = {{"cell", job.timings.cellMs},
                       {"boolean", job.timings.booleanMs},
                       {"islands", job.timings.islandsMs},
                       {"decomposition", job.decompositionMs},
                       {"total", job.timings.totalMs + job.decompositionMs}};
    if (job.outcome == Outcome::Failed)
        j["error"] = rubble::tools::utf8Escaped(job.message);
    return j;
}

void printSummary(std::ostream& out, const MeshJob& job, const fs::path& dir) {
    if (job.outcome == Outcome::Missed) {
        out << job.file << ": the impact misses the mesh: no pieces (" << job.message << ")\n";
        return;
    }
    if (job.outcome == Outcome::Failed) {
        out << job.file << ": fracture failed: " << job.message << "\n";
        return;
    }
    double sum = 0;
    for (const PieceOut& p : job.pieces)
        sum += p.mass.volume;
    out << job.file << ": " << job.pieces.size() << (job.pieces.size() == 1 ? " piece" : " pieces")
        << " written to " << dir.string() << "\n";
    char line[160];
    std::snprintf(line, sizeof line, "  %-10s %9s %12s %6s %7s %9s  %s\n", "piece", "triangles", "volume",
                  "parts", "closed", "oriented", "centre of mass");
    out << line;
    for (std::size_t i = 0; i < job.pieces.size(); ++i) {
        const PieceOut& p = job.pieces[i];
        const rubble::Vec3& c = p.mass.centerOfMass;
        std::snprintf(line, sizeof line, "  %-10s %9zu %12s %6zu %7s %9s  (%s, %s, %s)\n",
                      pieceName(i).c_str(), p.mesh.triangleCount(), num(p.mass.volume).c_str(), p.convexParts,
                      p.closed ? "yes" : "NO", p.oriented ? "yes" : "NO", num(c.x).c_str(), num(c.y).c_str(),
                      num(c.z).c_str());
        out << line;
    }
    out << "  volume: input " << num(job.inputVolume) << ", pieces " << num(sum);
    if (job.droppedVolume > 0)
        out << ", dropped " << num(job.droppedVolume) << " (pieces below the drop fraction)";
    out << " (relative difference "
        << num(std::abs(sum + job.droppedVolume - job.inputVolume) / job.inputVolume) << ")\n";
    if (!job.cut)
        out << "  nothing was cut: the piece is the whole input (the impact's cells contain the whole mesh, "
               "or "
               "everything they cut off was below the drop fraction)\n";
    out << "  time: cells " << num(job.timings.cellMs) << " ms, booleans " << num(job.timings.booleanMs)
        << " ms, islands " << num(job.timings.islandsMs) << " ms, decomposition update "
        << num(job.decompositionMs) << " ms, total " << num(job.timings.totalMs + job.decompositionMs)
        << " ms (parent decomposition, "
        << "done once at load time: " << num(job.parentDecompositionMs) << " ms)\n";
}

rubble::Status writeJob(const MeshJob& job, const fs::path& dir, const std::string& format) {
    if (format == "gltf") {
        std::vector<rubble::GltfNode> nodes;
        for (std::size_t i = 0; i < job.pieces.size(); ++i)
            nodes.push_back({pieceName(i), job.pieces[i].mesh, job.pieces[i].mass.centerOfMass});
        return rubble::writeGltf(dir / "pieces.gltf", nodes);
    }
    for (std::size_t i = 0; i < job.pieces.size(); ++i) {
        rubble::ObjWriteOptions options;
        options.objectName = pieceName(i);
        if (rubble::Status s = rubble::writeObj(dir / (pieceName(i) + ".obj"), job.pieces[i].mesh, options);
            !s)
            return s;
    }
    return {};
}

// Draws "fracturing [=====     ] 2/5" on stderr (only called when stderr is a terminal).
void drawProgress(std::size_t done, std::size_t total) {
    const std::size_t width = 30;
    const std::size_t filled = total ? done * width / total : width;
    std::fprintf(stderr, "\rfracturing [%s%s] %zu/%zu", std::string(filled, '=').c_str(),
                 std::string(width - filled, ' ').c_str(), done, total);
    if (done == total)
        std::fprintf(stderr, "\n");
    std::fflush(stderr);
}

// Writes the fractured meshes into a staging folder next to DIR and renames it to DIR.
int commitOutput(const std::vector<MeshJob>& jobs, const fs::path& dir, const std::string& format,
                 bool batch) {
    std::error_code ec;
    const fs::path parent = dir.has_parent_path() ? dir.parent_path() : fs::path(".");
    fs::create_directories(parent, ec);
    rubble::tools::removeStaleStaging(parent); // left by earlier runs that were killed
    // SIGINT / SIGTERM wait until the staging folder is renamed or removed.
    const rubble::tools::DeferSignals deferred;
    const fs::path stage = rubble::tools::stagingPath(dir);
    fs::remove_all(stage, ec);
    auto fail = [&](const std::string& message) {
        std::cerr << "rubble fracture: " << message << "\n";
        fs::remove_all(stage, ec);
        return kExitFailed;
    };
    if (!fs::create_directory(stage, ec))
        return fail("cannot create " + stage.string() + ": " + ec.message());
    for (const MeshJob& job : jobs) {
        if (job.outcome != Outcome::Fractured)
            continue;
        const fs::path sub = batch ? stage / job.folder : stage;
        if (batch && !fs::create_directory(sub, ec))
            return fail("cannot create " + sub.string() + ": " + ec.message());
        if (rubble::Status s = writeJob(job, sub, format); !s)
            return fail(s.message());
    }
    if (fs::exists(dir, ec))
        fs::remove(dir, ec); // empty (checked before fracturing)
    fs::rename(stage, dir, ec);
    if (ec)
        return fail("cannot rename " + stage.string() + " to " + dir.string() + ": " + ec.message());
    return kExitOk;
}

int runFracture(const FractureArgs& args) {
    auto usage = [](const std::string& message) {
        std::cerr << "rubble fracture: " << message << "\n";
        return kExitUsage;
    };
    const auto point = parsePoint(args.impact);
    if (!point)
        return usage("--impact '" + args.impact + "' is not three finite numbers X,Y,Z");
    fs::path dir = fs::path(args.output).lexically_normal();
    if (!dir.has_filename() && dir.has_parent_path()) // "out/" names the folder "out"
        dir = dir.parent_path();
    if (dir.empty() || dir.filename() == "." || dir.filename() == "..")
        return usage("-o '" + args.output + "' does not name a folder to create");
    std::error_code ec;
    if (fs::exists(dir, ec) && (!fs::is_directory(dir, ec) || !fs::is_empty(dir, ec)))
        return usage("the output folder '" + args.output +
                     "' exists and is not an empty folder (choose another one or remove it)");

    rubble::FractureParams params;
    if (args.cells > 1) {
        params.pattern = rubble::CellPattern::Shatter;
        params.cells = args.cells;
    }
    if (args.backend == "corefine")
        params.backend = rubble::BooleanKind::Corefine;
    else if (args.backend == "nef")
        params.backend = rubble::BooleanKind::Nef;
    else if (args.backend == "fast")
        params.backend = rubble::BooleanKind::Fast;
    rubble::Impact impact;
    impact.point = *point;
    impact.impulse = args.impulse;

    // Read and validate every input first: a bad one stops everything before anything is computed or written.
    const bool batch = args.files.size() > 1;
    std::vector<MeshJob> jobs(args.files.size());
    std::set<std::string> folders;
    rubble::CheckOptions noSelfIntersections;
    noSelfIntersections.selfIntersections = false;
    for (std::size_t i = 0; i < args.files.size(); ++i) {
        MeshJob& job = jobs[i];
        job.file = args.files[i];
        job.folder = fs::path(job.file).stem().string();
        if (batch && !folders.insert(job.folder).second)
            return usage("two inputs would be written to the same folder '" + job.folder + "' (" + job.file +
                         ")");
        auto mesh = rubble::readMesh(job.file);
        if (!mesh)
            return usage(mesh.error().message);
        const rubble::MeshReport r = rubble::checkMesh(mesh.value(), noSelfIntersections);
        if (!r.valid())
            return usage(job.file + ": not a valid solid, cannot fracture it: " +
                         (r.problems.empty() ? std::string("invalid mesh") : r.problems.front()) +
                         " (see rubble check " + job.file + ")");
        job.inputClosed = r.closed;
        job.inputVolume = rubble::signedVolume(mesh.value());
        job.input = std::move(mesh.value());
    }

    // Fracture: inline for one mesh, on a thread pool for several.
    if (!batch) {
        runJob(jobs[0], impact, params, args.seed);
    } else {
        const int workers = static_cast<int>(
            std::min<std::size_t>(jobs.size(), std::max(1u, std::thread::hardware_concurrency())));
        const bool progress = ::isatty(STDERR_FILENO) == 1;
        std::mutex mutex;
        std::size_t done = 0;
        rubble::ThreadPool pool(workers);
        if (progress)
            drawProgress(0, jobs.size());
        for (MeshJob& job : jobs)
            pool.submit([&, j = &job] {
                runJob(*j, impact, params, args.seed);
                std::lock_guard lock(mutex);
                ++done;
                if (progress)
                    drawProgress(done, jobs.size());
            });
        pool.waitIdle();
    }

    int code = kExitOk;
    bool anyFractured = false;
    for (const MeshJob& job : jobs) {
        if (job.outcome == Outcome::Invalid)
            return usage(job.file + ": " + job.message);
        if (job.outcome == Outcome::Failed)
            code = kExitFailed;
        else if (job.outcome == Outcome::Missed && code == kExitOk)
            code = kExitMissed;
        anyFractured |= job.outcome == Outcome::Fractured;
    }
    if (anyFractured)
        if (const int written = commitOutput(jobs, dir, args.format, batch); written != kExitOk)
            return written;

    std::ostream& text = args.json ? std::cerr : std::cout;
    for (const MeshJob& job : jobs)
        if (!args.json || job.outcome != Outcome::Fractured)
            printSummary(text, job, batch ? dir / job.folder : dir);
        else if (!job.cut)
            text << job.file << ": nothing was cut: the piece is the whole input\n";
    if (args.json) {
        nlohmann::json doc;
        if (batch) {
            doc["results"] = nlohmann::json::array();
            for (const MeshJob& job : jobs)
                doc["results"].push_back(jsonOf(job, true));
        } else {
            doc = jsonOf(jobs[0], false);
        }
        std::cout << rubble::tools::dumpJson(doc) << "\n";
    }
    return code;
}

const rubble::tools::Registrar registrar{
    {"fracture", "Fracture meshes at an impact point; write the pieces (OBJ or glTF) with their convex parts",
     [](CLI::App& app) {
         auto args = std::make_shared<FractureArgs>();
         app.footer(
             "The impact point is in each mesh's own coordinates. Pieces are written as DIR/piece_000.obj "
             "... "
             "(cut faces use the material 'interior' in the .mtl) or DIR/pieces.gltf (--format gltf, one "
             "node "
             "per piece at its centre of mass); with several meshes each goes to DIR/<mesh stem>/, fractured "
             "in "
             "parallel. DIR must not exist or be empty; nothing is written unless the inputs are valid.\n"
             "Exit codes: 0 every mesh fractured and written; 1 a fracture or a write failed (the other "
             "meshes "
             "are written); 2 unreadable or invalid mesh, or a usage error (nothing written); 3 the impact "
             "misses a mesh: no pieces for it (the other meshes are written).\n"
             "--json timings_ms: cell, boolean, islands as in the fracture kernel; decomposition is the "
             "incremental update of the parent's convex parts (the parent's own decomposition is a load-time "
             "cost and not counted); total = fracture + decomposition.");
         app.add_option("meshes", args->files,
                        "closed mesh files (.obj, .off, .stl, .ply, .3ds, .gltf, .glb)")
             ->required();
         app.add_option("--impact", args->impact, "impact point X,Y,Z in the mesh's coordinates")->required();
         const rubble::CellSizeLaw law;
         app.add_option("--impulse", args->impulse,
                        "impact impulse (N s); the cut region's edge is " + num(law.base) + " + " +
                            num(law.scale) + " impulse^" + num(law.exponent) + ", clamped to [" +
                            num(law.minSize) + ", " + num(law.maxSize) + "]")
             ->check(rubble::tools::finiteNumber())
             ->check(CLI::Range(0.0, 1e12))
             ->capture_default_str();
         app.add_option("--cells", args->cells,
                        "1: the thesis's single Voronoi cell; K > 1: shatter into K cells")
             ->check(CLI::Range(1, rubble::kMaxShatterCells))
             ->capture_default_str();
         app.add_option("--seed", args->seed, "random seed (same seed, same pieces, byte for byte)")
             ->check(rubble::tools::unsigned64())
             ->capture_default_str();
         app.add_option("--backend", args->backend, "boolean backend (default: the library's default)")
             ->check(CLI::IsMember({"corefine", "nef", "fast"}));
         app.add_option("-o,--output", args->output, "output folder (must not exist, or be empty)")
             ->required();
         app.add_flag("--json", args->json, "print the results as JSON on stdout (messages go to stderr)");
         app.add_option("--format", args->format, "output format of the pieces")
             ->check(CLI::IsMember({"obj", "gltf"}))
             ->capture_default_str();
         return [args] { return runFracture(*args); };
     }}};

} // namespace
