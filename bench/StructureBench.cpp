// `rubble-bench structure [--quick] [--frames N] [--iterations N] [--solvers A,B] [--sizes K,..]
// [--islands N] [--json] [--convergence] [--out DIR]`
//
// Stress-solver cost per frame under fire against bond count, one row per solver: a block of stacked bricks
// (k x h x k, 1 x 0.5 x 1 m each) on a ground root, each brick welded to its face neighbours; every frame one
// brick is replaced by its Voronoi pieces and debris loads land on random bricks, then one solve (thread CPU
// time) with its relative residual; with --islands N, N such blocks side by side, bonded only to the ground
// (separate islands of the direct solve); with --breaks, one bond breaks a frame instead. Solvers: the
// converged Gauss-Seidel, conjugate gradient and direct (sparse LDLT with an active set), and the old sweep
// budget at 12 sweeps (and at --iterations, default 25, as Blast). Also the first solve's cost, and what one
// fracture costs the structure: a brick replaced by its pieces, updated incrementally (BondGraph and the
// solver's add/remove, as StructureMonitor does) against a from-scratch rebuild (buildBonds and reset). Table
// on stdout (or with --json one row per graph size and solver: {"bonds", "solver", "solve_ms": {"p50",
// "p99"}, "residual": {"p50", "max"}, ...}), CSV in DIR/structure.csv, plots in DIR/structure.png and
// DIR/structure_convergence.png (residual against time of a first solve from zero forces, per solver).
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
#include "rubble/fracture/Fracture.hpp"
#include "rubble/structure/StressSolver.hpp"

namespace {

namespace fs = std::filesystem;
using rubble::bench::fixed;
using rubble::bench::threadCpuMs;

struct BenchArgs {
    bool quick = false;
    bool json = false;
    bool convergenceOnly = false;
    int frames = 60;
    int iterations = 25;
    int islands = 1;                  // blocks side by side
    bool breaks = false;              // a bond breaks each frame instead of a brick fracturing
    std::vector<std::string> solvers; // only these rows (empty: all)
    std::vector<int> sizes;           // block sizes k (k x h x k, h as in the default list; empty: all)
    std::string out = rubble::bench::resultsDir();
};

struct Row {
    std::string solver;
    std::size_t nodes = 0, bonds = 0, bondsAtEnd = 0;
    int iterations = 0;
    double residualP50 = 0, residualMax = 0, sweepsP50 = 0; // under fire
    double coldMs = 0, coldResidual = 0;                    // the first solve, from zero
    int coldSweeps = 0;
    double buildMs = 0, p50 = 0, p99 = 0, max = 0;
    double updateP50 = 0, updateP99 = 0, rebuildMs = 0; // one fracture's structure update, thread CPU
    double pieces = 0;                                  // pieces per fracture (mean)
    int islands = 1;
    double factorizations = 0; // direct: numeric factorisations a frame (mean)
};

double percentile(std::vector<double> v, double q) {
    if (v.empty())
        return 0;
    std::sort(v.begin(), v.end());
    return v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())))];
}

// Solids of `islands` k x h x k blocks of bricks, 1 m apart along x, on a ground slab (solid 0).
std::vector<std::vector<rubble::ConvexPolytope>> bricks(int k, int h, int islands = 1) {
    std::vector<std::vector<rubble::ConvexPolytope>> out;
    out.push_back({rubble::ConvexPolytope::fromAabb({{-1, -1, -1}, {(k + 1.0) * islands, 0, k + 1.0}})});
    for (int i = 0; i < islands; ++i)
        for (int y = 0; y < h; ++y)
            for (int x = i * (k + 1); x < i * (k + 1) + k; ++x)
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

// A solver configuration: a row of the table.
struct Solver {
    std::string name;
    rubble::StressMethod method;
    int sweeps = 0; // SweepBudget: sweeps a frame
};

std::vector<Solver> solvers(int iterations) {
    std::vector<Solver> out{{"gauss-seidel", rubble::StressMethod::GaussSeidel, 0},
                            {"conjugate-gradient", rubble::StressMethod::ConjugateGradient, 0},
                            {"direct", rubble::StressMethod::Direct, 0},
                            {"sweeps-12", rubble::StressMethod::SweepBudget, 12}};
    if (iterations != 12)
        out.push_back(
            {"sweeps-" + std::to_string(iterations), rubble::StressMethod::SweepBudget, iterations});
    return out;
}

rubble::StressSettings settingsOf(const Solver& s) {
    rubble::StressSettings settings;
    settings.method = s.method;
    settings.iterations = std::max(1, s.sweeps);
    settings.tolerance = 0.01; // the sweep budget's early stop (its own criterion, about 1e-3 g)
    settings.deadLoadGuess = true;
    return settings;
}

// A structure under fire: the brick block with its bond graph, changed one fracture at a time.
struct Structure {
    std::vector<std::vector<rubble::ConvexPolytope>> solids;
    rubble::BondGraph graph;
    rubble::StressSolver solver;
    std::vector<std::uint32_t> slot;

    void addSolid(std::size_t i, const rubble::StructureNode& node) {
        slot[i] = solver.addNode(node);
        for (rubble::Bond& b : graph.add(slot[i], solids[i]))
            (void)solver.addBond(std::move(b), {});
    }
    Structure(std::vector<std::vector<rubble::ConvexPolytope>> s,
              const std::vector<rubble::StructureNode>& nodes)
        : solids(std::move(s)), slot(solids.size()) {
        for (std::size_t i = 0; i < solids.size(); ++i)
            addSolid(i, nodes[i]);
    }
    // Replaces the victim brick by pieces (the first takes its place).
    void fracture(std::size_t victim, const std::vector<std::vector<rubble::ConvexPolytope>>& parts) {
        (void)graph.remove(slot[victim]);
        solver.removeNode(slot[victim]);
        solids[victim] = parts.front();
        addSolid(victim, rubble::structureNode(solids[victim], 1900, false));
        for (std::size_t p = 1; p < parts.size(); ++p) {
            solids.push_back(parts[p]);
            slot.push_back(0);
            addSolid(solids.size() - 1, rubble::structureNode(parts[p], 1900, false));
        }
    }
};

// One fracture a frame: which brick, and its pieces (computed once, shared by every solver).
struct Shot {
    std::size_t victim = 0;
    std::vector<std::vector<rubble::ConvexPolytope>> parts;
};

std::vector<Shot> shots(const std::vector<std::vector<rubble::ConvexPolytope>>& solids, int count) {
    std::vector<Shot> out;
    for (int f = 0; f < count; ++f) {
        Shot s;
        s.victim = 1 + (static_cast<std::size_t>(f) * 7919) % (solids.size() - 1);
        rubble::Aabb box;
        for (const rubble::ConvexPolytope& p : solids[s.victim])
            box.extend(p.bounds());
        s.parts = shatter(box, static_cast<std::uint64_t>(f) + 1);
        out.push_back(std::move(s));
    }
    return out;
}

// One fracture after another (bricks spread through the block), each replacing a brick by its pieces: the
// incremental update's thread CPU time per fracture, and a full rebuild's after the last one.
void measureUpdates(const std::vector<std::vector<rubble::ConvexPolytope>>& solids,
                    const std::vector<rubble::StructureNode>& nodes, const std::vector<Shot>& fire,
                    Row& row) {
    Structure s(solids, nodes);
    s.solver.solve();
    std::vector<double> ms;
    std::size_t pieces = 0;
    for (const Shot& shot : fire) {
        pieces += shot.parts.size();
        const double t0 = threadCpuMs();
        s.fracture(shot.victim, shot.parts);
        ms.push_back(threadCpuMs() - t0);
        s.solver.solve();
    }
    std::vector<rubble::StructureNode> all; // the old monitor kept its nodes: only bonds were rebuilt
    for (std::size_t i = 0; i < s.solids.size(); ++i)
        all.push_back(rubble::structureNode(s.solids[i], 1900, i == 0));
    const double t1 = threadCpuMs();
    std::vector<rubble::Bond> bonds = rubble::buildBonds(s.solids, {});
    const std::size_t count = bonds.size();
    rubble::StressSolver fresh;
    fresh.reset(std::move(all), std::move(bonds), std::vector<rubble::StrengthLimits>(count));
    row.rebuildMs = threadCpuMs() - t1;
    row.updateP50 = percentile(ms, 0.5);
    row.updateP99 = percentile(ms, 0.99);
    row.pieces = static_cast<double>(pieces) / static_cast<double>(fire.size());
}

// Debris landing on the block this frame: a few contact forces on bricks, fixed by the frame number.
void debris(Structure& s, int frame) {
    std::uint64_t x = 0x9e3779b97f4a7c15ull * static_cast<std::uint64_t>(frame + 1);
    for (int i = 0; i < 8; ++i) {
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        const std::size_t solid = 1 + (x * 0x2545f4914f6cdd1dull >> 33) % (s.solids.size() - 1);
        rubble::Aabb box;
        for (const rubble::ConvexPolytope& p : s.solids[solid])
            box.extend(p.bounds());
        const double push = 500.0 + static_cast<double>(x % 2000); // N: a 50-250 kg piece settling
        s.solver.addLoad(s.slot[solid], {0.1 * push, -push, 0}, {box.lo.x, box.hi.y, box.center().z});
    }
}

std::vector<Row> measure(int k, int h, int islands, bool breaks, const std::vector<Solver>& list, int frames,
                         int fractures) {
    const auto solids = bricks(k, h, islands);
    const auto t0 = std::chrono::steady_clock::now();
    const std::size_t bondCount = rubble::buildBonds(solids, {}).size();
    const double buildMs = rubble::bench::msSince(t0);
    std::vector<rubble::StructureNode> nodes;
    for (std::size_t i = 0; i < solids.size(); ++i)
        nodes.push_back(rubble::structureNode(solids[i], 1900, i == 0));
    const std::vector<Shot> fire = shots(solids, std::max(frames, fractures));
    std::vector<Row> rows;
    for (const Solver& solver : list) {
        Structure s(solids, nodes);
        Row r;
        r.solver = solver.name;
        r.nodes = nodes.size();
        r.bonds = bondCount;
        r.iterations = solver.sweeps;
        r.islands = islands;
        r.buildMs = buildMs;
        // The first solve, from zero forces.
        s.solver.settings() = settingsOf(solver);
        const double c0 = threadCpuMs();
        s.solver.solve();
        r.coldMs = threadCpuMs() - c0;
        r.coldResidual = s.solver.residual();
        r.coldSweeps = s.solver.sweeps();
        // Every solver starts under fire from the same converged state.
        s.solver.settings().method = rubble::StressMethod::ConjugateGradient;
        s.solver.settings().residual = 1e-9;
        s.solver.settings().maxSweeps = 5000;
        s.solver.solve();
        s.solver.settings() = settingsOf(solver);
        std::vector<double> ms, residual, sweeps;
        for (int f = 0; f < frames; ++f) {
            if (breaks) { // an intact bond, spread through the block
                std::size_t bond = (static_cast<std::size_t>(f) * 7919) % s.solver.bondCount();
                while (s.solver.broken(bond))
                    bond = (bond + 1) % s.solver.bondCount();
                s.solver.breakBond(bond);
            } else {
                s.fracture(fire[static_cast<std::size_t>(f)].victim, fire[static_cast<std::size_t>(f)].parts);
            }
            debris(s, f);
            const double s0 = threadCpuMs();
            s.solver.solve();
            ms.push_back(threadCpuMs() - s0);
            residual.push_back(s.solver.residual());
            sweeps.push_back(s.solver.sweeps());
            r.factorizations += s.solver.factorizations() / static_cast<double>(frames);
        }
        r.bondsAtEnd = 0;
        for (std::size_t i = 0; i < s.solver.bondCount(); ++i)
            r.bondsAtEnd += !s.solver.broken(i);
        r.p50 = percentile(ms, 0.5);
        r.p99 = percentile(ms, 0.99);
        r.max = *std::max_element(ms.begin(), ms.end());
        r.residualP50 = percentile(residual, 0.5);
        r.residualMax = *std::max_element(residual.begin(), residual.end());
        r.sweepsP50 = percentile(sweeps, 0.5);
        rows.push_back(r);
    }
    Row update;
    measureUpdates(solids, nodes, std::vector<Shot>(fire.begin(), fire.begin() + fractures), update);
    for (Row& r : rows) {
        r.updateP50 = update.updateP50;
        r.updateP99 = update.updateP99;
        r.rebuildMs = update.rebuildMs;
        r.pieces = update.pieces;
    }
    return rows;
}

// Residual after each sweep of a first solve (from zero forces), per solver: the convergence plot.
std::string convergence(int k, int h, const std::vector<Solver>& list, std::vector<std::string>& titles) {
    const auto solids = bricks(k, h);
    std::vector<rubble::StructureNode> nodes;
    for (std::size_t i = 0; i < solids.size(); ++i)
        nodes.push_back(rubble::structureNode(solids[i], 1900, i == 0));
    std::ostringstream data;
    for (const Solver& solver : list) {
        if (solver.method == rubble::StressMethod::SweepBudget && solver.sweeps != 12)
            continue;
        Structure s(solids, nodes);
        rubble::StressSettings settings = settingsOf(solver);
        settings.iterations = 2000; // the sweep budget's sweeps, unbounded here
        settings.tolerance = 0;
        settings.maxSweeps = 2000;
        settings.deadLoadGuess = false; // from zero forces: the iteration alone
        s.solver.settings() = settings;
        const double t0 = threadCpuMs();
        s.solver.solve();
        const double msTotal = threadCpuMs() - t0; // untraced: the time per sweep
        const int count = s.solver.sweeps();
        s.solver.settings().trace = true;
        Structure traced(solids, nodes);
        traced.solver.settings() = s.solver.settings();
        traced.solver.solve();
        const std::vector<double>& history = traced.solver.history();
        for (std::size_t i = 0; i < history.size(); ++i)
            data << (i + 1) << " " << (msTotal * static_cast<double>(i + 1) / std::max(1, count)) << " "
                 << std::max(history[i], 1e-15) << "\n"; // an exact solve drops to the floor
        data << "\n\n";
        titles.push_back(solver.method == rubble::StressMethod::SweepBudget
                             ? "gauss-seidel, every bond a sweep"
                             : solver.name);
    }
    return data.str();
}

int runBench(const BenchArgs& args) {
    const int frames = args.quick ? 5 : std::max(1, args.frames);
    // (k, h): bonds ~ 3 k^2 h.
    std::vector<std::pair<int, int>> sizes =
        args.quick ? std::vector<std::pair<int, int>>{{4, 4}, {8, 8}}
                   : std::vector<std::pair<int, int>>{{4, 4}, {8, 8}, {12, 12}, {16, 26}, {20, 34}};
    if (!args.sizes.empty())
        std::erase_if(sizes, [&](const auto& s) {
            return std::find(args.sizes.begin(), args.sizes.end(), s.first) == args.sizes.end();
        });
    std::vector<Solver> list = solvers(args.iterations);
    if (!args.solvers.empty())
        std::erase_if(list, [&](const Solver& s) {
            return std::find(args.solvers.begin(), args.solvers.end(), s.name) == args.solvers.end();
        });
    const rubble::bench::CpuMeter cpu;
    std::vector<Row> rows;
    for (const auto& [k, h] : sizes)
        for (const Row& r : args.convergenceOnly
                                ? std::vector<Row>{}
                                : measure(k, h, args.islands, args.breaks, list, frames, args.quick ? 3 : 20))
            rows.push_back(r);
    std::vector<std::string> titles;
    const std::string history = convergence(args.quick ? 8 : 16, args.quick ? 8 : 26, list, titles);
    const double otherCpu = cpu.read().other;

    if (args.json) {
        for (const Row& r : rows) {
            nlohmann::json j;
            j["bonds"] = r.bonds;
            j["solver"] = r.solver;
            j["solve_ms"] = {{"p50", r.p50}, {"p99", r.p99}};
            j["residual"] = {{"p50", r.residualP50}, {"max", r.residualMax}};
            j["sweeps_p50"] = r.sweepsP50;
            j["islands"] = r.islands;
            j["factorizations"] = r.factorizations;
            j["cold"] = {{"ms", r.coldMs}, {"residual", r.coldResidual}, {"sweeps", r.coldSweeps}};
            j["update_ms"] = {{"p50", r.updateP50}, {"p99", r.updateP99}};
            j["rebuild_ms"] = r.rebuildMs;
            std::cout << j.dump() << "\n";
        }
    }
    rubble::bench::Table table{{"bonds", "solver", "solve p50 ms", "p99", "max", "residual p50", "max",
                                "sweeps p50", "cold ms", "cold residual", "update p50 ms", "rebuild ms"},
                               {}};
    rubble::bench::Table csv{{"bonds",         "nodes",          "solver",
                              "frames",        "build_ms",       "solve_p50_ms",
                              "solve_p99_ms",  "solve_max_ms",   "residual_p50",
                              "residual_max",  "sweeps_p50",     "cold_ms",
                              "cold_residual", "cold_sweeps",    "update_p50_ms",
                              "update_p99_ms", "rebuild_ms",     "pieces_per_fracture",
                              "islands",       "factorizations", "other_cpu_cores"},
                             {}};
    auto sci = [](double v) {
        std::ostringstream o;
        o.precision(2);
        o << std::scientific << v;
        return o.str();
    };
    for (const Row& r : rows) {
        table.rows.push_back({std::to_string(r.bonds), r.solver, fixed(r.p50), fixed(r.p99), fixed(r.max),
                              sci(r.residualP50), sci(r.residualMax), fixed(r.sweepsP50, 0), fixed(r.coldMs),
                              sci(r.coldResidual), fixed(r.updateP50), fixed(r.rebuildMs)});
        csv.rows.push_back({std::to_string(r.bonds),
                            std::to_string(r.nodes),
                            r.solver,
                            std::to_string(frames),
                            fixed(r.buildMs),
                            fixed(r.p50, 4),
                            fixed(r.p99, 4),
                            fixed(r.max, 4),
                            sci(r.residualP50),
                            sci(r.residualMax),
                            fixed(r.sweepsP50, 0),
                            fixed(r.coldMs, 3),
                            sci(r.coldResidual),
                            std::to_string(r.coldSweeps),
                            fixed(r.updateP50, 4),
                            fixed(r.updateP99, 4),
                            fixed(r.rebuildMs, 2),
                            fixed(r.pieces, 1),
                            std::to_string(r.islands),
                            fixed(r.factorizations, 2),
                            fixed(otherCpu, 2)});
    }
    if (!args.json)
        rubble::bench::printTable(table);
    else
        std::cerr << "(table omitted with --json)\n";
    if (!args.convergenceOnly && !rubble::bench::writeCsv(fs::path(args.out) / "structure.csv", csv))
        return 1;
    std::ostringstream data, plot;
    plot << "set multiplot layout 1,2\nset logscale xy\nset xlabel 'bonds'\nset ylabel 'solve ms a frame "
            "under fire'\n"
            "set grid\nset key top left\nset title 'Solve per frame (p50, one core)'\nplot ";
    for (std::size_t s = 0; s < list.size(); ++s) {
        for (const Row& r : rows)
            if (r.solver == list[s].name)
                data << r.bonds << " " << r.p50 << " " << r.residualMax << "\n";
        data << "\n\n";
        plot << (s ? ", " : "") << "$DATA index " << s << " u 1:2 w lp t '" << list[s].name << "'";
    }
    plot << ", 1 w l dt 2 t '1 ms'\nset ylabel 'largest relative residual'\nset title 'Residual a frame acts "
            "on'"
            "\nplot ";
    for (std::size_t s = 0; s < list.size(); ++s)
        plot << (s ? ", " : "") << "$DATA index " << s << " u 1:3 w lp t '" << list[s].name << "'";
    plot << ", 1e-3 w l dt 2 t 'target'\nunset multiplot\n";
    if (!args.convergenceOnly)
        rubble::bench::plotPng(args.out, "structure", data.str(), plot.str());
    std::ostringstream conv;
    conv << "set logscale xy\nset yrange [1e-15:2]\nset key bottom left\nset xlabel 'ms (first solve, from "
            "zero forces)'\nset ylabel 'relative "
            "residual'\n"
            "set grid\nset title 'Convergence on a brick block, "
         << (args.quick ? "8 x 8 x 8" : "16 x 26 x 16") << "'\nplot ";
    for (std::size_t s = 0; s < titles.size(); ++s)
        conv << (s ? ", " : "") << "$DATA index " << s << " u 2:3 w l t '" << titles[s] << "'";
    conv << ", 1e-3 w l dt 2 t 'target'\n";
    rubble::bench::plotPng(args.out, "structure_convergence", history, conv.str());
    return 0;
}

const rubble::tools::Registrar registrar{
    {"structure", "Stress solver: solve time per frame against bond count", [](CLI::App& app) {
         auto args = std::make_shared<BenchArgs>();
         app.add_flag("--quick", args->quick, "two small graphs, 5 frames (CI smoke run)");
         app.add_flag("--json", args->json, "one JSON row per graph size and solver on stdout");
         app.add_flag("--convergence", args->convergenceOnly,
                      "only the convergence plot (structure_convergence.png)");
         app.add_option("--frames", args->frames, "timed frames per case")->check(CLI::Range(1, 100000));
         app.add_option("--iterations", args->iterations, "sweeps a frame of a second sweep-budget row")
             ->check(CLI::Range(1, 1000));
         app.add_option("--solvers", args->solvers,
                        "only these rows (gauss-seidel, conjugate-gradient, direct, sweeps-12, sweeps-N)")
             ->delimiter(',');
         app.add_option("--sizes", args->sizes,
                        "only these block sizes k (4, 8, 12, 16, 20; 16: 19,136 bonds)")
             ->delimiter(',')
             ->check(CLI::IsMember({4, 8, 12, 16, 20}));
         app.add_flag("--breaks", args->breaks, "a bond breaks each frame instead of a brick fracturing");
         app.add_option("--islands", args->islands, "blocks side by side, each its own island (default 1)")
             ->check(CLI::Range(1, 64));
         app.add_option("--out", args->out, "folder for structure.csv and structure.png");
         return [args] { return runBench(*args); };
     }}};

} // namespace
