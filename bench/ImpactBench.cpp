// `rubble-bench impact [--quick] [--runs N] [--out DIR]`
//
// The headline measurement: one impact → final pieces (cell, boolean, islands, mass properties, interior UVs)
// and → pieces with their convex collision parts (incremental update of the parent's cached decomposition),
// per subdivided cube (12 .. 10,092 triangles, like the thesis's Table 3.2) and per repository model
// (assets/models, except the cube_N copies of the generated cubes), per boolean backend (Corefine, Fast, and
// Nef up to 2,700 triangles). Runs are interleaved across backends; run i uses seed i for every backend, so
// the cells differ between runs and the fallback rate (how often Fast declines and Corefine redoes the split)
// is counted over them. Reference: the thesis's program built on this machine needs 0.243 s (12 triangles)
// .. 5.196 s (10,092) from impact to final collision shape (../shared/MEASUREMENTS.md). The thesis's single
// cell is the default pattern; the largest cube is also run with a 6-cell shatter pattern.
// Table on stdout, CSV in DIR/impact.csv, plot in DIR/impact.png (gnuplot).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>

#include "Subcommand.hpp"
#include "rubble/ConvexDecomposition.hpp"
#include "rubble/Fracture.hpp"
#include "rubble/MeshIO.hpp"

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct BenchArgs {
    bool quick = false;
    int runs = 15;
    std::string only; // run only the cases whose name contains this
    std::vector<std::string> backends{"corefine", "fast", "nef"}; // which backends run
    std::string out = RUBBLE_SOURCE_DIR "/bench/results";
};

struct Stats {
    double median = 0, min = 0, max = 0;
};

Stats stats(std::vector<double> v) {
    if (v.empty())
        return {};
    std::sort(v.begin(), v.end());
    return {v[v.size() / 2], v.front(), v.back()};
}

double msBetween(Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double, std::milli>(b - a).count();
}

const char* backendName(rubble::BooleanKind k) {
    switch (k) {
    case rubble::BooleanKind::Fast:
        return "fast";
    case rubble::BooleanKind::Nef:
        return "nef";
    case rubble::BooleanKind::Corefine:
        break;
    }
    return "corefine";
}

/// Samples of one backend on one case.
struct Samples {
    std::vector<double> pieces, withParts, cell, boolean, islands, mass, decomposition;
    int fallbacks = 0, failures = 0;
    std::size_t pieceCount = 0, partCount = 0; // of the last run
    std::string error;
};

struct Case {
    std::string name;
    rubble::Mesh mesh;
    rubble::Impact impact;
    double domain = 1; // edge of the cell's domain
    rubble::CellPattern pattern = rubble::CellPattern::SingleCell;
    double thesisS = -1;
    std::vector<rubble::ConvexPolytope> parentParts; // cached at load time, as the runtime does
    double decomposeMs = 0;
    std::map<rubble::BooleanKind, Samples> samples;
};

void runOnce(Case& c, rubble::BooleanKind kind, std::uint64_t seed) {
    rubble::FractureParams params;
    params.backend = kind;
    params.sizeLaw.base = c.domain;
    params.sizeLaw.scale = 0;
    params.pattern = c.pattern;
    params.cells = 6;
    Samples& s = c.samples[kind];
    const auto t0 = Clock::now();
    auto r = rubble::fracture(c.mesh, c.impact, params, seed);
    const auto t1 = Clock::now();
    if (!r) {
        ++s.failures;
        s.error = r.error().message;
        return;
    }
    std::vector<rubble::Mesh> meshes;
    std::vector<std::int32_t> pieceCells;
    meshes.reserve(r->pieces.size());
    for (const rubble::Piece& p : r->pieces) {
        meshes.push_back(p.mesh);
        pieceCells.push_back(p.cell);
    }
    const auto t2 = Clock::now();
    const auto parts = rubble::updateDecomposition(c.parentParts, r->cells, meshes, pieceCells);
    const auto t3 = Clock::now();
    // The copies of the piece meshes are the caller's choice (the runtime makes them too) and not timed.
    s.pieces.push_back(msBetween(t0, t1));
    s.withParts.push_back(msBetween(t0, t1) + msBetween(t2, t3));
    s.cell.push_back(r->timings.cellMs);
    s.boolean.push_back(r->timings.booleanMs);
    s.islands.push_back(r->timings.islandsMs - r->timings.massMs);
    s.mass.push_back(r->timings.massMs);
    s.decomposition.push_back(msBetween(t2, t3));
    s.fallbacks += r->exactFallback ? 1 : 0;
    s.pieceCount = r->pieces.size();
    s.partCount = 0;
    for (const auto& p : parts)
        s.partCount += p.size();
}

/// The centroid of the triangle furthest along +x: a point on the surface of any closed mesh.
rubble::Vec3 surfacePointAtMaxX(const rubble::Mesh& m) {
    std::size_t best = 0;
    double bestX = -1e300;
    for (std::size_t t = 0; t < m.triangleCount(); ++t) {
        const auto c = m.corners(t);
        const double x = c[0].x + c[1].x + c[2].x;
        if (x > bestX) {
            bestX = x;
            best = t;
        }
    }
    const auto c = m.corners(best);
    return (c[0] + c[1] + c[2]) * (1.0 / 3.0);
}

int runBench(const BenchArgs& args) {
    const int runs = args.quick ? 2 : std::max(1, args.runs);
    // The thesis's program measured here: impact → final collision shape (seconds, MEASUREMENTS.md).
    const std::map<std::size_t, double> thesis = {
        {12, 0.243}, {108, 0.280}, {588, 0.347}, {2700, 1.199}, {10092, 5.196}};
    std::vector<Case> cases;
    const std::vector<int> grid = args.quick ? std::vector<int>{1, 3} : std::vector<int>{1, 3, 7, 15, 29};
    for (int n : grid) {
        Case c;
        c.mesh = rubble::makeSubdividedBox({-1, -1, -1}, {1, 1, 1}, n);
        c.name = "cube_" + std::to_string(c.mesh.triangleCount());
        c.impact = {{1, 0.05, 0.1}, {1, 0, 0}, 1};
        c.domain = 1;
        if (auto it = thesis.find(c.mesh.triangleCount()); it != thesis.end())
            c.thesisS = it->second;
        cases.push_back(std::move(c));
    }
    {
        // The largest cube once more, shattered into 6 cells (adjacent cells share faces: see the fallbacks).
        Case c = cases.back();
        c.name += "_shatter6";
        c.pattern = rubble::CellPattern::Shatter;
        c.thesisS = -1;
        cases.push_back(std::move(c));
    }
    if (!args.quick) {
        std::vector<fs::path> models;
        for (const auto& e : fs::directory_iterator(fs::path(RUBBLE_SOURCE_DIR) / "assets" / "models"))
            if (e.path().extension() == ".obj" && e.path().stem().string().rfind("cube_", 0) != 0)
                models.push_back(e.path());
        std::sort(models.begin(), models.end());
        for (const fs::path& p : models) {
            auto m = rubble::readMesh(p);
            if (!m) {
                std::cerr << "impact: skipping " << p.filename().string() << ": " << m.error().message
                          << "\n";
                continue;
            }
            Case c;
            c.name = p.stem().string();
            c.mesh = std::move(m).value();
            const rubble::Aabb b = c.mesh.bounds();
            c.impact = {surfacePointAtMaxX(c.mesh), {1, 0, 0}, 1};
            c.domain = 0.5 * std::max({b.size().x, b.size().y, b.size().z});
            cases.push_back(std::move(c));
        }
    }
    if (!args.only.empty())
        cases.erase(
            std::remove_if(cases.begin(), cases.end(),
                           [&](const Case& c) { return c.name.find(args.only) == std::string::npos; }),
            cases.end());
    for (Case& c : cases) {
        const auto t0 = Clock::now();
        auto d = rubble::decompose(c.mesh);
        c.decomposeMs = msBetween(t0, Clock::now());
        if (d)
            c.parentParts = std::move(d->parts);
    }

    for (int run = 0; run < runs; ++run)
        for (Case& c : cases) {
            for (rubble::BooleanKind k :
                 {rubble::BooleanKind::Corefine, rubble::BooleanKind::Fast, rubble::BooleanKind::Nef}) {
                const bool wanted = std::find(args.backends.begin(), args.backends.end(), backendName(k)) !=
                                    args.backends.end();
                if (wanted && (k != rubble::BooleanKind::Nef || c.mesh.triangleCount() <= 2700))
                    runOnce(c, k, 1000 + static_cast<std::uint64_t>(run));
            }
        }

    std::printf("%-19s %6s %-8s | %-26s | %-26s | %6s %7s %7s %7s %7s | %6s %5s %5s | %8s %9s\n", "model",
                "tris", "backend", "pieces ms (med/min/max)", "+convex parts ms (med/min/max)", "cell",
                "boolean", "islands", "mass/uv", "decomp", "fallbk", "pcs", "parts", "thesis s", "x thesis");
    struct CsvRow {
        const Case* c;
        rubble::BooleanKind kind;
        Stats pieces, withParts;
        double cell, boolean, islands, mass, decomposition;
        const Samples* s;
    };
    std::vector<CsvRow> rows;
    for (const Case& c : cases)
        for (const auto& [kind, s] : c.samples) {
            CsvRow row{&c,
                       kind,
                       stats(s.pieces),
                       stats(s.withParts),
                       stats(s.cell).median,
                       stats(s.boolean).median,
                       stats(s.islands).median,
                       stats(s.mass).median,
                       stats(s.decomposition).median,
                       &s};
            rows.push_back(row);
            const int ok = static_cast<int>(s.pieces.size());
            char ref[64] = "";
            if (c.thesisS > 0 && ok > 0)
                std::snprintf(ref, sizeof ref, "%8.3f %9.0f", c.thesisS,
                              c.thesisS * 1000 / row.withParts.median);
            char fb[16];
            std::snprintf(fb, sizeof fb, "%d/%d", s.fallbacks, ok);
            std::printf(
                "%-19s %6zu %-8s | %8.3f %8.3f %8.3f | %8.3f %8.3f %8.3f | %6.3f %7.3f %7.3f %7.3f %7.3f | "
                "%6s %5zu %5zu | %s\n",
                c.name.c_str(), c.mesh.triangleCount(), backendName(kind), row.pieces.median, row.pieces.min,
                row.pieces.max, row.withParts.median, row.withParts.min, row.withParts.max, row.cell,
                row.boolean, row.islands, row.mass, row.decomposition, fb, s.pieceCount, s.partCount, ref);
            if (s.failures > 0)
                std::printf("  %d of %d runs failed: %s\n", s.failures, runs, s.error.c_str());
        }
    std::printf("runs per case: %d, interleaved; stage columns are medians in ms; fallbk = runs where Fast "
                "declined and Corefine made the split; parent decomposition cached before the impact\n",
                runs);

    std::error_code ec;
    fs::create_directories(args.out, ec);
    const fs::path csv = fs::path(args.out) / "impact.csv";
    std::ofstream out(csv);
    if (!out) {
        std::cerr << "impact: cannot write " << csv.string() << "\n";
        return 1;
    }
    out << "model,triangles,backend,runs,failures,fallbacks,pieces,convex_parts,pieces_median_ms,pieces_min_"
           "ms,"
           "pieces_max_ms,with_parts_median_ms,with_parts_min_ms,with_parts_max_ms,cell_ms,boolean_ms,"
           "islands_ms,mass_uv_ms,decomposition_ms,initial_decomposition_ms,thesis_s,speedup_vs_thesis\n";
    for (const CsvRow& r : rows) {
        out << r.c->name << "," << r.c->mesh.triangleCount() << "," << backendName(r.kind) << "," << runs
            << "," << r.s->failures << "," << r.s->fallbacks << "," << r.s->pieceCount << ","
            << r.s->partCount << "," << r.pieces.median << "," << r.pieces.min << "," << r.pieces.max << ","
            << r.withParts.median << "," << r.withParts.min << "," << r.withParts.max << "," << r.cell << ","
            << r.boolean << "," << r.islands << "," << r.mass << "," << r.decomposition << ","
            << r.c->decomposeMs << ",";
        if (r.c->thesisS > 0 && r.withParts.median > 0)
            out << r.c->thesisS << "," << r.c->thesisS * 1000 / r.withParts.median;
        else
            out << ",";
        out << "\n";
    }
    out.close();
    std::cout << "CSV: " << csv.string() << "\n";

    if (std::system("command -v gnuplot >/dev/null 2>&1") != 0) {
        std::cout << "gnuplot not found: plot skipped\n";
        return 0;
    }
    const fs::path dat = fs::path(args.out) / "impact_cubes.dat";
    {
        // One line per cube: triangles, thesis ms, then pieces+parts medians of corefine, fast, nef ("?" =
        // none).
        std::ofstream d(dat);
        for (const Case& c : cases) {
            if (c.thesisS <= 0)
                continue;
            d << c.mesh.triangleCount() << " " << c.thesisS * 1000;
            for (rubble::BooleanKind k :
                 {rubble::BooleanKind::Corefine, rubble::BooleanKind::Fast, rubble::BooleanKind::Nef}) {
                auto it = c.samples.find(k);
                if (it == c.samples.end() || it->second.withParts.empty())
                    d << " ?";
                else
                    d << " " << stats(it->second.withParts).median;
            }
            d << "\n";
        }
    }
    const fs::path png = fs::path(args.out) / "impact.png";
    const fs::path gp = fs::path(args.out) / "impact.gp";
    {
        std::ofstream g(gp);
        g << "set terminal pngcairo size 900,600\nset output '" << png.string() << "'\n"
          << "set datafile missing '?'\nset logscale xy\nset xrange [8:15000]\nset xlabel 'cube triangles'\n"
          << "set ylabel 'impact -> pieces + convex parts (ms)'\nset grid\nset key top left\n"
          << "set title 'Impact to final collision shapes: Rubble vs the thesis program (same machine)'\n"
          << "plot '" << dat.string() << "' u 1:2 w lp t 'thesis program (Nef + HACD)', '' u 1:3 w lp t "
          << "'Rubble, corefine', '' u 1:4 w lp t 'Rubble, fast', '' u 1:5 w lp t 'Rubble, nef', 16.7 w l dt "
             "2 "
          << "t '60 Hz frame'\n";
    }
    if (std::system(("gnuplot '" + gp.string() + "' 2>/dev/null").c_str()) == 0)
        std::cout << "plot: " << png.string() << "\n";
    else
        std::cout << "gnuplot failed: plot skipped\n";
    fs::remove(gp, ec);
    fs::remove(dat, ec);
    return 0;
}

const rubble::tools::Registrar registrar{
    {"impact", "Impact -> pieces (+ convex parts) per cube size, model and backend, with stage breakdown",
     [](CLI::App& app) {
         auto args = std::make_shared<BenchArgs>();
         app.add_flag("--quick", args->quick, "two repetitions, small cubes only (CI smoke run)");
         app.add_option("--runs", args->runs, "repetitions per case")->check(CLI::Range(1, 10000));
         app.add_option("--only", args->only, "only the cases whose name contains this (e.g. cube_10092)");
         app.add_option("--backends", args->backends,
                        "backends to run (corefine fast nef; nef only up to 2,700 "
                        "triangles)")
             ->check(CLI::IsMember({"corefine", "fast", "nef"}));
         app.add_option("--out", args->out, "folder for impact.csv and impact.png");
         return [args] { return runBench(*args); };
     }}};

} // namespace
