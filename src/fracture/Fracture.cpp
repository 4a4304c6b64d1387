// The fracture pipeline: validate, cells, booleans, interior attributes, islands, mass properties.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <span>

#include <time.h>

#include "BooleanBackends.hpp"
#include "FracturePipeline.hpp"
#include "geometry/OrientedShells.hpp"
#include "rubble/Fracture.hpp"
#include "rubble/Islands.hpp"
#include "rubble/MeshSimplify.hpp"
#include "rubble/Random.hpp"

namespace rubble {

namespace {

using Clock = std::chrono::steady_clock;

/// This thread's CPU time in ms.
double threadCpuMs() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}

/// A start on the wall clock and on this thread's CPU clock; a stage's time goes into both timings of a
/// result (FractureResult::timings and cpuTimings).
struct Stopwatch {
    Clock::time_point wall = Clock::now();
    double cpu = threadCpuMs();

    double wallMs() const { return std::chrono::duration<double, std::milli>(Clock::now() - wall).count(); }
    /// Sets the stage to the time since the start.
    void set(FractureResult& r, double FractureTimings::*stage) const {
        r.timings.*stage = wallMs();
        r.cpuTimings.*stage = threadCpuMs() - cpu;
    }
    /// Adds the time since the start to the stage.
    void add(FractureResult& r, double FractureTimings::*stage) const {
        r.timings.*stage += wallMs();
        r.cpuTimings.*stage += threadCpuMs() - cpu;
    }
};

/// Checks that mesh is a valid closed, oriented solid.
Status checkSolid(const Mesh& mesh) {
    if (mesh.empty())
        return makeError(ErrorCode::InvalidInput, "fracture: the mesh has no triangles");
    if (Status s = mesh.validate(); !s)
        return makeError(ErrorCode::InvalidInput, "fracture: invalid mesh: " + s.message());
    if (!detail::isClosedOriented(mesh))
        return makeError(
            ErrorCode::InvalidInput,
            "fracture: the mesh is not closed and consistently oriented (every edge must be shared "
            "by exactly two triangles in opposite directions); repair it first");
    return {};
}

Status positiveVolume(double volume) {
    if (!(volume > 0))
        return makeError(ErrorCode::InvalidInput, "fracture: the mesh does not enclose a positive volume");
    return {};
}

/// The input's volume and, when known facts fit it, its integrals (then nothing is scanned); else the mesh is
/// validated and integrals is null.
Status prepareInput(const Mesh& mesh, const MeshFacts& known, double& volume,
                    const VolumeIntegrals*& integrals) {
    integrals = nullptr;
    if (known.fit(mesh) && !mesh.empty()) {
        integrals = &known.integrals;
        volume = known.integrals.volume;
        return positiveVolume(volume);
    }
    if (Status s = checkSolid(mesh); !s)
        return s;
    volume = signedVolume(mesh);
    return positiveVolume(volume);
}

/// An orthonormal basis (u, v) of the plane with normal n, the same for n and -n (so both sides of a cut
/// get continuous texture coordinates).
void cutBasis(Vec3 n, Vec3& u, Vec3& v) {
    int big = 0;
    for (int a = 1; a < 3; ++a)
        if (std::abs(n[a]) > std::abs(n[big]))
            big = a;
    if (n[big] < 0)
        n = -n;
    int small = 0;
    for (int a = 1; a < 3; ++a)
        if (std::abs(n[a]) < std::abs(n[small]))
            small = a;
    Vec3 axis;
    axis[small] = 1;
    u = normalized(cross(axis, n));
    v = cross(n, u);
}

/// Cut faces made by these cells: planar UVs (projection onto the cut plane, scaled by uvScale) and the
/// plane's normal. Interior faces of earlier fractures (not on a face of these cells, or outside focus) keep
/// theirs. Only cells whose bounds hold a triangle are searched for its plane.
void finishCutFaces(Mesh& m, std::span<const ConvexPolytope> cells, double uvScale, const Aabb& focus,
                    double tolerance) {
    if (!m.hasMaterials())
        return;
    if (m.uvs.size() != 3 * m.triangles.size())
        m.uvs.assign(3 * m.triangles.size(), Vec2{});
    for (std::size_t t = 0; t < m.triangles.size(); ++t) {
        if (m.materials[t] != kInteriorMaterial)
            continue;
        const auto c = m.corners(t);
        if (!focus.contains(c[0]) || !focus.contains(c[1]) || !focus.contains(c[2]))
            continue;
        const Vec3 tn = cross(c[1] - c[0], c[2] - c[0]);
        // The cell face the triangle lies on: the plane nearest to its corners with a matching normal.
        const Plane* best = nullptr;
        double bestErr = std::numeric_limits<double>::infinity();
        Aabb box;
        for (const Vec3& p : c)
            box.extend(p);
        for (const ConvexPolytope& cell : cells) {
            if (!cell.bounds().overlaps(box, tolerance))
                continue;
            for (const PolytopeFace& f : cell.faces()) {
                if (std::abs(dot(f.plane.normal, tn)) < 0.5 * length(tn))
                    continue;
                const double e =
                    std::max({std::abs(f.plane.signedDistance(c[0])), std::abs(f.plane.signedDistance(c[1])),
                              std::abs(f.plane.signedDistance(c[2]))});
                if (e < bestErr) {
                    bestErr = e;
                    best = &f.plane;
                }
            }
        }
        if (!best || bestErr > tolerance)
            continue; // an earlier fracture's face
        Vec3 n = best->normal;
        if (dot(n, tn) < 0)
            n = -n;
        Vec3 u, v;
        cutBasis(n, u, v);
        for (int k = 0; k < 3; ++k) {
            const Vec3& p = c[static_cast<std::size_t>(k)];
            m.uvs[3 * t + static_cast<std::size_t>(k)] = {dot(p, u) * uvScale, dot(p, v) * uvScale};
            if (m.hasNormals())
                m.normals[3 * t + static_cast<std::size_t>(k)] = n;
        }
    }
}

/// The pieces of one split output. simplify: remove the vertices that carry no shape near the cells (focus).
/// With whole (the output's integrals), the largest island's integrals are whole minus the other islands'
/// plus what simplification changed, so it is not scanned; the others are measured.
void addPieces(Mesh&& m, const detail::OutputShells& shells, std::int32_t cell, double minVolume,
               bool simplify, const Aabb& focus, const VolumeIntegrals* whole, FractureResult& out) {
    if (m.empty())
        return;
    std::vector<Mesh> islands = splitIntoIslands(std::move(m), shells.triangleShell, shells.count);
    std::size_t largest = islands.size();
    VolumeIntegrals rest;
    if (whole) {
        const Stopwatch tm;
        largest = 0;
        for (std::size_t i = 1; i < islands.size(); ++i)
            if (islands[i].triangles.size() > islands[largest].triangles.size())
                largest = i;
        rest = *whole;
        for (std::size_t i = 0; i < islands.size(); ++i)
            if (i != largest)
                rest.accumulate(volumeIntegrals(islands[i], whole->reference), -1.0);
        tm.add(out, &FractureTimings::massMs);
    }
    for (std::size_t i = 0; i < islands.size(); ++i) {
        Mesh& island = islands[i];
        const bool byDifference = i == largest;
        if (simplify) {
            const Stopwatch ts;
            PlanarSimplifyParams sp;
            sp.focus = focus;
            sp.integralsReference = rest.reference;
            PlanarSimplifyReport report;
            island = simplifyPlanarRegions(std::move(island), sp, &report);
            if (byDifference && !report.unchanged)
                rest.accumulate(report.integralsChange, 1.0);
            ts.add(out, &FractureTimings::simplifyMs);
        }
        const Stopwatch tm;
        MeshFacts facts{true, island.triangles.size(), island.positions.size(),
                        byDifference ? rest : volumeIntegrals(island)};
        MassProperties mp = massProperties(facts.integrals);
        tm.add(out, &FractureTimings::massMs);
        if (!(mp.volume > minVolume)) {
            out.droppedVolume += mp.volume;
            continue;
        }
        out.pieces.push_back({std::move(island), mp, cell, std::move(facts)});
    }
}

} // namespace

std::unique_ptr<BooleanBackend> makeBooleanBackend(BooleanKind kind) {
    switch (kind) {
    case BooleanKind::Nef:
        return detail::makeNefBackend();
    case BooleanKind::Fast:
        return detail::makeFastBackend(true);
    case BooleanKind::Corefine:
        break;
    }
    return detail::makeCorefineBackend();
}

namespace detail {

bool splitIsSound(const SplitResult& s, double inputVolume, std::vector<OutputShells>* shells) {
    double v = 0;
    if (shells)
        shells->assign(1 + s.inside.size(), {});
    std::size_t index = 0;
    auto sound = [&](const Mesh& m) {
        OutputShells* out = shells ? &(*shells)[index++] : nullptr;
        if (m.empty())
            return true;
        if (!m.validate())
            return false;
        const std::int64_t count = closedOrientedShells(m, out ? &out->triangleShell : nullptr);
        if (count < 0)
            return false;
        if (out)
            out->count = static_cast<std::size_t>(count);
        const double mv =
            &m == &s.remainder && s.remainderIntegrals ? s.remainderIntegrals->volume : signedVolume(m);
        v += mv;
        return mv > 0;
    };
    if (!sound(s.remainder))
        return false;
    for (const Mesh& m : s.inside)
        if (!sound(m))
            return false;
    return std::abs(v - inputVolume) <= 1e-7 * inputVolume;
}

} // namespace detail

namespace {

/// The pipeline after input validation.
Result<FractureResult> runPipeline(const Mesh& mesh, std::vector<ConvexPolytope> cells,
                                   const FractureParams& params, const BooleanBackend& backend,
                                   bool exactRedo, double inputVolume) {
    const Stopwatch t0;
    FractureResult res;
    res.inputVolume = inputVolume;
    const Aabb meshBox = mesh.bounds();
    bool any = false;
    for (const ConvexPolytope& c : cells)
        any |= !c.empty() && c.bounds().overlaps(meshBox);
    if (!any)
        return makeError(ErrorCode::NoIntersection, "fracture: the impact's cells do not touch the mesh");

    auto split = backend.split(mesh, cells);
    // The result must close up and conserve volume; a failed fast split is redone exactly. The check labels
    // the shells of every output on the way; the islands below reuse them.
    std::vector<detail::OutputShells> shells;
    const Stopwatch tv;
    bool sound = split && detail::splitIsSound(*split, inputVolume, &shells);
    tv.set(res, &FractureTimings::verifyMs);
    if (split && !sound && exactRedo) {
        split = detail::makeCorefineBackend()->split(mesh, cells);
        if (split)
            split->exactFallback = true;
        sound = split && detail::splitIsSound(*split, inputVolume, &shells);
    }
    if (!split)
        return split.error();
    if (!sound)
        return makeError(ErrorCode::GeometryFailure,
                         "fracture: the " + backend.name() +
                             " backend produced pieces that are not closed or do not conserve volume" +
                             (exactRedo ? ", and so did its exact redo (corefine)" : ""));
    bool hit = false;
    for (const Mesh& m : split->inside)
        hit |= !m.empty();
    if (!hit)
        return makeError(
            ErrorCode::NoIntersection,
            "fracture: the impact's cells do not intersect the mesh (is the impact outside it?)");
    res.exactFallback = split->exactFallback;
    t0.set(res, &FractureTimings::booleanMs);

    const Stopwatch t1;
    Aabb focus; // where the cut made new faces and vertices (the cells, a little larger)
    for (const ConvexPolytope& c : cells)
        focus.extend(c.bounds());
    const Vec3 grow = Vec3{1, 1, 1} * (1e-6 * (focus.diagonal() + meshBox.diagonal()));
    focus = {focus.lo - grow, focus.hi + grow};
    const double onPlane = 1e-7 * meshBox.diagonal();
    finishCutFaces(split->remainder, cells, params.uvScale, focus, onPlane);
    for (std::size_t i = 0; i < split->inside.size(); ++i) // a cell's piece is cut by that cell only
        finishCutFaces(split->inside[i], std::span(cells).subspan(i, 1), params.uvScale, focus, onPlane);
    t1.set(res, &FractureTimings::massMs);
    const double minVolume = std::max(0.0, params.minPieceVolumeFraction) * inputVolume;
    const VolumeIntegrals* whole = split->remainderIntegrals ? &*split->remainderIntegrals : nullptr;
    addPieces(std::move(split->remainder), shells[0], -1, minVolume, params.simplifyPieces, focus, whole,
              res);
    for (std::size_t i = 0; i < split->inside.size(); ++i)
        addPieces(std::move(split->inside[i]), shells[i + 1], static_cast<std::int32_t>(i), minVolume,
                  params.simplifyPieces, focus, nullptr, res);
    t1.set(res, &FractureTimings::islandsMs);
    res.cells = std::move(cells);
    t0.set(res, &FractureTimings::totalMs);
    return res;
}

} // namespace

namespace detail {

Result<FractureResult> fractureWithBackend(const Mesh& mesh, std::vector<ConvexPolytope> cells,
                                           const FractureParams& params, const BooleanBackend& backend,
                                           bool exactRedo, const MeshFacts& known) {
    const Stopwatch t0;
    double volume = 0;
    const VolumeIntegrals* integrals = nullptr;
    if (Status s = prepareInput(mesh, known, volume, integrals); !s)
        return s.error();
    FractureResult pre; // the stages before the pipeline
    t0.set(pre, &FractureTimings::validateMs);
    auto r = runPipeline(mesh, std::move(cells), params, backend, exactRedo, volume);
    if (r) {
        r->timings.validateMs = pre.timings.validateMs;
        r->cpuTimings.validateMs = pre.cpuTimings.validateMs;
        t0.set(*r, &FractureTimings::totalMs);
    }
    return r;
}

} // namespace detail

Result<MeshFacts> analyzeMesh(const Mesh& mesh) {
    if (Status s = checkSolid(mesh); !s)
        return s.error();
    MeshFacts facts{true, mesh.triangles.size(), mesh.positions.size(), volumeIntegrals(mesh)};
    if (Status s = positiveVolume(facts.integrals.volume); !s)
        return s.error();
    return facts;
}

namespace {

/// The backend of params, given the input's integrals when they are known (Fast uses them).
std::unique_ptr<BooleanBackend> backendFor(BooleanKind kind, bool exactFallback,
                                           const VolumeIntegrals* integrals) {
    if (kind == BooleanKind::Fast)
        return detail::makeFastBackend(exactFallback, integrals);
    return makeBooleanBackend(kind);
}

} // namespace

Result<FractureResult> fractureWithCells(const Mesh& mesh, std::vector<ConvexPolytope> cells,
                                         const FractureParams& params, const MeshFacts& known) {
    const VolumeIntegrals* integrals = known.fit(mesh) ? &known.integrals : nullptr;
    return detail::fractureWithBackend(mesh, std::move(cells), params,
                                       *backendFor(params.backend, true, integrals),
                                       params.backend == BooleanKind::Fast, known);
}

Result<FractureResult> fracture(const Mesh& mesh, const Impact& impact, const FractureParams& params,
                                std::uint64_t seed, const MeshFacts& known) {
    const Stopwatch t0;
    double volume = 0;
    const VolumeIntegrals* integrals = nullptr;
    if (Status s = prepareInput(mesh, known, volume, integrals); !s)
        return s.error();
    if (!isFinite(impact.point) || !std::isfinite(impact.impulse))
        return makeError(ErrorCode::InvalidInput, "fracture: the impact point or impulse is not finite");
    FractureResult pre; // the stages before the pipeline
    t0.set(pre, &FractureTimings::validateMs);
    auto cellsFor = [&](std::uint64_t s) {
        const Stopwatch tc;
        std::vector<ConvexPolytope> cells = generateCells(mesh.bounds(), impact, params, s);
        tc.add(pre, &FractureTimings::cellMs);
        return cells;
    };
    auto finish = [&](Result<FractureResult> r, int redraws) {
        if (r) {
            r->redraws = redraws;
            for (auto [to, from] :
                 {std::pair{&r->timings, &pre.timings}, {&r->cpuTimings, &pre.cpuTimings}}) {
                to->validateMs = from->validateMs;
                to->cellMs = from->cellMs;
            }
            t0.set(*r, &FractureTimings::totalMs);
        }
        return r;
    };
    // The pattern is random: one the clipper declines as near-degenerate is redrawn (from derived seeds)
    // before the exact fallback cuts the seed's own pattern.
    constexpr int kRedraws = 2;
    if (params.backend == BooleanKind::Fast)
        for (int redraw = 0; redraw <= kRedraws; ++redraw) {
            std::vector<ConvexPolytope> cells = cellsFor(redraw == 0 ? seed : mixSeed(seed, 0xDA7A + redraw));
            if (cells.empty())
                break;
            auto r = runPipeline(mesh, std::move(cells), params, *detail::makeFastBackend(false, integrals),
                                 false, volume);
            if (r || r.error().code != ErrorCode::GeometryFailure)
                return finish(std::move(r), redraw);
        }
    std::vector<ConvexPolytope> cells = cellsFor(seed);
    if (cells.empty())
        return makeError(ErrorCode::NoIntersection, "fracture: no cell could be built around the impact");
    return finish(runPipeline(mesh, std::move(cells), params, *backendFor(params.backend, true, integrals),
                              params.backend == BooleanKind::Fast, volume),
                  0);
}

} // namespace rubble
