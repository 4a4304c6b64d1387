// `rubble-bench decomposition [--quick] [--runs N] [--out DIR]`
//
// Convex decomposition cost per subdivided cube (12 .. 10,092 triangles, like the thesis's Table 3.2) and per
// seed model when ../shared/seed/media is present: the initial decomposition of the whole object and the
// incremental update at fracture time (parent parts clipped by one Voronoi cell at (0.99, 0, 0), fragments
// assigned to the pieces). Reference columns: the thesis's HACD decomposition times (Table 3.2) and the
// thesis's program measured on this machine, with the speed-up of the incremental update against them.
// Table on stdout, CSV in DIR/decomposition.csv, plot in DIR/decomposition.png (gnuplot).
//
// --organic: organic meshes generated here (a body with seven limbs, a bumpy potato; bench/MegaMeshes.hpp) at
// 5k, 20k and 100k triangles, each decomposed side by side in the same run by: Rubble on one thread, on two,
// Rubble searching through its bounded proxy at every size (the cheaper first pass), and Qhull's hull of the
// whole (the floor: one part); the exact search at 20k and 100k, and up to 32 parts. Held-out meshes (CGAL's
// armadillo, camel...) are added when found (--held-out DIR, else ../shared and /usr/share/doc/libcgal*).
// Columns: wall and CPU time, parts, volume excess, Hausdorff concavity (rubble/collision/PartConcavity.hpp);
// DIR/decomposition_organic.csv and .png.
#include <sys/resource.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <sstream>

#include "BenchUtil.hpp"
#include "MegaMeshes.hpp"
#include "Subcommand.hpp"
#include "VoxelDecomposition.hpp"
#include "rubble/collision/ConvexDecomposition.hpp"
#include "rubble/collision/DecomposeControl.hpp"
#include "rubble/collision/PartConcavity.hpp"
#include "rubble/core/Random.hpp"
#include "rubble/core/ThreadPool.hpp"
#include "rubble/fracture/Fracture.hpp"
#include "rubble/geometry/MassProperties.hpp"
#include "rubble/io/MeshIO.hpp"

namespace {

namespace fs = std::filesystem;
using rubble::bench::fixed;
using rubble::bench::Stats;
using rubble::bench::timeIt;

/// The kinds --mega-kinds accepts.
std::vector<std::string> allKinds() {
    std::vector<std::string> kinds = rubble::bench::kMegaKinds;
    kinds.insert(kinds.end(), rubble::bench::kOrganicKinds.begin(), rubble::bench::kOrganicKinds.end());
    return kinds;
}

struct BenchArgs {
    bool quick = false;
    int runs = 15;
    std::string out = rubble::bench::resultsDir();
    std::vector<std::string> methods; // --organic: only these methods (all when empty)
};

/// The Voronoi cell of `site` among 15 random sites in a cube of edge `size` around it.
rubble::ConvexPolytope voronoiCell(const rubble::Vec3& site, double size, std::uint64_t seed) {
    rubble::Rng rng(seed);
    const rubble::Vec3 h{size / 2, size / 2, size / 2};
    rubble::ConvexPolytope cell = rubble::ConvexPolytope::fromAabb({site - h, site + h});
    for (int i = 0; i < 15; ++i) {
        const rubble::Vec3 other = rng.inBox(site - h, site + h);
        cell = cell.clipped(rubble::Plane::fromPointNormal((site + other) * 0.5, other - site), i);
    }
    return cell;
}

struct Row {
    std::string name;
    std::size_t triangles = 0;
    std::size_t parts = 0;
    double excess = 0;
    Stats initial, update;
    std::size_t updatedParts = 0;
    std::string pieces; // how pieces were made
    double thesisS = -1, seedS = -1;
};

Row measure(const std::string& name, const rubble::Mesh& mesh, const rubble::Vec3& impact, int runs) {
    Row row;
    row.name = name;
    row.triangles = mesh.triangles.size();
    std::optional<rubble::Decomposition> d;
    row.initial = timeIt(runs, [&] { d = rubble::decompose(mesh).value(); });
    row.parts = d->parts.size();
    row.excess = d->excess();
    // Pieces of one fracture by a cell at the impact.
    const double size = 0.5 * mesh.bounds().size().x + 1e-9;
    std::vector<rubble::ConvexPolytope> cells{voronoiCell(impact, size, 1)};
    std::vector<rubble::Mesh> pieces;
    std::vector<std::int32_t> pieceCells;
    rubble::FractureParams fp;
    fp.backend = rubble::BooleanKind::Fast;
    auto fr = rubble::fractureWithCells(mesh, cells, fp);
    if (fr) {
        for (const rubble::Piece& p : fr->pieces) {
            pieces.push_back(p.mesh);
            pieceCells.push_back(p.cell);
        }
        row.pieces = "fracture";
    } else {
        // Stand-in pieces: the input as the remainder, the clipped cell as the debris.
        rubble::ConvexPolytope debris = rubble::ConvexPolytope::fromAabb(mesh.bounds());
        for (const rubble::PolytopeFaceView& f : cells[0].faces())
            debris = debris.clipped(f.plane);
        pieces = {mesh, debris.toMesh()};
        pieceCells = {-1, 0};
        row.pieces = "stand-in (" + fr.error().message.substr(0, 40) + ")";
    }
    std::vector<std::vector<rubble::ConvexPolytope>> updated;
    row.update =
        timeIt(runs, [&] { updated = rubble::updateDecomposition(d->parts, cells, pieces, pieceCells); });
    for (const auto& u : updated)
        row.updatedParts += u.size();
    return row;
}

int runBench(const BenchArgs& args) {
    const int runs = args.quick ? 1 : std::max(1, args.runs);
    // Thesis Table 3.2 (HACD, seconds) and the thesis's program measured here (seconds).
    const std::vector<int> grid = args.quick ? std::vector<int>{1, 3} : std::vector<int>{1, 3, 7, 15, 29};
    const std::map<std::size_t, std::pair<double, double>> reference = {{12, {0.118, 0.191}},
                                                                        {108, {0.135, 0.210}},
                                                                        {588, {0.261, 0.223}},
                                                                        {2700, {2.362, 1.120}},
                                                                        {10092, {12.007, 5.099}}};
    const rubble::bench::CpuMeter cpu; // the cases are short: one reading for all of them
    std::vector<Row> rows;
    for (int n : grid) {
        const rubble::Mesh cube = rubble::makeSubdividedBox({-1, -1, -1}, {1, 1, 1}, n);
        Row r = measure("cube_" + std::to_string(cube.triangles.size()), cube, {0.99, 0, 0}, runs);
        if (auto it = reference.find(r.triangles); it != reference.end()) {
            r.thesisS = it->second.first;
            r.seedS = it->second.second;
        }
        rows.push_back(r);
    }
    const fs::path media = rubble::bench::sourceDir() / ".." / "shared" / "seed" / "media";
    if (!args.quick && fs::is_directory(media)) {
        for (const char* name : {"building.obj", "missile.obj", "ship.obj", "empty.obj"}) {
            auto mesh = rubble::readMesh(media / name);
            if (!mesh) {
                std::cerr << "decomposition: skipping " << name << ": " << mesh.error().message << "\n";
                continue;
            }
            const rubble::Aabb b = mesh->bounds();
            const rubble::Vec3 impact{b.hi.x - 0.01 * b.size().x, b.center().y, b.center().z};
            rows.push_back(measure(name, mesh.value(), impact, runs));
        }
    } else if (!args.quick) {
        std::cout << "(seed media not found at " << media.string() << ": seed models skipped)\n";
    }

    const double otherCpu = cpu.read().other;
    rubble::bench::Table table{{"model", "tris", "parts", "excess", "initial med ms", "min", "max",
                                "update med ms", "min", "max", "thesis s", "seed s", "x thesis", "x seed"},
                               {}};
    rubble::bench::Table csv{{"model", "triangles", "parts", "excess", "runs", "initial_median_ms",
                              "initial_min_ms", "initial_max_ms", "update_median_ms", "update_min_ms",
                              "update_max_ms", "updated_parts", "pieces", "thesis_hacd_s", "seed_program_s",
                              "speedup_vs_thesis", "speedup_vs_seed", "other_cpu_cores"},
                             {}};
    auto str = [](auto v) {
        std::ostringstream o;
        o << v;
        return o.str();
    };
    std::ostringstream data;
    for (const Row& r : rows) {
        const bool ref = r.thesisS > 0;
        const double xThesis = ref ? r.thesisS * 1000 / r.update.median : -1;
        const double xSeed = ref ? r.seedS * 1000 / r.update.median : -1;
        table.rows.push_back({r.name, str(r.triangles), str(r.parts), fixed(r.excess, 4),
                              fixed(r.initial.median), fixed(r.initial.min), fixed(r.initial.max),
                              fixed(r.update.median), fixed(r.update.min), fixed(r.update.max),
                              ref ? fixed(r.thesisS) : "", ref ? fixed(r.seedS) : "", fixed(xThesis, 0),
                              fixed(xSeed, 0)});
        csv.rows.push_back({r.name, str(r.triangles), str(r.parts), str(r.excess), str(runs),
                            str(r.initial.median), str(r.initial.min), str(r.initial.max),
                            str(r.update.median), str(r.update.min), str(r.update.max), str(r.updatedParts),
                            r.pieces, ref ? str(r.thesisS) : "", ref ? str(r.seedS) : "",
                            ref ? str(xThesis) : "", ref ? str(xSeed) : "",
                            rubble::bench::fixed(otherCpu, 2)});
        if (ref)
            data << r.triangles << " " << r.initial.median << " " << r.update.median << " "
                 << r.thesisS * 1000 << " " << r.seedS * 1000 << "\n";
    }
    rubble::bench::printTable(table);
    std::cout << "runs per case: " << runs
              << "; update = parent parts clipped by one cell, fragments assigned to "
              << (rows.empty() ? "" : rows[0].pieces) << " pieces\n";
    if (!rubble::bench::writeCsv(fs::path(args.out) / "decomposition.csv", csv))
        return 1;
    rubble::bench::plotPng(args.out, "decomposition", data.str(),
                           "set logscale xy\nset xlabel 'cube triangles'\nset ylabel 'time (ms)'\nset grid\n"
                           "set key top left\nset title 'Convex decomposition: Rubble vs the thesis (HACD)'\n"
                           "plot $DATA u 1:4 w lp t 'thesis Table 3.2 (HACD)', '' u 1:5 w lp t "
                           "'thesis program measured here', '' u 1:2 w lp t 'Rubble initial decomposition', "
                           "'' u 1:3 w lp t 'Rubble incremental update'");
    return 0;
}

/// CPU time of this process (all threads), in milliseconds.
double cpuMs() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return (u.ru_utime.tv_sec + u.ru_stime.tv_sec) * 1e3 + (u.ru_utime.tv_usec + u.ru_stime.tv_usec) * 1e-3;
}

/// One decomposition method of the organic rows.
struct Method {
    std::string name;
    int threads = 1;
    bool hullOnly = false;          // Qhull's hull of the whole mesh
    std::size_t proxyAbove = 20000; // DecompositionParams::proxyAboveTriangles
    std::size_t maxTriangles = std::numeric_limits<std::size_t>::max(); // larger meshes skip the method
    int maxParts = 24;                                                  // DecompositionParams::maxParts
    bool voxel = false; // the voxel baseline (VoxelDecomposition.hpp)
};

/// An organic row's mesh: generated here, or a held-out file.
struct OrganicCase {
    std::string name, series;
    rubble::Mesh mesh;
};

/// Held-out meshes (CGAL's data set: armadillo, camel, elephant...) under dir, or when dir is empty under
/// ../shared and /usr/share/doc/libcgal*; the first file of each name, in path order. Never committed.
std::vector<fs::path> heldOutMeshes(const std::string& dir) {
    std::vector<fs::path> roots;
    std::error_code ec;
    if (!dir.empty()) {
        roots.push_back(dir);
    } else {
        roots.push_back(rubble::bench::sourceDir() / ".." / "shared");
        for (const auto& e : fs::directory_iterator("/usr/share/doc", ec))
            if (e.path().filename().string().rfind("libcgal", 0) == 0)
                roots.push_back(e.path());
    }
    const std::vector<std::string> names = {"armadillo", "camel", "elephant", "dragon",
                                            "bunny",     "cow",   "homer"};
    const std::vector<std::string>& extensions = rubble::supportedMeshExtensions();
    std::map<std::string, std::pair<std::string, fs::path>> found; // name -> (stem, file)
    for (const fs::path& root : roots) {
        std::vector<fs::path> files;
        for (auto it =
                 fs::recursive_directory_iterator(root, fs::directory_options::skip_permission_denied, ec);
             !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
            if (it.depth() > 6)
                it.disable_recursion_pending();
            if (it->is_regular_file(ec))
                files.push_back(it->path());
        }
        std::sort(files.begin(), files.end());
        for (const fs::path& f : files) {
            std::string stem = f.stem().string(), ext = f.extension().string();
            std::transform(stem.begin(), stem.end(), stem.begin(),
                           [](unsigned char c) { return std::tolower(c); });
            std::transform(ext.begin(), ext.end(), ext.begin(),
                           [](unsigned char c) { return std::tolower(c); });
            if (std::find(extensions.begin(), extensions.end(), ext) == extensions.end())
                continue;
            // Per name, the file whose stem is the name, else the shortest stem holding it (CGAL's
            // ChineseDragon-10kv; elephant before elephant-with-holes).
            for (const std::string& n : names)
                if (stem.find(n) != std::string::npos) {
                    auto it = found.find(n);
                    if (it == found.end() || (it->second.first != n && stem.size() < it->second.first.size()))
                        found[n] = {stem, f};
                }
        }
    }
    std::vector<fs::path> out;
    for (const auto& [n, f] : found)
        out.push_back(f.second);
    return out;
}

/// The share of the mesh's vertices (every k-th, at most 2000) that lie in no part, beyond 1e-9 of the
/// diagonal.
double uncoveredShare(const rubble::Mesh& mesh, const std::vector<rubble::ConvexPolytope>& parts) {
    const std::size_t stride = std::max<std::size_t>(1, mesh.positions.size() / 2000);
    const double eps = 1e-9 * mesh.bounds().diagonal();
    std::size_t sampled = 0, out = 0;
    for (std::size_t v = 0; v < mesh.positions.size(); v += stride) {
        ++sampled;
        out += std::none_of(parts.begin(), parts.end(), [&](const rubble::ConvexPolytope& p) {
            return p.contains(mesh.positions[v], eps);
        });
    }
    return sampled ? static_cast<double>(out) / static_cast<double>(sampled) : 0;
}

int runOrganic(const BenchArgs& args, const std::string& heldOutDir) {
    const int runs = args.quick ? 1 : std::max(1, std::min(args.runs, 5));
    const std::vector<std::size_t> sizes =
        args.quick ? std::vector<std::size_t>{2000} : std::vector<std::size_t>{5000, 20000, 100000};
    const std::vector<Method> methods = {
        {"rubble", 1, false, rubble::DecompositionParams{}.proxyAboveTriangles},
        {"rubble_2_threads", 2, false, rubble::DecompositionParams{}.proxyAboveTriangles},
        {"rubble_proxy_always", 1, false, 0},
        {"qhull_hull", 1, true, 0},
        // The exact search on a mesh just above the threshold, as on one just under it (e.g. CGAL's camel).
        {"rubble_exact", 1, false, std::numeric_limits<std::size_t>::max(), 30000},
        {"rubble_exact_2_threads", 2, false, std::numeric_limits<std::size_t>::max(), 30000},
        // The budget: at most 32 parts.
        {"rubble_32_parts", 1, false, rubble::DecompositionParams{}.proxyAboveTriangles,
         std::numeric_limits<std::size_t>::max(), 32},
        {"rubble_exact_32_parts", 1, false, std::numeric_limits<std::size_t>::max(), 30000, 32},
        // A V-HACD-style voxel method written here, at the same budget (VoxelDecomposition.hpp).
        {"voxel_32_parts", 1, false, 0, std::numeric_limits<std::size_t>::max(), 32, true}};
    std::vector<OrganicCase> cases;
    for (const std::string& kind : rubble::bench::kOrganicKinds)
        for (std::size_t size : sizes) {
            OrganicCase c{"", kind, rubble::bench::megaMesh(kind, size)};
            c.name = kind + "_" + std::to_string(c.mesh.triangles.size());
            cases.push_back(std::move(c));
        }
    if (!args.quick || !heldOutDir.empty()) {
        const std::vector<fs::path> heldOut = heldOutMeshes(heldOutDir);
        if (heldOut.empty())
            std::cout << "(no held-out meshes (CGAL's armadillo, camel, ...) found"
                      << (heldOutDir.empty() ? " under ../shared or /usr/share/doc/libcgal*"
                                             : " in " + heldOutDir)
                      << ": held-out rows skipped)\n";
        for (const fs::path& f : heldOut) {
            auto mesh = rubble::readMesh(f);
            if (!mesh) {
                std::cout << "(held-out " << f.string() << " skipped: " << mesh.error().message << ")\n";
                continue;
            }
            cases.push_back({"held_out_" + f.stem().string(), "held-out", std::move(mesh.value())});
        }
    }
    const rubble::bench::CpuMeter cpu;
    int status = 0;
    rubble::bench::Table table{
        {"mesh", "tris", "method", "parts", "wall med ms", "cpu med ms", "excess", "concavity", "uncovered"},
        {}};
    rubble::bench::Table csv{{"mesh", "triangles", "method", "threads", "runs", "parts", "wall_median_ms",
                              "wall_min_ms", "wall_max_ms", "cpu_median_ms", "excess", "concavity",
                              "uncovered_vertices", "other_cpu_cores"},
                             {}};
    std::map<std::string, std::ostringstream> series; // kind + method -> "triangles cpu_ms concavity" lines
    for (const OrganicCase& oc : cases) {
        const rubble::Mesh& mesh = oc.mesh;
        for (const Method& m : methods) {
            if (mesh.triangles.size() > m.maxTriangles ||
                (!args.methods.empty() &&
                 std::find(args.methods.begin(), args.methods.end(), m.name) == args.methods.end()))
                continue;
            std::optional<rubble::ThreadPool> pool;
            rubble::DecomposeControl control;
            if (m.threads > 1) {
                pool.emplace(m.threads - 1);
                control.jobs = &*pool;
            }
            rubble::DecompositionParams params;
            params.proxyAboveTriangles = m.proxyAbove;
            params.maxParts = m.maxParts;
            std::vector<double> wall, cpuTime;
            rubble::Decomposition d;
            bool failed = false;
            for (int r = 0; r < runs && !failed; ++r) {
                const auto t0 = std::chrono::steady_clock::now();
                const double c0 = cpuMs();
                if (m.voxel) {
                    rubble::bench::VoxelParams vp;
                    vp.maxParts = m.maxParts;
                    if (args.quick)
                        vp.cells = 24; // the smoke run checks the method, not its resolution
                    if (auto got = rubble::bench::voxelDecompose(mesh, vp)) {
                        d = std::move(got.value());
                    } else {
                        std::cout << "(" << oc.name << ", " << m.name << ": " << got.error().message << ")\n";
                        failed = true;
                    }
                } else if (m.hullOnly) {
                    d = {};
                    d.parts.push_back(rubble::convexHull(mesh.positions).value());
                    d.meshVolume = rubble::signedVolume(mesh);
                    d.hullVolume = d.parts[0].volume();
                } else if (auto got = rubble::decompose(mesh, params, control)) {
                    d = std::move(got.value());
                } else {
                    std::cout << "(" << oc.name << ", " << m.name << ": " << got.error().message << ")\n";
                    failed = true;
                }
                cpuTime.push_back(cpuMs() - c0);
                wall.push_back(rubble::bench::msSince(t0));
            }
            if (failed)
                continue;
            const Stats w = rubble::bench::stats(wall), c = rubble::bench::stats(cpuTime);
            const double concavity = rubble::partConcavity(mesh, d.parts);
            const double uncovered = uncoveredShare(mesh, d.parts);
            // The voxel parts hold every solid voxel, and each vertex lies in one (a check of the baseline).
            if (m.voxel && uncovered > 0) {
                std::cout << "(" << oc.name << ", " << m.name << ": " << uncovered
                          << " of the sampled vertices lie in no part)\n";
                status = 1;
            }
            table.rows.push_back({oc.name, std::to_string(mesh.triangles.size()), m.name,
                                  std::to_string(d.parts.size()), fixed(w.median), fixed(c.median),
                                  fixed(d.excess(), 4), fixed(concavity, 4), fixed(uncovered, 4)});
            csv.rows.push_back({oc.name, std::to_string(mesh.triangles.size()), m.name,
                                std::to_string(m.threads), std::to_string(runs),
                                std::to_string(d.parts.size()), fixed(w.median), fixed(w.min), fixed(w.max),
                                fixed(c.median), fixed(d.excess(), 5), fixed(concavity, 5),
                                fixed(uncovered, 5), ""});
            series[oc.series + " " + m.name] << mesh.triangles.size() << " " << c.median << " " << concavity
                                             << "\n";
        }
    }
    const std::string other = fixed(cpu.read().other, 2);
    for (auto& row : csv.rows)
        row.back() = other;
    rubble::bench::printTable(table);
    std::cout << "runs per case: " << runs << "; other_cpu_cores " << other
              << " (the rest of the machine's busy cores during the run)\n";
    if (!rubble::bench::writeCsv(fs::path(args.out) / "decomposition_organic.csv", csv))
        return 1;
    // Two panels: CPU time and concavity against triangles, one line per mesh series and method.
    std::ostringstream data, plot, lines;
    int block = 0;
    for (auto& [label, rows] : series) {
        data << rows.str() << "\n\n";
        lines << (block ? ", " : "") << "$DATA index " << block << " u 1:COLUMN w lp t '" << label << "'";
        ++block;
    }
    auto panel = [&](int column) {
        std::string s = lines.str();
        for (std::size_t at; (at = s.find("COLUMN")) != std::string::npos;)
            s.replace(at, 6, std::to_string(column));
        return s;
    };
    plot << "set multiplot layout 1,2 title 'Organic meshes per method (other cores busy: " << other
         << ")' noenhanced\nset logscale x\nset xlabel 'triangles'\nset grid\nset key bottom right font ',6' "
            "noenhanced\nset logscale y\nset ylabel 'CPU time, all threads (ms)'\nplot "
         << panel(2)
         << "\nunset logscale y\nset ylabel 'concavity (Hausdorff, of the diagonal)'\nset key top "
         << "right font ',6' noenhanced\nplot " << panel(3) << "\nunset multiplot\n";
    rubble::bench::plotPng(args.out, "decomposition_organic", data.str(), plot.str());
    return status;
}

const rubble::tools::Registrar registrar{
    {"decomposition", "Convex decomposition: initial and incremental update per cube size and seed model",
     [](CLI::App& app) {
         auto args = std::make_shared<BenchArgs>();
         app.add_flag("--quick", args->quick, "one repetition, small cubes only (CI smoke run)");
         app.add_option("--runs", args->runs, "repetitions per case")->check(CLI::Range(1, 10000));
         app.add_option("--out", args->out, "folder for decomposition.csv and decomposition.png");
         auto organic = std::make_shared<bool>(false);
         auto heldOut = std::make_shared<std::string>();
         app.add_option(
             "--held-out", *heldOut,
             "folder of held-out meshes for the --organic rows (CGAL's armadillo, camel, elephant, "
             "dragon, bunny, cow, homer; default: ../shared and /usr/share/doc/libcgal*)");
         app.add_option("--methods", args->methods,
                        "--organic: only these methods (rubble, rubble_exact, voxel_32_parts, ...)");
         app.add_flag("--organic", *organic,
                      "only the organic rows (limbed blob and bumpy potato at 5k, 20k, 100k triangles; "
                      "decomposition_organic.csv/.png), Rubble beside the hull of the whole");
         auto mega = std::make_shared<rubble::bench::MegaArgs>();
         auto megaOn = std::make_shared<bool>(false);
         app.add_flag("--mega", *megaOn,
                      "only the million-triangle rows (UV sphere, geodesic sphere, torus, subdivided arch at "
                      "100k, 250k, 1M; "
                      "decomposition_megamesh.csv/.png)");
         app.add_option("--mega-sizes", mega->sizes, "triangle counts of the --mega rows");
         app.add_option("--mega-kinds", mega->kinds, "meshes of the --mega rows")
             ->check(CLI::IsMember(allKinds()));
         app.add_option("--hits", mega->hits, "random hits per --mega mesh")->check(CLI::Range(1, 10000));
         auto writeDir = std::make_shared<std::string>();
         app.add_option("--write-mega", *writeDir,
                        "write the --mega meshes as OBJ into this folder (kind_triangles.obj) and stop");
         return [args, mega, megaOn, writeDir, organic, heldOut] {
             if (!writeDir->empty())
                 return rubble::bench::writeMegaMeshes(*mega, *writeDir);
             if (*organic)
                 return runOrganic(*args, *heldOut);
             if (!*megaOn)
                 return runBench(*args);
             mega->out = args->out;
             return rubble::bench::runMegaDecomposition(*mega);
         };
     }}};

} // namespace
