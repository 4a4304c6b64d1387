// `rubble-bench structure [--quick] [--frames N] [--iterations N] [--json] [--out DIR]`
//
// Stress-solver cost per frame against bond count: a block of stacked bricks (k x h x k, 1 x 0.5 x 1 m each)
// on a ground root, each brick bonded to its face neighbours, solved frame after frame (warm-started) with 1
// and with --iterations (default 25, as Blast) Gauss-Seidel sweeps. Also the bond-graph build time, and what
// one fracture costs the structure: a brick replaced by its Voronoi pieces, updated incrementally (BondGraph
// and the solver's add/remove, as StructureMonitor does) against a from-scratch rebuild (buildBonds and
// reset), both in thread CPU time. Table on stdout (or with --json one row per graph size for --iterations:
// {"bonds": N, "solve_ms": {"p50", "p99"}, "update_ms": {"p50", "p99"}, "rebuild_ms": ...}), CSV in
// DIR/structure.csv, plot in DIR/structure.png (gnuplot).
#include <algorithm>
#include <chrono>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "BenchUtil.hpp"
#include "Subcommand.hpp"
#include "rubble/Fracture.hpp"
#include "rubble/StressSolver.hpp"

namespace {

namespace fs = std::filesystem;
using rubble::bench::fixed;

struct BenchArgs {
    bool quick = false;
    bool json = false;
    int frames = 60;
    int iterations = 25;
    std::string out = rubble::bench::kResultsDir;
};

struct Row {
    std::size_t nodes = 0, bonds = 0;
    int iterations = 0;
    double buildMs = 0, p50 = 0, p99 = 0, max = 0;
    double updateP50 = 0, updateP99 = 0, rebuildMs = 0; // one fracture's structure update, thread CPU
    double pieces = 0;                                  // pieces per fracture (mean)
};

double threadCpuMs() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) * 1e-6;
}

double percentile(std::vector<double> v, double q) {
    if (v.empty())
        return 0;
    std::sort(v.begin(), v.end());
    return v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())))];
}

// Solids of a k x h x k block of bricks on a ground slab (solid 0).
std::vector<std::vector<rubble::ConvexPolytope>> bricks(int k, int h) {
    std::vector<std::vector<rubble::ConvexPolytope>> out;
    out.push_back({rubble::ConvexPolytope::fromAabb({{-1, -1, -1}, {k + 1.0, 0, k + 1.0}})});
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < k; ++x)
            for (int z = 0; z < k; ++z)
                out.push_back({rubble::ConvexPolytope::fromAabb(
                    {{double(x), 0.5 * y, double(z)}, {x + 1.0, 0.5 * (y + 1), z + 1.0}})});
    return out;
}

// The convex pieces of a brick shattered at its top centre: Voronoi cells clipped to the brick.
std::vector<std::vector<rubble::ConvexPolytope>> shatter(const rubble::Aabb& brick, std::uint64_t seed) {
    rubble::FractureParams params;
    params.pattern = rubble::CellPattern::Shatter;
    params.cells = 12;
    params.sizeLaw.base = 1.5;
    params.sizeLaw.scale = 0;
    const rubble::Impact hit{{brick.center().x, brick.hi.y, brick.center().z}, {0, 1, 0}, 1000};
    std::vector<std::vector<rubble::ConvexPolytope>> out;
    for (rubble::ConvexPolytope cell : rubble::generateCells(brick, hit, params, seed)) {
        for (int axis = 0; axis < 3 && !cell.empty(); ++axis) {
            rubble::Vec3 n;
            n[axis] = 1;
            cell = cell.clipped({n, brick.hi[axis]}).clipped({-1.0 * n, -brick.lo[axis]});
        }
        if (!cell.empty() && cell.volume() > 1e-9)
            out.push_back({std::move(cell)});
    }
    return out;
}

// One fracture after another (bricks spread through the block), each replacing a brick by its pieces: the
// incremental update's thread CPU time per fracture, and a full rebuild's after the last one.
void measureUpdates(std::vector<std::vector<rubble::ConvexPolytope>> solids,
                    const std::vector<rubble::StructureNode>& nodes, int fractures, Row& row) {
    rubble::BondGraph graph;
    rubble::StressSolver solver;
    std::vector<std::uint32_t> slot(solids.size());
    auto addSolid = [&](std::size_t i) {
        slot[i] = solver.addNode(rubble::structureNode(solids[i], 1900, i == 0));
        for (rubble::Bond& b : graph.add(slot[i], solids[i]))
            (void)solver.addBond(std::move(b), {});
    };
    for (std::size_t i = 0; i < solids.size(); ++i) {
        slot[i] = solver.addNode(nodes[i]);
        for (rubble::Bond& b : graph.add(slot[i], solids[i]))
            (void)solver.addBond(std::move(b), {});
    }
    solver.solve();
    std::vector<double> ms;
    std::size_t pieces = 0;
    for (int f = 0; f < fractures; ++f) {
        const std::size_t victim = 1 + (static_cast<std::size_t>(f) * 7919) % (solids.size() - 1);
        rubble::Aabb box;
        for (const rubble::ConvexPolytope& p : solids[victim])
            box.extend(p.bounds());
        const auto parts = shatter(box, static_cast<std::uint64_t>(f) + 1);
        pieces += parts.size();
        const double t0 = threadCpuMs();
        (void)graph.remove(slot[victim]);
        solver.removeNode(slot[victim]);
        solids[victim] = parts.front();
        addSolid(victim);
        for (std::size_t p = 1; p < parts.size(); ++p) {
            solids.push_back(parts[p]);
            slot.push_back(0);
            addSolid(solids.size() - 1);
        }
        ms.push_back(threadCpuMs() - t0);
        solver.solve();
    }
    std::vector<rubble::StructureNode> all; // the old monitor kept its nodes: only bonds were rebuilt
    for (std::size_t i = 0; i < solids.size(); ++i)
        all.push_back(rubble::structureNode(solids[i], 1900, i == 0));
    const double t1 = threadCpuMs();
    std::vector<rubble::Bond> bonds = rubble::buildBonds(solids, {});
    const std::size_t count = bonds.size();
    rubble::StressSolver fresh;
    fresh.reset(std::move(all), std::move(bonds), std::vector<rubble::StrengthLimits>(count));
    row.rebuildMs = threadCpuMs() - t1;
    row.updateP50 = percentile(ms, 0.5);
    row.updateP99 = percentile(ms, 0.99);
    row.pieces = static_cast<double>(pieces) / fractures;
}

std::vector<Row> measure(int k, int h, const std::vector<int>& iterations, int frames, int fractures) {
    const auto solids = bricks(k, h);
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<rubble::Bond> bonds = rubble::buildBonds(solids, {});
    const double buildMs = rubble::bench::msSince(t0);
    std::vector<rubble::StructureNode> nodes;
    for (std::size_t i = 0; i < solids.size(); ++i)
        nodes.push_back(rubble::structureNode(solids[i], 1900, i == 0));
    std::vector<Row> rows;
    for (int it : iterations) {
        rubble::StressSettings settings;
        settings.iterations = it;
        settings.tolerance = 0; // every sweep: the cost of a structure that keeps changing
        rubble::StressSolver solver(settings);
        solver.reset(nodes, bonds,
                     std::vector<rubble::StrengthLimits>(bonds.size())); // unlimited: nothing breaks
        for (int i = 0; i < 3; ++i)
            solver.solve();
        std::vector<double> ms;
        for (int f = 0; f < frames; ++f) {
            const auto s0 = std::chrono::steady_clock::now();
            solver.solve();
            ms.push_back(rubble::bench::msSince(s0));
        }
        Row r;
        r.nodes = nodes.size();
        r.bonds = bonds.size();
        r.iterations = it;
        r.buildMs = buildMs;
        r.p50 = percentile(ms, 0.5);
        r.p99 = percentile(ms, 0.99);
        r.max = *std::max_element(ms.begin(), ms.end());
        rows.push_back(r);
    }
    Row update;
    measureUpdates(solids, nodes, fractures, update);
    for (Row& r : rows) {
        r.updateP50 = update.updateP50;
        r.updateP99 = update.updateP99;
        r.rebuildMs = update.rebuildMs;
        r.pieces = update.pieces;
    }
    return rows;
}

int runBench(const BenchArgs& args) {
    const int frames = args.quick ? 5 : std::max(1, args.frames);
    // (k, h): bonds ~ 3 k^2 h.
    const std::vector<std::pair<int, int>> sizes =
        args.quick ? std::vector<std::pair<int, int>>{{4, 4}, {8, 8}}
                   : std::vector<std::pair<int, int>>{{4, 4}, {8, 8}, {12, 12}, {16, 26}, {20, 34}};
    std::vector<int> iterations{1};
    if (args.iterations != 1)
        iterations.push_back(args.iterations);
    const rubble::bench::CpuMeter cpu;
    std::vector<Row> rows;
    for (const auto& [k, h] : sizes)
        for (const Row& r : measure(k, h, iterations, frames, args.quick ? 3 : 20))
            rows.push_back(r);
    const double otherCpu = cpu.read().other;

    if (args.json) {
        for (const Row& r : rows)
            if (r.iterations == args.iterations) {
                nlohmann::json j;
                j["bonds"] = r.bonds;
                j["solve_ms"] = {{"p50", r.p50}, {"p99", r.p99}};
                j["update_ms"] = {{"p50", r.updateP50}, {"p99", r.updateP99}};
                j["rebuild_ms"] = r.rebuildMs;
                std::cout << j.dump() << "\n";
            }
    }
    rubble::bench::Table table{{"bonds", "nodes", "iterations", "build ms", "solve p50 ms", "p99", "max",
                                "ns / bond / iteration", "update p50 ms", "update p99", "rebuild ms"},
                               {}};
    rubble::bench::Table csv{{"bonds", "nodes", "iterations", "frames", "build_ms", "solve_p50_ms",
                              "solve_p99_ms", "solve_max_ms", "ns_per_bond_iteration", "update_p50_ms",
                              "update_p99_ms", "rebuild_ms", "pieces_per_fracture", "other_cpu_cores"},
                             {}};
    std::ostringstream data;
    for (const Row& r : rows) {
        const double perBond = r.p50 * 1e6 / (static_cast<double>(r.bonds) * r.iterations);
        table.rows.push_back({std::to_string(r.bonds), std::to_string(r.nodes), std::to_string(r.iterations),
                              fixed(r.buildMs), fixed(r.p50), fixed(r.p99), fixed(r.max), fixed(perBond, 1),
                              fixed(r.updateP50), fixed(r.updateP99), fixed(r.rebuildMs)});
        csv.rows.push_back({std::to_string(r.bonds), std::to_string(r.nodes), std::to_string(r.iterations),
                            std::to_string(frames), fixed(r.buildMs), fixed(r.p50, 4), fixed(r.p99, 4),
                            fixed(r.max, 4), fixed(perBond, 2), fixed(r.updateP50, 4), fixed(r.updateP99, 4),
                            fixed(r.rebuildMs, 2), fixed(r.pieces, 1), fixed(otherCpu, 2)});
    }
    for (int it : iterations) {
        for (const Row& r : rows)
            if (r.iterations == it)
                data << r.bonds << " " << r.p50 << " " << r.p99 << "\n";
        data << "\n\n";
    }
    if (!args.json)
        rubble::bench::printTable(table);
    else
        std::cerr << "(table omitted with --json)\n";
    if (!rubble::bench::writeCsv(fs::path(args.out) / "structure.csv", csv))
        return 1;
    std::ostringstream plot;
    plot << "set logscale xy\nset xlabel 'bonds'\nset ylabel 'solve time per frame (ms)'\nset grid\n"
            "set key top left\nset title 'Stress solver: one frame (one core)'\n"
            "plot $DATA index 0 u 1:2 w lp t 'p50, 1 iteration', '' index 0 u 1:3 w lp t 'p99, 1 iteration'";
    if (iterations.size() > 1)
        plot << ", '' index 1 u 1:2 w lp t 'p50, " << args.iterations
             << " iterations', '' index 1 u 1:3 w lp t 'p99, " << args.iterations << " iterations'";
    plot << ", 1 w l dt 2 t '1 ms budget'";
    rubble::bench::plotPng(args.out, "structure", data.str(), plot.str());
    return 0;
}

const rubble::tools::Registrar registrar{
    {"structure", "Stress solver: solve time per frame against bond count", [](CLI::App& app) {
         auto args = std::make_shared<BenchArgs>();
         app.add_flag("--quick", args->quick, "two small graphs, 5 frames (CI smoke run)");
         app.add_flag("--json", args->json, "one JSON row per graph size on stdout");
         app.add_option("--frames", args->frames, "timed frames per case")->check(CLI::Range(1, 100000));
         app.add_option("--iterations", args->iterations, "Gauss-Seidel sweeps per frame")
             ->check(CLI::Range(1, 1000));
         app.add_option("--out", args->out, "folder for structure.csv and structure.png");
         return [args] { return runBench(*args); };
     }}};

} // namespace
