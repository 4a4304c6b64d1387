// `rubble-bench booleans [--quick] [--runs N] [--seed S] [--out DIR]`
//
// The thesis's Table 3.2 subtraction experiment, boolean stage only, for the three backends side by side:
// subdivided cubes [-1,1]^3 of 12 .. 10,092 triangles (like the seed's cube_N.obj) and the scene objects in
// assets/models. Per case one seeded thesis cell (the Voronoi cell of the impact among random sites, pattern
// SingleCell, domain edge = half the mesh's largest extent) at a seeded impact (an area-weighted random point
// on the surface); the timed operation is BooleanBackend::split with that cell, i.e. damaged = mesh − cell
// and debris = mesh ∩ cell. Repetitions are interleaved (Nef, Corefine, Fast, Nef, ...) so that machine noise
// hits every backend alike. Every split is checked once: closed pieces whose volumes add up to the input's.
// Reference columns for the cubes: the thesis's Table 3.2 subtraction times, CGAL Nef measured on this kind
// of machine by a throwaway prototype (../shared/MEASUREMENTS.md) and the thesis's program measured here.
// Table on stdout, CSV in DIR/booleans.csv, plot in DIR/booleans.png (gnuplot, log axes).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <thread>

#include "BenchUtil.hpp"
#include "Subcommand.hpp"
#include "fracture/BooleanBackend.hpp"
#include "rubble/core/Random.hpp"
#include "rubble/fracture/Fracture.hpp"
#include "rubble/geometry/MassProperties.hpp"
#include "rubble/geometry/MeshCheck.hpp"
#include "rubble/io/MeshIO.hpp"

namespace {

namespace fs = std::filesystem;
using rubble::bench::fixed;
using rubble::bench::Stats;

struct BenchArgs {
    bool quick = false;
    int runs = 10;
    std::uint64_t seed = 1;
    std::string out = rubble::bench::resultsDir();
};

constexpr rubble::BooleanKind kKinds[] = {rubble::BooleanKind::Nef, rubble::BooleanKind::Corefine,
                                          rubble::BooleanKind::Fast};
constexpr std::size_t kBackends = std::size(kKinds);

struct Reference {
    double thesisMs = -1;    // thesis Table 3.2, subtraction (average, seconds -> ms)
    double prototypeMs = -1; // CGAL Nef, difference + intersection, prototype on this kind of machine
    double seedMs = -1;      // the thesis's program measured here (median subtraction)
};

const std::map<std::size_t, Reference> kReference = {{12, {37, 3.96, 3.2}},
                                                     {108, {69, 5.32, 15.8}},
                                                     {588, {134, 12.3, 28.3}},
                                                     {2700, {386, 52.4, 67.6}},
                                                     {10092, {1211, 280, 145}}};

struct Case {
    std::string name;
    bool cube = false;
    rubble::Mesh mesh;
};

struct Row {
    std::string name;
    bool cube = false;
    std::size_t triangles = 0;
    std::size_t cellPlanes = 0;
    Stats ms[kBackends];
    std::string check[kBackends]; // "ok" or what is wrong
    Reference ref;
};

// An area-weighted random point on the surface.
rubble::Vec3 surfacePoint(const rubble::Mesh& mesh, rubble::Rng& rng) {
    double total = 0;
    for (std::size_t t = 0; t < mesh.triangleCount(); ++t)
        total += length(mesh.triangleNormal(t));
    double pick = rng.uniform(0.0, total);
    std::size_t t = 0;
    for (; t + 1 < mesh.triangleCount(); ++t) {
        pick -= length(mesh.triangleNormal(t));
        if (pick <= 0)
            break;
    }
    double u = rng.uniform(), v = rng.uniform();
    if (u + v > 1) {
        u = 1 - u;
        v = 1 - v;
    }
    const auto c = mesh.corners(t);
    return c[0] + u * (c[1] - c[0]) + v * (c[2] - c[0]);
}

std::string checkSplit(const rubble::Result<rubble::SplitResult>& split, double volume) {
    if (!split)
        return "failed: " + split.error().message;
    rubble::CheckOptions options;
    options.selfIntersections = false;
    double sum = 0;
    std::size_t nonEmpty = 0;
    auto add = [&](const rubble::Mesh& m) {
        if (m.empty())
            return true;
        ++nonEmpty;
        sum += rubble::signedVolume(m);
        const rubble::MeshReport r = rubble::checkMesh(m, options);
        return r.closed && r.oriented;
    };
    bool closed = add(split->remainder);
    for (const rubble::Mesh& m : split->inside)
        closed &= add(m);
    if (!closed)
        return "open pieces";
    if (std::abs(sum - volume) > 1e-6 * volume)
        return "volume off by " + fixed(std::abs(sum - volume) / volume, 9);
    return split->inside.empty() || split->inside[0].empty() ? "cell misses" : "ok";
}

Row measure(const Case& c, int runs, std::uint64_t seed) {
    Row row;
    row.name = c.name;
    row.cube = c.cube;
    row.triangles = c.mesh.triangleCount();
    if (auto it = kReference.find(row.triangles); c.cube && it != kReference.end())
        row.ref = it->second;
    rubble::Rng rng(seed);
    rubble::Impact impact;
    impact.point = surfacePoint(c.mesh, rng);
    rubble::FractureParams params; // SingleCell: the thesis's cell
    const rubble::Vec3 size = c.mesh.bounds().size();
    params.sizeLaw.base = 0.5 * std::max({size.x, size.y, size.z});
    params.sizeLaw.scale = 0;
    params.sizeLaw.maxSize = params.sizeLaw.base;
    const std::vector<rubble::ConvexPolytope> cells =
        rubble::generateCells(c.mesh.bounds(), impact, params, seed);
    row.cellPlanes = cells.empty() ? 0 : cells[0].faces().size();
    const double volume = rubble::signedVolume(c.mesh);

    std::unique_ptr<rubble::BooleanBackend> backends[kBackends];
    for (std::size_t b = 0; b < kBackends; ++b) {
        backends[b] = rubble::makeBooleanBackend(kKinds[b]);
        row.check[b] = checkSplit(backends[b]->split(c.mesh, cells), volume); // also warms caches up
    }
    std::vector<double> samples[kBackends];
    for (int r = 0; r < runs; ++r)
        for (std::size_t b = 0; b < kBackends; ++b) {
            const auto t0 = std::chrono::steady_clock::now();
            const auto split = backends[b]->split(c.mesh, cells);
            samples[b].push_back(rubble::bench::msSince(t0));
        }
    for (std::size_t b = 0; b < kBackends; ++b)
        row.ms[b] = rubble::bench::stats(samples[b]);
    return row;
}

std::vector<Case> cases(bool quick) {
    std::vector<Case> all;
    for (int n : quick ? std::vector<int>{1, 3, 7} : std::vector<int>{1, 3, 7, 15, 29}) {
        rubble::Mesh cube = rubble::makeSubdividedBox({-1, -1, -1}, {1, 1, 1}, n);
        all.push_back({"cube_" + std::to_string(cube.triangleCount()), true, std::move(cube)});
    }
    if (quick)
        return all;
    for (const fs::path& f : rubble::bench::repoModels()) {
        auto mesh = rubble::readMesh(f);
        if (!mesh) {
            std::cerr << "booleans: skipping " << f.string() << ": " << mesh.error().message << "\n";
            continue;
        }
        all.push_back({f.stem().string(), false, std::move(mesh.value())});
    }
    return all;
}

int runBench(const BenchArgs& args) {
    const int runs = args.quick ? 1 : args.runs;
    std::vector<Row> rows;
    std::uint64_t seed = args.seed;
    const rubble::bench::CpuMeter cpu; // most cases are short: one reading for all of them
    for (const Case& c : cases(args.quick))
        rows.push_back(measure(c, runs, seed++));
    const double otherCpu = cpu.read().other; // cores other processes used meanwhile (the machine is shared)

    const char* names[kBackends] = {"nef", "corefine", "fast"};
    rubble::bench::Table table{{"case", "tris"}, {}};
    rubble::bench::Table csv{{"case", "triangles", "cell_planes", "runs"}, {}};
    for (std::size_t b = 0; b < kBackends; ++b) {
        const std::string n = names[b];
        for (const char* s : {" med", " min", " max"})
            table.header.push_back(n + s);
        for (const char* s : {"_median_ms", "_min_ms", "_max_ms"})
            csv.header.push_back(n + s);
        if (b > 0) {
            table.header.push_back("nef/" + n);
            csv.header.push_back("nef_over_" + n);
        }
    }
    for (const char* h : {"thesis T3.2", "nef proto", "seed prog", "checks"})
        table.header.push_back(h);
    for (const char* h : {"thesis_table_3_2_ms", "nef_prototype_here_ms", "seed_program_here_ms", "checks",
                          "other_cpu_cores"})
        csv.header.push_back(h);

    auto str = [](auto v) {
        std::ostringstream o;
        o << v;
        return o.str();
    };
    std::ostringstream cubeData, modelData;
    for (const Row& r : rows) {
        std::vector<std::string> t{r.name, str(r.triangles)};
        std::vector<std::string> c{r.name, str(r.triangles), str(r.cellPlanes), str(runs)};
        std::string checks;
        for (std::size_t b = 0; b < kBackends; ++b) {
            for (double v : {r.ms[b].median, r.ms[b].min, r.ms[b].max}) {
                t.push_back(fixed(v, 3));
                c.push_back(str(v));
            }
            if (b > 0) {
                const double ratio = r.ms[b].median > 0 ? r.ms[0].median / r.ms[b].median : -1;
                t.push_back(fixed(ratio, 1));
                c.push_back(ratio > 0 ? str(ratio) : "");
            }
            if (r.check[b] != "ok")
                checks += (checks.empty() ? "" : "; ") + std::string(names[b]) + ": " + r.check[b];
        }
        if (checks.empty())
            checks = "ok";
        for (double v : {r.ref.thesisMs, r.ref.prototypeMs, r.ref.seedMs}) {
            t.push_back(fixed(v, 2));
            c.push_back(v >= 0 ? str(v) : "");
        }
        t.push_back(checks);
        c.push_back(checks);
        c.push_back(fixed(otherCpu, 2));
        table.rows.push_back(t);
        csv.rows.push_back(c);
        std::ostringstream& d = r.cube ? cubeData : modelData;
        d << r.triangles << " " << r.ms[0].median << " " << r.ms[1].median << " " << r.ms[2].median;
        if (r.cube)
            d << " " << (r.ref.thesisMs > 0 ? str(r.ref.thesisMs) : "NaN") << " "
              << (r.ref.seedMs > 0 ? str(r.ref.seedMs) : "NaN") << " "
              << (r.ref.prototypeMs > 0 ? str(r.ref.prototypeMs) : "NaN");
        d << "\n";
    }
    rubble::bench::printTable(table);
    std::cout << "other processes used " << fixed(otherCpu, 2) << " of "
              << std::thread::hardware_concurrency()
              << " cores meanwhile: absolute times grow with it, ratios between backends much less\n";
    std::cout << "ms per split (difference + intersection with one seeded thesis cell), " << runs
              << (runs == 1 ? " run" : " runs")
              << " per backend, interleaved; reference columns in ms: thesis Table 3.2 (subtraction), "
                 "Nef prototype and the thesis's program measured on this kind of machine\n";
    if (!rubble::bench::writeCsv(fs::path(args.out) / "booleans.csv", csv))
        return 1;
    rubble::bench::plotPng(
        args.out, "booleans", cubeData.str() + "\n\n" + modelData.str(),
        "set logscale xy\nset xlabel 'triangles'\nset ylabel 'boolean stage (ms)'\nset grid\n"
        "set key top left\nset title 'Mesh booleans (one thesis cell): Rubble backends vs "
        "the thesis'\n"
        "nef = '#1f77b4'; core = '#ff7f0e'; fast = '#2ca02c'\n"
        "plot $DATA index 0 u 1:5 w lp lc rgb '#7f7f7f' t 'thesis Table 3.2 (subtraction)', "
        "'' index 0 u 1:6 w lp lc rgb '#9467bd' t 'thesis program measured here', "
        "'' index 0 u 1:7 w lp dt 2 lc rgb nef t 'Nef prototype measured here', "
        "'' index 0 u 1:2 w lp pt 5 lc rgb nef t 'Nef (cubes)', "
        "'' index 0 u 1:3 w lp pt 7 lc rgb core t 'Corefine (cubes)', "
        "'' index 0 u 1:4 w lp pt 9 lc rgb fast t 'Fast (cubes)', "
        "'' index 1 u 1:2 w p pt 4 lc rgb nef t 'Nef (models)', "
        "'' index 1 u 1:3 w p pt 6 lc rgb core t 'Corefine (models)', "
        "'' index 1 u 1:4 w p pt 8 lc rgb fast t 'Fast (models)'");
    bool allOk = true;
    for (const Row& r : rows)
        for (const std::string& c : r.check)
            allOk &= c == "ok";
    return allOk ? 0 : 1;
}

const rubble::tools::Registrar registrar{
    {"booleans", "Boolean stage (mesh − cell, mesh ∩ cell) per backend on the thesis's cubes and our models",
     [](CLI::App& app) {
         auto args = std::make_shared<BenchArgs>();
         app.add_flag("--quick", args->quick,
                      "one repetition, cubes up to 588 triangles only (CI smoke run)");
         app.add_option("--runs", args->runs, "repetitions per case and backend")
             ->check(CLI::Range(1, 10000))
             ->capture_default_str();
         app.add_option("--seed", args->seed, "seed of the first case's impact and cell (then +1 per case)")
             ->check(rubble::tools::unsigned64())
             ->capture_default_str();
         app.add_option("--out", args->out, "folder for booleans.csv and booleans.png");
         return [args] { return runBench(*args); };
     }}};

} // namespace
