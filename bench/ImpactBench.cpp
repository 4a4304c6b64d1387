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
// cell is the default pattern; the largest cube is also run with a 6-cell shatter pattern. Chained rows
// (`<case>_chain10`) measure the 10th successive impact on the largest remainder of the largest cube and of
// two concave models, whose convex parts went through 9 incremental updates (parent_parts column);
// parts_excess = Σ part volume / Σ piece volume − 1 of the measured impact (the merge's quality).
// Table on stdout, CSV in DIR/impact.csv, plot in DIR/impact.png (gnuplot).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <optional>

#include "BenchUtil.hpp"
#include "MegaMeshes.hpp"
#include "Subcommand.hpp"
#include "geometry/MeshTopology.hpp"
#include "rubble/collision/ConvexDecomposition.hpp"
#include "rubble/collision/PartConcavity.hpp"
#include "rubble/core/Random.hpp"
#include "rubble/fracture/Fracture.hpp"
#include "rubble/io/MeshIO.hpp"

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct BenchArgs {
    bool quick = false;
    int runs = 15;
    std::string only; // run only the cases whose name contains this
    std::vector<std::string> backends{"corefine", "fast", "nef"}; // which backends run
    std::string out = rubble::bench::resultsDir();
    bool rough = false; // only the rough rows beside their flat twins (impact_rough.csv)
    bool parts = false; // with rough: the flat cut's parts vs each rough piece's own (impact_rough_parts.csv)
};

using rubble::bench::msSince;
using rubble::bench::stats;

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

/// How well one choice of convex parts covers the rough pieces of one fracture.
struct PartsQuality {
    std::vector<double> ms;    // time to the parts
    std::size_t count = 0;     // parts of every piece, last run
    double vertexOverA = 0;    // largest distance of a rough-surface vertex outside every part, over A
    std::vector<double> ratio; // Σ part volume / Σ piece volume
    double concavity = 0;      // largest partConcavity of a piece (fraction of its diagonal)
    double concavityOverA = 0; // the same, in units of A
};

/// Samples of one backend on one case.
struct Samples {
    std::vector<double> pieces, withParts, cell, boolean, islands, mass, decomposition;
    std::vector<double> concavity; // recordConcavity of the pieces and their parts (not in withParts)
    std::vector<double> piecesCpu; // impact → pieces in the calling thread's CPU time
    std::vector<double> excess;    // (Σ part volume − Σ piece volume) / Σ piece volume
    int fallbacks = 0, failures = 0;
    std::size_t pieceCount = 0, partCount = 0; // of the last run
    std::size_t mostCut = 0;                   // the most cut triangles of one piece, every run
    std::string error;
    PartsQuality flatCut, ownParts; // with --parts, on rough cases: the runtime's parts and the alternative
};

struct Case {
    std::string name;
    rubble::Mesh mesh;
    rubble::Impact impact;
    double domain = 1; // edge of the cell's domain
    rubble::CellPattern pattern = rubble::CellPattern::SingleCell;
    int cells = 6;                          // of a shatter pattern
    rubble::Roughness roughness;            // flat by default
    std::optional<rubble::MeshFacts> known; // fractured in place from a copy made outside the timed region
    double thesisS = -1;
    std::vector<rubble::ConvexPolytope> parentParts; // cached at load time, as the runtime does
    double decomposeMs = 0;
    std::map<rubble::BooleanKind, Samples> samples;
};

/// to = from with 1/16 spare capacity, as the runtime copies a mesh that a fracture edits in place
/// (DestructionWorld.cpp, editableCopy): an edit that adds triangles does not reallocate the arrays.
template <class T>
void assignWithRoom(std::vector<T>& to, const std::vector<T>& from) {
    to.reserve(from.size() + from.size() / 16);
    to = from;
}

/// Segment distance, for polygonDistance.
double segmentDistance(const rubble::Vec3& p, const rubble::Vec3& a, const rubble::Vec3& b) {
    const rubble::Vec3 ab = b - a;
    const double len2 = dot(ab, ab);
    const double t = len2 > 0 ? std::clamp(dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
    return length(p - (a + ab * t));
}

/// Distance from p to the solid union of parts (0 inside one): exact, face polygon by face polygon.
double outsideParts(const rubble::Vec3& p, const std::vector<rubble::ConvexPolytope>& parts) {
    double best = std::numeric_limits<double>::infinity();
    for (const rubble::ConvexPolytope& part : parts) {
        if (part.contains(p))
            return 0;
        for (const rubble::PolytopeFaceView& f : part.faces()) {
            const std::size_t n = f.corners.size();
            bool inside = n >= 3;
            double edges = std::numeric_limits<double>::infinity();
            for (std::size_t i = 0; i < n; ++i) {
                const rubble::Vec3 &a = f.corners[i], &b = f.corners[(i + 1) % n];
                inside = inside && dot(cross(b - a, p - a), f.plane.normal) >= 0;
                edges = std::min(edges, segmentDistance(p, a, b));
            }
            best = std::min(best, inside ? std::abs(f.plane.signedDistance(p)) : edges);
        }
    }
    return best;
}

/// The quality of parts[i] for the pieces of r, whose roughness amplitude is amplitude.
void measureParts(PartsQuality& q, const rubble::FractureResult& r,
                  const std::vector<std::vector<rubble::ConvexPolytope>>& parts, double amplitude,
                  double ms) {
    q.ms.push_back(ms);
    q.count = 0;
    double partVolume = 0, pieceVolume = 0;
    const std::vector<double> concavity = rubble::pieceConcavity(r, parts);
    for (std::size_t i = 0; i < parts.size() && i < r.pieces.size(); ++i) {
        q.count += parts[i].size();
        for (const rubble::ConvexPolytope& p : parts[i])
            partVolume += p.volume();
        const rubble::Mesh& m = r.pieces[i].mesh;
        pieceVolume += r.pieces[i].mass.volume;
        q.concavity = std::max(q.concavity, concavity[i]);
        q.concavityOverA = std::max(q.concavityOverA, concavity[i] * m.bounds().diagonal() / amplitude);
        for (std::size_t t = 0; t < m.triangles.size(); ++t)
            if (m.materials[t] == rubble::kInteriorMaterial)
                for (const rubble::Vec3& v : m.corners(t))
                    q.vertexOverA = std::max(q.vertexOverA, outsideParts(v, parts[i]) / amplitude);
    }
    q.ratio.push_back(pieceVolume > 0 ? partVolume / pieceVolume : 0.0);
}

/// The amplitude of a rough cut in mesh units: relative to the cube root of the cells' mean volume.
double cutAmplitude(const rubble::Roughness& r, const std::vector<rubble::ConvexPolytope>& cells) {
    double volume = 0;
    int count = 0;
    for (const rubble::ConvexPolytope& c : cells)
        if (!c.empty()) {
            volume += c.volume();
            ++count;
        }
    return r.relative && count > 0 ? r.amplitude * std::cbrt(volume / count) : r.amplitude;
}

void runOnce(Case& c, rubble::BooleanKind kind, std::uint64_t seed, bool compareParts) {
    rubble::FractureParams params;
    params.backend = kind;
    params.sizeLaw.base = c.domain;
    params.sizeLaw.scale = 0;
    params.pattern = c.pattern;
    params.cells = c.cells;
    params.roughness = c.roughness;
    Samples& s = c.samples[kind];
    rubble::Mesh work; // the copy the runtime makes, not timed
    rubble::MeshFacts facts = c.known ? *c.known : rubble::MeshFacts{};
    if (c.known) {
        assignWithRoom(work.positions, c.mesh.positions);
        assignWithRoom(work.triangles, c.mesh.triangles);
        assignWithRoom(work.normals, c.mesh.normals);
        assignWithRoom(work.uvs, c.mesh.uvs);
        assignWithRoom(work.materials, c.mesh.materials);
        work.materialNames = c.mesh.materialNames;
        if (rubble::MeshTopology* t = facts.topology.get())
            assignWithRoom(t->twin, c.known->topology.get()->twin);
    }
    const auto t0 = Clock::now();
    auto r = c.known ? rubble::fracture(std::move(work), c.impact, params, seed, std::move(facts))
                     : rubble::fracture(c.mesh, c.impact, params, seed);
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
    rubble::recordConcavity(*r, parts);
    s.concavity.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t3).count());
    // The copies of the piece meshes are the caller's choice (the runtime makes them too) and not timed.
    const double piecesMs = std::chrono::duration<double, std::milli>(t1 - t0).count();
    const double partsMs = std::chrono::duration<double, std::milli>(t3 - t2).count();
    s.pieces.push_back(piecesMs);
    s.piecesCpu.push_back(r->stats.cpuTimings.totalMs);
    s.withParts.push_back(piecesMs + partsMs);
    s.cell.push_back(r->stats.timings.cellMs);
    s.boolean.push_back(r->stats.timings.booleanMs);
    s.islands.push_back(r->stats.timings.islandsMs - r->stats.timings.massMs);
    s.mass.push_back(r->stats.timings.massMs);
    s.decomposition.push_back(partsMs);
    s.fallbacks += r->stats.exactFallback ? 1 : 0;
    s.pieceCount = r->pieces.size();
    for (const rubble::Piece& p : r->pieces)
        s.mostCut = std::max(
            s.mostCut, static_cast<std::size_t>(std::count(p.mesh.materials.begin(), p.mesh.materials.end(),
                                                           rubble::kInteriorMaterial)));
    s.partCount = 0;
    double partVolume = 0, pieceVolume = 0;
    for (std::size_t i = 0; i < parts.size(); ++i) {
        s.partCount += parts[i].size();
        for (const rubble::ConvexPolytope& p : parts[i])
            partVolume += p.volume();
        pieceVolume += r->pieces[i].mass.volume;
    }
    s.excess.push_back(pieceVolume > 0 ? partVolume / pieceVolume - 1 : 0.0);
    if (!compareParts || !r->stats.rough)
        return;
    // The alternative: each rough piece decomposed on its own, with the default settings.
    const auto t4 = Clock::now();
    std::vector<std::vector<rubble::ConvexPolytope>> own;
    own.reserve(meshes.size());
    for (const rubble::Mesh& m : meshes) {
        auto d = rubble::decompose(m);
        own.push_back(d ? std::move(d->parts) : std::vector<rubble::ConvexPolytope>{});
    }
    const double ownMs = msSince(t4);
    const double amplitude = cutAmplitude(c.roughness, r->cells);
    measureParts(s.flatCut, *r, parts, amplitude, partsMs);
    measureParts(s.ownParts, *r, own, amplitude, ownMs);
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

/// Impact on the surface point furthest along dir (the centroid of the triangle furthest along it).
rubble::Impact impactAlong(const rubble::Mesh& m, const rubble::Vec3& dir) {
    std::size_t best = 0;
    double bestD = -1e300;
    for (std::size_t t = 0; t < m.triangleCount(); ++t) {
        const auto c = m.corners(t);
        const double d = dot(c[0] + c[1] + c[2], dir);
        if (d > bestD) {
            bestD = d;
            best = t;
        }
    }
    const auto c = m.corners(best);
    return {(c[0] + c[1] + c[2]) * (1.0 / 3.0), dir, 1};
}

/// Turns a fresh case into a chained one: chain − 1 impacts (Fast backend, seeded directions) each on the
/// largest piece of the previous one, whose convex parts come from updateDecomposition as in the runtime
/// (pieces of pieces). The measured impact is the chain-th, on that remainder with its updated parts.
bool chainCase(Case& c, int chain) {
    rubble::FractureParams params;
    params.backend = rubble::BooleanKind::Fast;
    params.sizeLaw.base = c.domain;
    params.sizeLaw.scale = 0;
    params.pattern = c.pattern;
    params.cells = 6;
    rubble::Rng rng(7);
    for (int k = 1; k < chain; ++k) {
        auto r = rubble::fracture(c.mesh, impactAlong(c.mesh, rng.unitVector()), params, 500 + k);
        if (!r || r->pieces.empty()) {
            std::cerr << "impact: " << c.name << ": chained impact " << k << " failed\n";
            return false;
        }
        std::vector<rubble::Mesh> meshes;
        std::vector<std::int32_t> pieceCells;
        std::size_t largest = 0;
        for (std::size_t i = 0; i < r->pieces.size(); ++i) {
            meshes.push_back(r->pieces[i].mesh);
            pieceCells.push_back(r->pieces[i].cell);
            if (r->pieces[i].mass.volume > r->pieces[largest].mass.volume)
                largest = i;
        }
        auto parts = rubble::updateDecomposition(c.parentParts, r->cells, meshes, pieceCells);
        c.mesh = std::move(meshes[largest]);
        c.parentParts = std::move(parts[largest]);
    }
    c.impact = impactAlong(c.mesh, rng.unitVector());
    c.name += "_chain" + std::to_string(chain);
    return true;
}

/// The rough rows: flat and concrete-rough twins, Fast backend, interleaved in one run; the
/// 10k cube with one cell and with a 16-cell shatter, and a 250k geodesic sphere copied (no known facts) and
/// edited in place (known facts, as the runtime keeps them).
std::vector<Case> roughCases(bool quick) {
    std::vector<Case> cases;
    Case cube;
    cube.mesh = rubble::makeSubdividedBox({-1, -1, -1}, {1, 1, 1}, quick ? 7 : 29);
    cube.name = "cube_" + std::to_string(cube.mesh.triangleCount());
    cube.impact = {{1, 0.05, 0.1}, {1, 0, 0}, 1};
    cases.push_back(cube);
    cube.name += "_shatter16";
    cube.pattern = rubble::CellPattern::Shatter;
    cube.cells = 16;
    cases.push_back(std::move(cube));
    if (!quick) {
        Case sphere;
        sphere.mesh = rubble::bench::megaMesh("geosphere", 250000);
        sphere.name = "geosphere_" + std::to_string(sphere.mesh.triangleCount());
        sphere.impact = {surfacePointAtMaxX(sphere.mesh), {1, 0, 0}, 1};
        sphere.domain = 0.5;
        cases.push_back(sphere);
        sphere.name += "_inplace";
        sphere.known = rubble::analyzeMesh(sphere.mesh).value();
        cases.push_back(std::move(sphere));
    }
    const std::size_t flat = cases.size();
    for (std::size_t i = 0; i < flat; ++i) {
        Case c = cases[i];
        c.name += "_rough";
        c.roughness = rubble::roughnessPreset("concrete");
        cases.push_back(std::move(c));
    }
    return cases;
}

/// --rough --parts: the flat cut's parts beside each rough piece's own, per rough case (Fast backend).
int writePartsComparison(const BenchArgs& args, const std::vector<Case>& cases, int runs, double otherCpu) {
    using rubble::bench::fixed;
    rubble::bench::Table table;
    table.header = {"model",
                    "triangles",
                    "parts_from",
                    "runs",
                    "pieces",
                    "parts_ms_median",
                    "parts_ms_min",
                    "convex_parts",
                    "rough_vertex_outside_over_A_max",
                    "parts_over_piece_volume_median",
                    "hausdorff_concavity_max",
                    "hausdorff_over_A_max",
                    "other_cpu_cores"};
    std::string data;
    for (const Case& c : cases) {
        auto it = c.samples.find(rubble::BooleanKind::Fast);
        if (!c.roughness.active() || it == c.samples.end() || it->second.flatCut.ms.empty())
            continue;
        const Samples& s = it->second;
        data += "\"" + c.name.substr(0, c.name.size() - 6) + "\""; // without _rough
        for (const auto& [from, q] : {std::pair<const char*, const PartsQuality*>{"flat_cut", &s.flatCut},
                                      {"rough_piece", &s.ownParts}}) {
            table.rows.push_back(
                {c.name, std::to_string(c.mesh.triangleCount()), from, std::to_string(q->ms.size()),
                 std::to_string(s.pieceCount), fixed(stats(q->ms).median), fixed(stats(q->ms).min),
                 std::to_string(q->count), fixed(q->vertexOverA, 3), fixed(stats(q->ratio).median, 4),
                 fixed(q->concavity, 4), fixed(q->concavityOverA, 3), fixed(otherCpu, 2)});
            data += " " + fixed(stats(q->ms).median) + " " + fixed(q->vertexOverA, 3) + " " +
                    fixed(q->concavityOverA, 3);
        }
        data += "\n";
    }
    rubble::bench::printTable(table);
    std::printf(
        "runs per case: %d (seeds 1000+i), both choices on the same fracture; A = the cut's amplitude; "
        "other processes used %.2f cores meanwhile\n",
        runs, otherCpu);
    if (!rubble::bench::writeCsv(fs::path(args.out) / "impact_rough_parts.csv", table))
        return 1;
    bool bound = true; // the flat cut's parts stay within A of every rough vertex (docs/roughness.md)
    for (const Case& c : cases)
        for (const auto& [kind, s] : c.samples)
            if (s.flatCut.vertexOverA > 1 + 1e-9) {
                std::cerr << "impact: " << c.name << ": a rough vertex lies " << s.flatCut.vertexOverA
                          << " A outside the flat cut's parts\n";
                bound = false;
            }
    rubble::bench::plotPng(
        args.out, "impact_rough_parts", data,
        "set termoption noenhanced\nset multiplot layout 1,3 title 'Convex parts of rough pieces: flat cut "
        "parts (as shipped) vs each rough piece decomposed, one run'\n"
        "set style data histograms\nset style fill solid 0.6\nset xtics rotate by -30 font ',8'\n"
        "set grid ytics\nset key top left font ',8'\nset logscale y\n"
        "set title 'ms to parts (median)' font ',9'\n"
        "plot $DATA u 2:xtic(1) t 'flat cut', '' u 5 t 'rough piece'\n"
        "unset logscale y\nset yrange [0:1.3]\n"
        "set title 'rough vertex outside parts / A' font ',9'\n"
        "plot $DATA u 3:xtic(1) t 'flat cut', '' u 6 t 'rough piece', 1 w l dt 2 lc 'black' t 'A'\n"
        "set yrange [0:*]\nset title 'Hausdorff concavity / A' font ',9'\n"
        "plot $DATA u 4:xtic(1) t 'flat cut', '' u 7 t 'rough piece'\nunset multiplot");
    return bound ? 0 : 1;
}

int runBench(const BenchArgs& args) {
    const int runs = args.quick ? 2 : std::max(1, args.runs);
    // The thesis's program measured here: impact → final collision shape (seconds, MEASUREMENTS.md).
    const std::map<std::size_t, double> thesis = {
        {12, 0.243}, {108, 0.280}, {588, 0.347}, {2700, 1.199}, {10092, 5.196}};
    std::vector<Case> cases;
    const std::vector<int> grid = args.rough   ? std::vector<int>{}
                                  : args.quick ? std::vector<int>{1, 3}
                                               : std::vector<int>{1, 3, 7, 15, 29};
    if (args.rough)
        cases = roughCases(args.quick);
    if (args.parts) // the rough cases only, once each (the in-place copy makes the same pieces)
        cases.erase(std::remove_if(cases.begin(), cases.end(),
                                   [](const Case& c) { return !c.roughness.active() || c.known; }),
                    cases.end());
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
    if (!args.rough) {
        // The largest cube once more, shattered into 6 cells (adjacent cells share faces: see the fallbacks).
        Case c = cases.back();
        c.name += "_shatter6";
        c.pattern = rubble::CellPattern::Shatter;
        c.thesisS = -1;
        cases.push_back(std::move(c));
    }
    if (!args.quick && !args.rough) {
        for (const fs::path& p : rubble::bench::repoModels()) {
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
    std::map<std::uint64_t, const Case*> decomposed; // by mesh hash: twins share their parent's parts
    for (Case& c : cases) {
        const std::uint64_t hash = c.mesh.hash();
        if (auto it = decomposed.find(hash); it != decomposed.end()) {
            c.parentParts = it->second->parentParts;
            c.decomposeMs = it->second->decomposeMs;
            continue;
        }
        const auto t0 = Clock::now();
        auto d = rubble::decompose(c.mesh);
        c.decomposeMs = msSince(t0);
        if (d)
            c.parentParts = std::move(d->parts);
        decomposed.emplace(hash, &c);
    }
    // Chained impacts (pieces of pieces carry many convex parts): the 10th impact on the largest remainder
    // of the largest cube and of two concave models.
    if (!args.quick && !args.rough) {
        const std::size_t fresh = cases.size();
        for (std::size_t i = 0; i < fresh; ++i)
            if (cases[i].pattern == rubble::CellPattern::SingleCell &&
                (cases[i].name == "cube_10092" || cases[i].name == "building" ||
                 cases[i].name == "fighter")) {
                Case c = cases[i];
                c.thesisS = -1;
                if (chainCase(c, 10))
                    cases.push_back(std::move(c));
            }
    }

    if (!args.only.empty())
        cases.erase(
            std::remove_if(cases.begin(), cases.end(),
                           [&](const Case& c) { return c.name.find(args.only) == std::string::npos; }),
            cases.end());

    const rubble::bench::CpuMeter cpu; // the cases are interleaved: one reading for all of them
    for (int run = 0; run < runs; ++run)
        for (Case& c : cases) {
            for (rubble::BooleanKind k :
                 {rubble::BooleanKind::Corefine, rubble::BooleanKind::Fast, rubble::BooleanKind::Nef}) {
                const bool wanted = std::find(args.backends.begin(), args.backends.end(), backendName(k)) !=
                                    args.backends.end();
                if (wanted && (k != rubble::BooleanKind::Nef || c.mesh.triangleCount() <= 2700))
                    runOnce(c, k, 1000 + static_cast<std::uint64_t>(run), args.parts);
            }
        }

    using rubble::bench::fixed;
    const double otherCpu = cpu.read().other;
    rubble::bench::Table table;
    table.header = {"model",
                    "triangles",
                    "backend",
                    "runs",
                    "failures",
                    "fallbacks",
                    "pieces",
                    "parent_parts",
                    "convex_parts",
                    "pieces_median_ms",
                    "pieces_min_ms",
                    "pieces_max_ms",
                    "with_parts_median_ms",
                    "with_parts_min_ms",
                    "with_parts_max_ms",
                    "cell_ms",
                    "boolean_ms",
                    "islands_ms",
                    "mass_uv_ms",
                    "decomposition_ms",
                    "parts_excess",
                    "initial_decomposition_ms",
                    "thesis_s",
                    "speedup_vs_thesis",
                    "pieces_cpu_median_ms",
                    "cut_triangles_max",
                    "concavity_ms",
                    "other_cpu_cores"};
    std::string failures;
    for (const Case& c : cases)
        for (const auto& [kind, s] : c.samples) {
            const rubble::bench::Stats pieces = stats(s.pieces), withParts = stats(s.withParts);
            const bool reference = c.thesisS > 0 && withParts.median > 0;
            table.rows.push_back({c.name,
                                  std::to_string(c.mesh.triangleCount()),
                                  backendName(kind),
                                  std::to_string(runs),
                                  std::to_string(s.failures),
                                  std::to_string(s.fallbacks),
                                  std::to_string(s.pieceCount),
                                  std::to_string(c.parentParts.size()),
                                  std::to_string(s.partCount),
                                  fixed(pieces.median),
                                  fixed(pieces.min),
                                  fixed(pieces.max),
                                  fixed(withParts.median),
                                  fixed(withParts.min),
                                  fixed(withParts.max),
                                  fixed(stats(s.cell).median),
                                  fixed(stats(s.boolean).median),
                                  fixed(stats(s.islands).median),
                                  fixed(stats(s.mass).median),
                                  fixed(stats(s.decomposition).median),
                                  fixed(stats(s.excess).median, 4),
                                  fixed(c.decomposeMs),
                                  reference ? fixed(c.thesisS) : "",
                                  reference ? fixed(c.thesisS * 1000 / withParts.median, 0) : "",
                                  fixed(stats(s.piecesCpu).median),
                                  std::to_string(s.mostCut),
                                  fixed(stats(s.concavity).median),
                                  fixed(otherCpu, 2)});
            if (s.failures > 0)
                failures += c.name + " " + backendName(kind) + ": " + std::to_string(s.failures) + " of " +
                            std::to_string(runs) + " runs failed: " + s.error + "\n";
        }
    rubble::bench::printTable(table);
    std::printf(
        "%sruns per case: %d, interleaved (run i uses seed 1000+i for every backend); stage columns are "
        "medians in ms; fallbacks = runs where Fast declined and Corefine made the split; the parent's "
        "decomposition is cached before the impact (initial_decomposition_ms); other processes used %.2f "
        "cores meanwhile\n",
        failures.c_str(), runs, otherCpu);
    if (args.parts)
        return writePartsComparison(args, cases, runs, otherCpu);
    if (!rubble::bench::writeCsv(fs::path(args.out) / (args.rough ? "impact_rough.csv" : "impact.csv"),
                                 table))
        return 1;
    if (args.rough) { // rough over flat, per case: impact → pieces in the fracture's CPU time
        std::string data;
        for (const Case& c : cases) {
            const auto flat = std::find_if(cases.begin(), cases.end(),
                                           [&](const Case& f) { return f.name + "_rough" == c.name; });
            if (flat == cases.end() || !c.samples.count(rubble::BooleanKind::Fast) ||
                !flat->samples.count(rubble::BooleanKind::Fast))
                continue;
            const Samples &r = c.samples.at(rubble::BooleanKind::Fast),
                          &f = flat->samples.at(rubble::BooleanKind::Fast);
            data += "\"" + flat->name + "\" " + fixed(stats(f.piecesCpu).median) + " " +
                    fixed(stats(r.piecesCpu).median) + "\n";
        }
        rubble::bench::plotPng(args.out, "impact_rough", data,
                               "set termoption noenhanced\nset style data histograms\nset style fill solid "
                               "0.6\nset ylabel 'impact -> pieces, CPU ms of the fracture'\n"
                               "set xtics rotate by -15\nset grid ytics\nset key top left\n"
                               "set title 'Flat vs rough (concrete) cut faces, fast backend, one run'\n"
                               "plot $DATA u 2:xtic(1) t 'flat', '' u 3 t 'rough'");
        return 0;
    }

    // One line per cube: triangles, thesis ms, then pieces+parts medians of corefine, fast, nef ("?" = none).
    std::string data;
    for (const Case& c : cases) {
        if (c.thesisS <= 0)
            continue;
        data += std::to_string(c.mesh.triangleCount()) + " " + fixed(c.thesisS * 1000);
        for (rubble::BooleanKind k :
             {rubble::BooleanKind::Corefine, rubble::BooleanKind::Fast, rubble::BooleanKind::Nef}) {
            auto it = c.samples.find(k);
            const bool has = it != c.samples.end() && !it->second.withParts.empty();
            data += " " + (has ? fixed(stats(it->second.withParts).median) : std::string("?"));
        }
        data += "\n";
    }
    rubble::bench::plotPng(
        args.out, "impact", data,
        "set datafile missing '?'\nset logscale xy\nset xrange [8:15000]\n"
        "set xlabel 'cube triangles'\nset ylabel 'impact -> pieces + convex parts (ms)'\n"
        "set grid\nset key top left\n"
        "set title 'Impact to final collision shapes: Rubble vs the thesis program (same "
        "machine)'\n"
        "plot $DATA u 1:2 w lp t 'thesis program (Nef + HACD)', '' u 1:3 w lp t 'Rubble, "
        "corefine', '' u 1:4 w lp t 'Rubble, fast', '' u 1:5 w lp t 'Rubble, nef', 16.7 w l "
        "dt 2 t '60 Hz frame'");
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
         app.add_flag(
             "--rough", args->rough,
             "only flat and rough (concrete) twins: the 10k cube with one cell and a 16-cell shatter, "
             "a 250k geodesic sphere copied and edited in place (impact_rough.csv/.png)");
         app.add_flag("--parts", args->parts,
                      "with --rough: also decompose every rough piece on its own and compare its parts with "
                      "the flat cut's (impact_rough_parts.csv/.png)");
         auto mega = std::make_shared<rubble::bench::MegaArgs>();
         auto megaOn = std::make_shared<bool>(false);
         app.add_flag("--mega", *megaOn,
                      "only the million-triangle rows (UV sphere, geodesic sphere, torus, subdivided arch at "
                      "100k, 250k, 1M; "
                      "impact_megamesh.csv/.png)");
         app.add_option("--mega-sizes", mega->sizes, "triangle counts of the --mega rows");
         app.add_option("--mega-kinds", mega->kinds, "meshes of the --mega rows")
             ->check(CLI::IsMember(rubble::bench::kMegaKinds));
         app.add_option("--hits", mega->hits, "random hits per --mega mesh")->check(CLI::Range(1, 10000));
         app.add_flag(
             "--no-facts", [mega](std::int64_t) { mega->facts = false; },
             "--mega: fracture without the meshes' known facts (every hit validates and measures the "
             "whole mesh)");
         app.add_flag("--world", mega->world,
                      "--mega: also run each mesh's hits through a DestructionRuntime on the Bullet binding, "
                      "side by side with the kernel (impact_megamesh_world.csv)");
         app.add_option("--chain", mega->chain,
                        "chained hits on the 250k UV sphere and geodesic sphere in --mega (0: none)")
             ->check(CLI::Range(0, 100000));
         return [args, mega, megaOn] {
             args->rough = args->rough || args->parts;
             if (!*megaOn)
                 return runBench(*args);
             mega->out = args->out;
             return rubble::bench::runMegaImpact(*mega);
         };
     }}};

} // namespace
