// The million-triangle rows, run by `rubble-bench impact --mega` and `rubble-bench decomposition
// --mega`: a UV sphere, a geodesic sphere, a torus and the arch asset subdivided, at 100k, 250k and 1M
// triangles. Every hit is a single cell of edge a quarter of the mesh's largest extent at a random surface
// point (seed = hit index).
// The clip-only bound is the time to clip just the triangles whose bounds meet the cell by its planes (found
// beforehand, untimed): what a fracture must at least do. Each hit fractures a copy of its input made outside
// the timed region, with the consuming fracture (Mesh&&): with known facts (a topology above 20k triangles),
// the remainder is that copy edited in place, as an object that owns its mesh would do. The meshes are given
// zero UVs and material 0 first (untimed), as every piece has them, and the copies have the spare capacity a
// piece's arrays have after its first in-place fracture (roomyCopy).
#include <algorithm>
#include <chrono>
#include <iostream>
#include <optional>
#include <sstream>

#include <time.h>

#include "BenchUtil.hpp"
#include "MegaMeshes.hpp"
#include "geometry/MeshTopology.hpp"
#include "rubble/collision/ConvexDecomposition.hpp"
#include "rubble/core/Random.hpp"
#include "rubble/fracture/Fracture.hpp"

namespace rubble::bench {

namespace {

using Clock = std::chrono::steady_clock;

std::string str(double v) {
    std::ostringstream o;
    o << v;
    return o.str();
}

/// A hit on a random triangle of mesh (seed), just inside the surface, pushing inward.
Impact randomHit(const Mesh& mesh, std::uint64_t seed) {
    Rng rng(mixSeed(0x5EED, seed));
    const std::size_t t = rng.below(mesh.triangles.size());
    const auto c = mesh.corners(t);
    const Vec3 n = normalized(cross(c[1] - c[0], c[2] - c[0]));
    const double size = mesh.bounds().diagonal();
    return {(c[0] + c[1] + c[2]) / 3.0 - n * (1e-3 * size), n, 100};
}

FractureParams hitParams(const Mesh& mesh) {
    FractureParams p;
    const Vec3 s = mesh.bounds().size();
    p.sizeLaw.base = 0.25 * std::max({s.x, s.y, s.z});
    p.sizeLaw.scale = 0;
    return p;
}

/// Clip-only bound: the triangles whose bounds meet a cell (found beforehand, not timed: a spatial index
/// would give them) clipped by every plane of that cell (ms), and how many there were.
double clipOnly(const Mesh& mesh, const std::vector<ConvexPolytope>& cells, std::size_t& touched) {
    std::vector<std::pair<std::size_t, std::size_t>> work; // (cell, triangle)
    for (std::size_t k = 0; k < cells.size(); ++k) {
        const Aabb cb = cells[k].bounds();
        for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
            Aabb tb;
            for (const Vec3& p : mesh.corners(t))
                tb.extend(p);
            if (tb.overlaps(cb))
                work.emplace_back(k, t);
        }
    }
    touched = work.size();
    const auto t0 = Clock::now();
    std::size_t kept = 0;
    std::vector<Vec3> poly, next;
    for (const auto& [k, t] : work) {
        const auto c = mesh.corners(t);
        poly.assign(c.begin(), c.end());
        for (const PolytopeFaceView& f : cells[k].faces()) {
            next.clear();
            for (std::size_t i = 0; i < poly.size(); ++i) {
                const Vec3& a = poly[i];
                const Vec3& b = poly[(i + 1) % poly.size()];
                const double da = f.plane.signedDistance(a), db = f.plane.signedDistance(b);
                if (da <= 0)
                    next.push_back(a);
                if ((da < 0 && db > 0) || (da > 0 && db < 0))
                    next.push_back(a + (b - a) * (da / (da - db)));
            }
            poly.swap(next);
            if (poly.size() < 3)
                break;
        }
        kept += poly.size();
    }
    const double ms = msSince(t0);
    if (kept == 1) // keeps the loop from being optimised away
        std::cout << "";
    return ms;
}

struct HitSamples {
    std::vector<double> withParts, withPartsCpu, pieces, validate, cell, boolean, islands, mass, simplify,
        parts, clip;
    std::vector<double> cpuValidate, cpuBoolean, cpuVerify, cpuIslands, cpuMass, cpuSimplify, cpuParts;
    std::vector<double> touched, excess;
    int failures = 0, fallbacks = 0, inPlace = 0, fullLabels = 0, raced = 0;
    std::vector<std::string> path; ///< per hit: how the remainder's islands were found
};

/// The mesh with zero texture coordinates and material 0 (untimed), as every piece has them after its first
/// fracture: a hit then measures what a hit on a piece costs, not a one-off fill of the attributes.
Mesh withAttributes(Mesh mesh) {
    mesh.uvs.assign(3 * mesh.triangles.size(), Vec2f{});
    mesh.materials.assign(mesh.triangles.size(), 0u);
    return mesh;
}

/// A copy of mesh (and of facts) with the spare capacity an object's mesh keeps after its first in-place
/// fracture (replaceTriangles grows the arrays by 1/16 more than they need), so a hit measures a hit on a
/// piece, not the one-off reallocation of a freshly loaded mesh.
template <class T>
std::vector<T> roomy(const std::vector<T>& v) {
    std::vector<T> out;
    out.reserve(v.size() + v.size() / 16);
    out.assign(v.begin(), v.end());
    return out;
}
Mesh roomyCopy(const Mesh& m) {
    Mesh c;
    c.positions = roomy(m.positions);
    c.triangles = roomy(m.triangles);
    c.normals = roomy(m.normals);
    c.uvs = roomy(m.uvs);
    c.materials = roomy(m.materials);
    c.materialNames = m.materialNames;
    return c;
}
MeshFacts roomyCopy(const MeshFacts& f) {
    MeshFacts c = f;
    if (const MeshTopology* t = f.topology.get())
        c.topology = MeshTopology{roomy(t->twin)};
    return c;
}

/// One fracture and its decomposition update, into s. The mesh and its facts are consumed (the caller copies
/// them, untimed, when it keeps them): with a topology in the facts, the fracture edits the mesh in place.
std::optional<FractureResult> hitOnce(const Mesh& mesh, Mesh&& work, MeshFacts&& facts,
                                      const std::vector<ConvexPolytope>& parentParts, const Impact& impact,
                                      std::uint64_t seed, HitSamples& s,
                                      std::vector<std::vector<ConvexPolytope>>* partsOut = nullptr) {
    const FractureParams params = hitParams(mesh);
    const double c0 = threadCpuMs();
    const auto t0 = Clock::now();
    auto r = fracture(std::move(work), impact, params, seed, std::move(facts));
    const double piecesMs = msSince(t0);
    if (!r) {
        ++s.failures;
        return std::nullopt;
    }
    const auto t1 = Clock::now();
    const double c1 = threadCpuMs();
    auto parts = updateDecomposition(parentParts, *r);
    const double partsMs = msSince(t1);
    s.cpuParts.push_back(threadCpuMs() - c1);
    const FractureTimings& ct = r->stats.cpuTimings;
    s.cpuValidate.push_back(ct.validateMs);
    s.cpuBoolean.push_back(ct.booleanMs - ct.verifyMs);
    s.cpuVerify.push_back(ct.verifyMs);
    s.cpuIslands.push_back(ct.islandsMs - ct.massMs - ct.simplifyMs);
    s.cpuMass.push_back(ct.massMs);
    s.cpuSimplify.push_back(ct.simplifyMs);
    s.withPartsCpu.push_back(threadCpuMs() - c0);
    s.withParts.push_back(piecesMs + partsMs);
    s.pieces.push_back(piecesMs);
    s.validate.push_back(r->stats.timings.validateMs);
    s.cell.push_back(r->stats.timings.cellMs);
    s.boolean.push_back(r->stats.timings.booleanMs);
    s.islands.push_back(r->stats.timings.islandsMs - r->stats.timings.massMs - r->stats.timings.simplifyMs);
    s.mass.push_back(r->stats.timings.massMs);
    s.simplify.push_back(r->stats.timings.simplifyMs);
    s.parts.push_back(partsMs);
    s.fallbacks += r->stats.exactFallback ? 1 : 0;
    s.inPlace += r->stats.editedInPlace ? 1 : 0;
    s.fullLabels += r->stats.islandsLabelledFully ? 1 : 0;
    s.raced += r->stats.islandsByRace ? 1 : 0;
    s.path.push_back(r->stats.islandsLabelledFully ? "full"
                     : r->stats.islandsByRace      ? "race"
                     : r->stats.editedInPlace      ? "walk"
                                                   : "copy");
    std::size_t touched = 0;
    s.clip.push_back(clipOnly(mesh, r->cells, touched));
    s.touched.push_back(static_cast<double>(touched));
    double partVolume = 0, pieceVolume = 0;
    for (std::size_t i = 0; i < parts.size(); ++i) {
        for (const ConvexPolytope& p : parts[i])
            partVolume += p.volume();
        pieceVolume += r->pieces[i].mass.volume;
    }
    s.excess.push_back(pieceVolume > 0 ? partVolume / pieceVolume - 1 : -1);
    if (partsOut)
        *partsOut = std::move(parts);
    return std::move(r).value();
}

// Fills the other_cpu_cores column (the last), prints the table and writes the CSV.
bool finishTable(const CpuMeter& cpu, const Table& table, Table& csv, const std::string& dir,
                 const std::string& file) {
    const std::string other = fixed(cpu.read().other, 2);
    for (auto& row : csv.rows)
        row.back() = other;
    printTable(table);
    std::cout << "other_cpu_cores " << other << " (the rest of the machine's busy cores during the run)\n";
    return writeCsv(std::filesystem::path(dir) / file, csv);
}

} // namespace

/// The table and CSV rows of one impact case; ratios against the median, or against the first hit (chains).
void addImpactRows(const std::string& name, const std::string& kind, std::size_t triangles,
                   const HitSamples& s, bool againstFirst, Table& table, Table& csv,
                   std::ostringstream& data) {
    const Stats w = stats(s.withParts), c = stats(s.withPartsCpu);
    const double base = againstFirst ? (s.withParts.empty() ? -1 : s.withParts.front()) : w.median;
    const double cpuBase = againstFirst ? (s.withPartsCpu.empty() ? -1 : s.withPartsCpu.front()) : c.median;
    const double ratio = base > 0 ? w.max / base : -1, cpuRatio = cpuBase > 0 ? c.max / cpuBase : -1;
    // The decomposition update alone (thread CPU): worst over the first hit or over the median.
    const Stats pc = stats(s.cpuParts);
    const double partsBase = againstFirst ? (s.cpuParts.empty() ? -1 : s.cpuParts.front()) : pc.median;
    const double partsRatio = partsBase > 0 ? pc.max / partsBase : -1;
    double excessMax = -1;
    for (double e : s.excess)
        excessMax = std::max(excessMax, e);
    const auto med = [](const std::vector<double>& v) { return stats(v).median; };
    const std::vector<double>* cpuStages[] = {&s.cpuValidate, &s.cpuBoolean,  &s.cpuVerify, &s.cpuIslands,
                                              &s.cpuMass,     &s.cpuSimplify, &s.cpuParts};
    std::vector<std::string> row{name,
                                 std::to_string(triangles),
                                 std::to_string(s.withParts.size()),
                                 fixed(w.median),
                                 fixed(w.max),
                                 fixed(ratio, 2),
                                 fixed(c.median),
                                 fixed(c.max),
                                 fixed(cpuRatio, 2)};
    for (const auto* cpuStage : cpuStages)
        row.push_back(fixed(med(*cpuStage)));
    row.insert(row.end(), {fixed(pc.max), fixed(partsRatio, 2), fixed(med(s.clip)), fixed(med(s.touched), 0),
                           fixed(stats(s.touched).max, 0)});
    table.rows.push_back(std::move(row));
    csv.rows.push_back({name,
                        kind,
                        std::to_string(triangles),
                        std::to_string(s.withParts.size()),
                        std::to_string(s.failures),
                        std::to_string(s.fallbacks),
                        againstFirst ? "first" : "median",
                        str(w.median),
                        str(w.max),
                        str(ratio),
                        str(c.median),
                        str(c.max),
                        str(cpuRatio),
                        str(med(s.pieces)),
                        str(med(s.validate)),
                        str(med(s.cell)),
                        str(med(s.boolean)),
                        str(med(s.islands)),
                        str(med(s.mass)),
                        str(med(s.simplify)),
                        str(med(s.parts)),
                        str(stats(s.parts).max),
                        str(excessMax),
                        str(med(s.clip)),
                        str(med(s.touched))});
    for (const auto* cpuStage : cpuStages)
        csv.rows.back().push_back(str(med(*cpuStage)));
    csv.rows.back().push_back(str(pc.max));
    csv.rows.back().push_back(str(partsRatio));
    csv.rows.back().push_back(str(stats(s.clip).max));
    csv.rows.back().push_back(str(stats(s.touched).max));
    csv.rows.back().push_back(""); // other_cpu_cores, filled by finishTable
    if (!againstFirst)
        data << kind << " " << triangles << " " << w.median << " " << w.max << " " << med(s.clip) << " "
             << c.median << "\n";
    std::cout << name << ": with parts median " << fixed(w.median) << " ms, max " << fixed(w.max)
              << " ms; CPU median " << fixed(c.median) << " ms, max " << fixed(c.max) << " ms; " << s.inPlace
              << " edited in place (" << s.fullLabels << " labelled in full, " << s.raced
              << " by racing walks)" << std::endl;
}

int runMegaImpact(const MegaArgs& args) {
    const CpuMeter cpu;
    Table table{{"mesh",       "tris",         "hits",      "with parts med ms",
                 "max",        "worst/base",   "cpu med",   "cpu max",
                 "cpu w/b",    "cpu validate", "clip",      "verify",
                 "islands",    "mass",         "simplify",  "parts",
                 "parts max",  "parts w/b",    "clip-only", "touched",
                 "touched max"},
                {}};
    Table csv{{"mesh",
               "kind",
               "triangles",
               "hits",
               "failures",
               "fallbacks",
               "ratio_base",
               "with_parts_median_ms",
               "with_parts_max_ms",
               "worst_over_base",
               "with_parts_cpu_median_ms",
               "with_parts_cpu_max_ms",
               "cpu_worst_over_base",
               "pieces_median_ms",
               "validate_median_ms",
               "cell_median_ms",
               "boolean_median_ms",
               "islands_median_ms",
               "mass_median_ms",
               "simplify_median_ms",
               "parts_median_ms",
               "parts_max_ms",
               "parts_excess_max",
               "clip_only_median_ms",
               "touched_triangles_median",
               "validate_cpu_median_ms",
               "clip_cpu_median_ms",
               "verify_cpu_median_ms",
               "islands_cpu_median_ms",
               "mass_cpu_median_ms",
               "simplify_cpu_median_ms",
               "parts_cpu_median_ms",
               "parts_cpu_max_ms",
               "parts_cpu_worst_over_base",
               "clip_only_max_ms",
               "touched_triangles_max",
               "other_cpu_cores"},
              {}};
    std::ostringstream data;
    Table worldTable{{"mesh", "tris", "hits", "kernel med ms", "world med ms", "max", "world/kernel",
                      "prepare", "boolean", "islands", "parts", "finish", "adoption", "shapes", "heap B/tri"},
                     {}};
    Table worldCsv{worldRowHeader(), {}};
    for (const std::string& kind : args.kinds)
        for (std::size_t size : args.sizes) {
            const Mesh mesh = withAttributes(megaMesh(kind, size));
            const std::string name = kind + "_" + std::to_string(mesh.triangles.size());
            auto d = decompose(mesh);
            if (!d) {
                std::cerr << name << ": " << d.error().message << "\n";
                continue;
            }
            // What an object knows of its mesh once it is added (checked and measured once, untimed).
            const MeshFacts facts = args.facts ? analyzeMesh(mesh).value() : MeshFacts{};
            HitSamples s;
            std::vector<Impact> impacts;
            for (int h = 0; h < args.hits; ++h) {
                const Impact impact = randomHit(mesh, static_cast<std::uint64_t>(h));
                impacts.push_back(impact);
                hitOnce(mesh, roomyCopy(mesh), roomyCopy(facts), d->parts, impact,
                        static_cast<std::uint64_t>(h), s);
            }
            addImpactRows(name, kind, mesh.triangles.size(), s, false, table, csv, data);
            if (args.world && !addWorldRow(name, mesh, d->parts, hitParams(mesh), impacts,
                                           stats(s.withParts).median, worldTable, worldCsv))
                return 1;
        }
    // Chained hits: the largest piece of each hit is hit again, with the parts its update gave it.
    Table hits; // one row per hit of the chains (thread CPU ms), to find the slow ones and what they did
    hits.header = {"mesh",
                   "hit",
                   "triangles_in",
                   "touched",
                   "pieces_ms",
                   "with_parts_cpu_ms",
                   "boolean_cpu_ms",
                   "verify_cpu_ms",
                   "islands_cpu_ms",
                   "mass_cpu_ms",
                   "simplify_cpu_ms",
                   "parts_cpu_ms",
                   "islands_path"};
    for (const char* chainKind : {"sphere", "geosphere"}) {
        if (args.chain <= 0)
            break;
        Mesh mesh = withAttributes(megaMesh(chainKind, 250000));
        const std::size_t startTriangles = mesh.triangles.size();
        auto d = decompose(mesh);
        std::vector<ConvexPolytope> parts = d ? d->parts : std::vector<ConvexPolytope>{};
        MeshFacts facts = args.facts ? analyzeMesh(mesh).value() : MeshFacts{};
        HitSamples s;
        std::vector<std::size_t> chainSizes; // the input's triangles, per successful hit
        for (int h = 0; h < args.chain; ++h) {
            std::vector<std::vector<ConvexPolytope>> pieceParts;
            const Impact impact = randomHit(mesh, static_cast<std::uint64_t>(1000 + h));
            auto r = hitOnce(mesh, roomyCopy(mesh), roomyCopy(facts), parts, impact,
                             static_cast<std::uint64_t>(1000 + h), s, &pieceParts);
            if (!r)
                continue;
            chainSizes.push_back(mesh.triangles.size());
            std::size_t largest = 0;
            for (std::size_t i = 1; i < r->pieces.size(); ++i)
                if (r->pieces[i].mass.volume > r->pieces[largest].mass.volume)
                    largest = i;
            mesh = std::move(r->pieces[largest].mesh);
            if (args.facts)
                facts = r->pieces[largest].facts;
            parts = std::move(pieceParts[largest]);
        }
        const std::string name = std::string(chainKind) + "_" + std::to_string(startTriangles) + "_chain" +
                                 std::to_string(args.chain);
        addImpactRows(name, std::string(chainKind) + "_chain", startTriangles, s, true, table, csv, data);
        for (std::size_t h = 0; h < s.withPartsCpu.size(); ++h)
            hits.rows.push_back({name, std::to_string(h), std::to_string(chainSizes[h]),
                                 fixed(s.touched[h], 0), fixed(s.pieces[h]), fixed(s.withPartsCpu[h]),
                                 fixed(s.cpuBoolean[h]), fixed(s.cpuVerify[h]), fixed(s.cpuIslands[h]),
                                 fixed(s.cpuMass[h]), fixed(s.cpuSimplify[h]), fixed(s.cpuParts[h]),
                                 s.path[h]});
        std::cout << "  (chain: ratios are max / first hit; the last piece has " << mesh.triangles.size()
                  << " triangles)\n";
    }
    if (args.chain > 0 && !writeCsv(std::filesystem::path(args.out) / "impact_megamesh_chain.csv", hits))
        return 1;
    if (args.world && !finishTable(cpu, worldTable, worldCsv, args.out, "impact_megamesh_world.csv"))
        return 1;
    if (args.world) { // per mesh: the kernel's median beside the world's stages (medians, ms)
        std::ostringstream world;
        for (const auto& r : worldCsv.rows) {
            world << r[0];
            for (std::size_t c : {4, 8, 9, 10, 11, 12, 13, 14, 15, 16})
                world << ' ' << r[c];
            world << '\n';
        }
        plotPng(args.out, "impact_megamesh_world", world.str(),
                "set style data histograms\nset style histogram rowstacked\nset style fill solid 0.8\n"
                "set boxwidth 0.35\nset ylabel 'ms (medians)'\nset key outside right\nset grid y\n"
                "set xtics rotate by -20\n"
                "set termoption noenhanced\nset title 'Impact to adopted pieces: kernel (left) and the "
                "world stages (right)'\n"
                "plot $DATA u ($0-0.2):2:(0.35) w boxes lc rgb 'gray' t 'kernel with parts', "
                "'' u ($0+0.2):($3+$4+$5+$6+$7+$8+$9+$10+$11):(0.35):xtic(1) w boxes t 'adoption', "
                "'' u ($0+0.2):($3+$4+$5+$6+$7+$8+$9+$10):(0.35) w boxes t 'handoff', "
                "'' u ($0+0.2):($3+$4+$5+$6+$7+$8+$9):(0.35) w boxes t 'finish', "
                "'' u ($0+0.2):($3+$4+$5+$6+$7+$8):(0.35) w boxes t 'parts', "
                "'' u ($0+0.2):($3+$4+$5+$6+$7):(0.35) w boxes t 'islands', "
                "'' u ($0+0.2):($3+$4+$5+$6):(0.35) w boxes t 'boolean', "
                "'' u ($0+0.2):($3+$4+$5):(0.35) w boxes t 'cells', "
                "'' u ($0+0.2):($3+$4):(0.35) w boxes t 'prepare', "
                "'' u ($0+0.2):3:(0.35) w boxes t 'queue'");
    }
    if (!finishTable(cpu, table, csv, args.out, "impact_megamesh.csv"))
        return 1;
    plotPng(
        args.out, "impact_megamesh", data.str(),
        "set logscale xy\nset xlabel 'triangles'\nset ylabel 'time (ms)'\nset grid\nset key top left\n"
        "set title 'Impact to pieces with convex parts (20 random hits) vs triangles'\n"
        "plot for [k in 'sphere geosphere torus arch'] $DATA u ((strcol(1) eq k) ? $2 : 1/0):3 w lp t k.' "
        "median', "
        "for [k in 'sphere geosphere torus arch'] $DATA u ((strcol(1) eq k) ? $2 : 1/0):4 w p t k.' worst', "
        "for [k in 'sphere geosphere torus arch'] $DATA u ((strcol(1) eq k) ? $2 : 1/0):6 w lp dt 3 t k.' "
        "CPU median', "
        "for [k in 'sphere geosphere torus arch'] $DATA u ((strcol(1) eq k) ? $2 : 1/0):5 w l dt 2 t k.' "
        "clip-only'");
    return 0;
}

int runMegaDecomposition(const MegaArgs& args) {
    const CpuMeter cpu;
    Table table{{"mesh", "tris", "parts", "excess", "initial ms", "cpu", "update med ms", "max", "cpu med",
                 "max", "hits"},
                {}};
    Table csv{{"mesh", "kind", "triangles", "parts", "excess", "initial_ms", "initial_cpu_ms",
               "update_median_ms", "update_max_ms", "update_cpu_median_ms", "update_cpu_max_ms", "hits",
               "other_cpu_cores"},
              {}};
    std::ostringstream data;
    for (const std::string& kind : args.kinds)
        for (std::size_t size : args.sizes) {
            const Mesh mesh = megaMesh(kind, size);
            const std::string name = kind + "_" + std::to_string(mesh.triangles.size());
            const double c0 = threadCpuMs();
            const auto t0 = Clock::now();
            auto d = decompose(mesh);
            const double initialMs = msSince(t0);
            const double initialCpuMs = threadCpuMs() - c0;
            if (!d) {
                std::cerr << name << ": " << d.error().message << "\n";
                continue;
            }
            std::vector<double> updates, updatesCpu;
            for (int h = 0; h < args.hits; ++h) {
                auto r = fracture(mesh, randomHit(mesh, static_cast<std::uint64_t>(h)), hitParams(mesh),
                                  static_cast<std::uint64_t>(h));
                if (!r)
                    continue;
                const double c1 = threadCpuMs();
                const auto t1 = Clock::now();
                const auto parts = updateDecomposition(d->parts, *r);
                updates.push_back(msSince(t1));
                updatesCpu.push_back(threadCpuMs() - c1);
            }
            const Stats u = stats(updates), uc = stats(updatesCpu);
            table.rows.push_back({name, std::to_string(mesh.triangles.size()),
                                  std::to_string(d->parts.size()), fixed(d->excess(), 4), fixed(initialMs),
                                  fixed(initialCpuMs), fixed(u.median), fixed(u.max), fixed(uc.median),
                                  fixed(uc.max), std::to_string(updates.size())});
            csv.rows.push_back({name, kind, std::to_string(mesh.triangles.size()),
                                std::to_string(d->parts.size()), str(d->excess()), str(initialMs),
                                str(initialCpuMs), str(u.median), str(u.max), str(uc.median), str(uc.max),
                                std::to_string(updates.size()), ""});
            data << kind << " " << mesh.triangles.size() << " " << initialMs << " " << u.median << " "
                 << initialCpuMs << " " << uc.median << "\n";
            std::cout << name << ": initial " << fixed(initialMs) << " ms, update median " << fixed(u.median)
                      << " ms" << std::endl;
        }
    if (!finishTable(cpu, table, csv, args.out, "decomposition_megamesh.csv"))
        return 1;
    plotPng(args.out, "decomposition_megamesh", data.str(),
            "set logscale xy\nset xlabel 'triangles'\nset ylabel 'time (ms)'\nset grid\nset key top left\n"
            "set title 'Convex decomposition of high-poly meshes vs triangles'\n"
            "plot for [k in 'sphere geosphere torus arch'] $DATA u ((strcol(1) eq k) ? $2 : 1/0):3 w lp t "
            "k.' initial', "
            "for [k in 'sphere geosphere torus arch'] $DATA u ((strcol(1) eq k) ? $2 : 1/0):4 w lp t k.' "
            "update', "
            "for [k in 'sphere geosphere torus arch'] $DATA u ((strcol(1) eq k) ? $2 : 1/0):5 w p t k.' "
            "initial CPU', "
            "for [k in 'sphere geosphere torus arch'] $DATA u ((strcol(1) eq k) ? $2 : 1/0):6 w p t k.' "
            "update CPU'");
    return 0;
}

} // namespace rubble::bench
