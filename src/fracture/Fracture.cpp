// The fracture pipeline: validate, cells, booleans, interior attributes, islands, mass properties.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <span>
#include <unordered_map>
#include <utility>

#include <time.h>

#include "BooleanBackends.hpp"
#include "FracturePipeline.hpp"
#include "RoughCut.hpp"
#include "geometry/Islands.hpp"
#include "geometry/MeshTopology.hpp"
#include "geometry/OrientedShells.hpp"
#include "geometry/TopologyEdit.hpp"
#include "rubble/core/ParameterCheck.hpp"
#include "rubble/core/Random.hpp"
#include "rubble/fracture/Fracture.hpp"
#include "rubble/fracture/FractureRequest.hpp"
#include "rubble/geometry/MeshCheck.hpp"
#include "rubble/geometry/MeshSimplify.hpp"

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
/// result (FractureStats::timings and cpuTimings).
struct Stopwatch {
    Clock::time_point wall = Clock::now();
    double cpu = threadCpuMs();

    double wallMs() const { return std::chrono::duration<double, std::milli>(Clock::now() - wall).count(); }
    /// Sets the stage to the time since the start.
    void set(FractureResult& r, double FractureTimings::*stage) const {
        r.stats.timings.*stage = wallMs();
        r.stats.cpuTimings.*stage = threadCpuMs() - cpu;
    }
    /// Adds the time since the start to the stage.
    void add(FractureResult& r, double FractureTimings::*stage) const {
        r.stats.timings.*stage += wallMs();
        r.stats.cpuTimings.*stage += threadCpuMs() - cpu;
    }
};

/// What the stages of one fracture share: the result they build and the clocks that time them. Validation
/// and cells are timed once; each attempt at the split restarts the rest.
class Stages {
public:
    FractureResult res; ///< what the stages made so far

    /// A new attempt at the split: a fresh result that keeps the validation and cell times.
    void restart() {
        FractureResult fresh;
        for (auto [to, from] : {std::pair{&fresh.stats.timings, &res.stats.timings},
                                {&fresh.stats.cpuTimings, &res.stats.cpuTimings}}) {
            to->validateMs = from->validateMs;
            to->cellMs = from->cellMs;
        }
        res = std::move(fresh);
        split_ = {};
    }
    /// Starts the clock of the pieces (after the split).
    void startPieces() { pieces_ = {}; }
    /// Sets stage to the time since the fracture began.
    void sinceStart(double FractureTimings::*stage) { start_.set(res, stage); }
    /// Sets stage to the time since the attempt's split began.
    void sinceSplit(double FractureTimings::*stage) { split_.set(res, stage); }
    /// Sets stage to the time since the pieces began.
    void sincePieces(double FractureTimings::*stage) { pieces_.set(res, stage); }
    /// Runs step and adds its time to stage.
    template <class Step>
    void time(double FractureTimings::*stage, Step&& step) {
        const Stopwatch clock;
        step();
        clock.add(res, stage);
    }

private:
    Stopwatch start_, split_, pieces_;
};

/// Checks that mesh is a valid closed, oriented solid.
Status checkSolid(const Mesh& mesh) {
    if (mesh.empty())
        return makeError(ErrorCode::InvalidInput, "fracture: the mesh has no triangles");
    if (Status s = mesh.validate(); !s)
        return makeError(ErrorCode::InvalidInput, "fracture: invalid mesh: " + s.message());
    if (Status s = checkCoordinateRange(mesh, "fracture"); !s)
        return s;
    std::vector<std::uint32_t> shellOf;
    const std::int64_t shells = detail::closedOrientedShells(mesh, &shellOf);
    if (shells < 0)
        return makeError(
            ErrorCode::InvalidInput,
            "fracture: the mesh is not closed and consistently oriented (every edge must be shared "
            "by exactly two triangles in opposite directions); repair it first");
    std::vector<std::string> listed;
    if (shells > 1 && detail::misnestedShells(mesh, shellOf, static_cast<std::size_t>(shells), 1, listed) > 0)
        return makeError(ErrorCode::InvalidInput,
                         "fracture: a shell faces the wrong way for its nesting (" + listed.front() +
                             "); a shell inside another must face inward (a cavity)");
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

/// Cut faces made by these cells: planar UVs (projection onto the cut plane, scaled by uvScale) and the
/// plane's normal. Interior faces of earlier fractures (not on a face of these cells, or outside focus) keep
/// theirs. Only cells whose bounds hold a triangle are searched for its plane.
void finishCutFaces(Mesh& m, std::span<const ConvexPolytope> cells, double uvScale, const Aabb& focus,
                    double tolerance, const std::vector<std::uint32_t>* only = nullptr) {
    if (!m.hasMaterials())
        return;
    if (m.uvs.size() != 3 * m.triangles.size())
        m.uvs.assign(3 * m.triangles.size(), Vec2f{});
    const std::size_t count = only ? only->size() : m.triangles.size();
    for (std::size_t i = 0; i < count; ++i) {
        const std::size_t t = only ? (*only)[i] : i;
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
            for (const PolytopeFaceView& f : cell.faces()) {
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
        detail::cutBasis(n, u, v);
        for (int k = 0; k < 3; ++k) {
            const Vec3& p = c[static_cast<std::size_t>(k)];
            m.uvs[3 * t + static_cast<std::size_t>(k)] = {dot(p, u) * uvScale, dot(p, v) * uvScale};
            if (m.hasNormals())
                m.normals[3 * t + static_cast<std::size_t>(k)] = Vec3f(n);
        }
    }
}

/// The pieces of one split output. simplify: remove the vertices that carry no shape near the cells (focus).
/// With whole (the output's integrals), the largest island's integrals are whole minus the other islands'
/// plus what simplification changed, so it is not scanned; the others are measured. topology: m's when it is
/// one island (kept, or found again when simplification changed it); with wantTopology, islands above
/// kTopologyAboveTriangles get theirs.
void addPieces(Mesh&& m, const detail::OutputShells& shells, std::int32_t cell, double minVolume,
               bool simplify, const Aabb& focus, const VolumeIntegrals* whole, Stages& st,
               MeshTopology* topology = nullptr, bool wantTopology = false) {
    if (m.empty())
        return;
    std::vector<Mesh> islands = splitIntoIslands(std::move(m), shells.triangleShell, shells.count);
    std::size_t largest = islands.size();
    VolumeIntegrals rest;
    if (whole)
        st.time(&FractureTimings::massMs, [&] {
            largest = 0;
            for (std::size_t i = 1; i < islands.size(); ++i)
                if (islands[i].triangles.size() > islands[largest].triangles.size())
                    largest = i;
            rest = *whole;
            for (std::size_t i = 0; i < islands.size(); ++i)
                if (i != largest)
                    rest.accumulate(volumeIntegrals(islands[i], whole->reference), -1.0);
        });
    for (std::size_t i = 0; i < islands.size(); ++i) {
        Mesh& island = islands[i];
        const bool byDifference = i == largest;
        if (simplify)
            st.time(&FractureTimings::simplifyMs, [&] {
                PlanarSimplifyParams sp;
                sp.focus = focus;
                sp.integralsReference = rest.reference;
                PlanarSimplifyReport report;
                island = simplifyPlanarRegions(std::move(island), sp, &report);
                if (byDifference && !report.unchanged)
                    rest.accumulate(report.integralsChange, 1.0);
                if (topology && !report.unchanged)
                    topology = nullptr; // found again below
            });
        MeshFacts facts;
        MassProperties mp;
        st.time(&FractureTimings::massMs, [&] {
            MeshTopology topo;
            const bool large = island.triangles.size() > kTopologyAboveTriangles;
            if (topology && islands.size() == 1 && large) {
                topo = std::move(*topology);
                detail::compactVerticesIfSparse(island);
            } else if (topology && islands.size() == 1) {
                island.removeUnreferencedVertices(); // small: the copying path's layout from now on
            } else if (wantTopology && large) {
                topo = buildTopology(island).value_or(MeshTopology{});
            }
            facts = MeshFacts{true, island.triangles.size(), island.positions.size(),
                              byDifference ? rest : volumeIntegrals(island), std::move(topo)};
            mp = massProperties(facts.integrals);
        });
        if (!(mp.volume > minVolume)) {
            st.res.droppedVolume += mp.volume;
            continue;
        }
        st.res.pieces.push_back({std::move(island), mp, cell, std::move(facts)});
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

bool splitIsSound(const SplitResult& s, double inputVolume, std::vector<OutputShells>* shells,
                  double otherVolume) {
    double v = otherVolume;
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

/// Where the cut made new faces and vertices: the cells, a little larger.
Aabb cutFocus(const std::vector<ConvexPolytope>& cells, const Aabb& meshBox) {
    Aabb focus;
    for (const ConvexPolytope& c : cells)
        focus.extend(c.bounds());
    const Vec3 grow = Vec3{1, 1, 1} * (1e-6 * (focus.diagonal() + meshBox.diagonal()));
    return {focus.lo - grow, focus.hi + grow};
}

/// The start of a pipeline: the result knows the input volume, meshBox is the mesh's bounds; an error when
/// no cell reaches them.
Status startPipeline(const Mesh& mesh, const std::vector<ConvexPolytope>& cells, double inputVolume,
                     Stages& st, Aabb& meshBox) {
    st.restart();
    st.res.inputVolume = inputVolume;
    meshBox = mesh.bounds();
    bool any = false;
    for (const ConvexPolytope& c : cells)
        any |= !c.empty() && c.bounds().overlaps(meshBox);
    if (!any)
        return makeError(ErrorCode::NoIntersection, "fracture: the impact's cells do not touch the mesh");
    return {};
}

Error cellsCutNothing() {
    return makeError(ErrorCode::NoIntersection,
                     "fracture: the impact's cells do not intersect the mesh (is the impact outside it?)");
}

/// Interior UVs of the cells' pieces: a cell's piece is cut by that cell only.
void finishInsideCutFaces(std::vector<Mesh>& inside, const std::vector<ConvexPolytope>& cells,
                          const FractureParams& params, const Aabb& focus, double onPlane) {
    for (std::size_t i = 0; i < inside.size(); ++i)
        finishCutFaces(inside[i], std::span(cells).subspan(i, 1), params.uvScale, focus, onPlane);
}

void simplifyAroundCut(Mesh& mesh, MeshTopology& topology, std::span<const std::uint32_t> added,
                       const Aabb& focus, double meshDiagonal, VolumeIntegrals& rest);

/// The cells' pieces in place: a piece that is one shell and whose first insideKept[i] triangles are the
/// input's (the rest new) is simplified around its new triangles only, with its topology.
struct InsideInPlace {
    const std::vector<std::size_t>& insideKept;
    double meshDiagonal;
};

/// After the remainder's pieces: the cells' pieces (shells[i + 1] for inside[i]) and the cells.
Status finishPieces(std::vector<Mesh>&& inside, const std::vector<detail::OutputShells>& shells,
                    std::vector<ConvexPolytope>&& cells, const FractureParams& params, double minVolume,
                    const Aabb& focus, bool wantTopology, Stages& st,
                    const InsideInPlace* inPlace = nullptr) {
    for (std::size_t i = 0; i < inside.size(); ++i) {
        Mesh& m = inside[i];
        std::optional<MeshTopology> topology;
        if (inPlace && params.simplifyPieces && shells[i + 1].count == 1 && i < inPlace->insideKept.size() &&
            inPlace->insideKept[i] < m.triangles.size())
            st.time(&FractureTimings::simplifyMs, [&] {
                topology = buildTopology(m);
                if (!topology)
                    return;
                std::vector<std::uint32_t> added(m.triangles.size() - inPlace->insideKept[i]);
                for (std::size_t k = 0; k < added.size(); ++k)
                    added[k] = static_cast<std::uint32_t>(inPlace->insideKept[i] + k);
                VolumeIntegrals unused; // the piece is measured in full
                simplifyAroundCut(m, *topology, added, focus, inPlace->meshDiagonal, unused);
            });
        addPieces(std::move(m), shells[i + 1], static_cast<std::int32_t>(i), minVolume,
                  params.simplifyPieces && !topology, focus, nullptr, st, topology ? &*topology : nullptr,
                  wantTopology);
    }
    st.sincePieces(&FractureTimings::islandsMs);
    st.res.cells = std::move(cells);
    return {};
}

/// The pipeline after input validation, an attempt of its own in st. wantTopology: pieces above
/// kTopologyAboveTriangles get theirs.
Status runPipeline(Stages& st, const Mesh& mesh, std::vector<ConvexPolytope> cells,
                   const FractureParams& params, const BooleanBackend& backend, bool exactRedo,
                   double inputVolume, bool wantTopology = false) {
    FractureResult& res = st.res;
    Aabb meshBox;
    if (Status s = startPipeline(mesh, cells, inputVolume, st, meshBox); !s)
        return s;

    auto split = backend.split(mesh, cells);
    const double onPlane = 1e-7 * meshBox.diagonal();
    // Rough cut faces need the clipper's split: each cut triangle in both outputs it separates.
    res.stats.rough = split && params.roughness.active() && !split->exactFallback && backend.name() == "fast";
    if (res.stats.rough)
        detail::roughenSplit(*split, cells, params.roughness, params.uvScale, meshBox, onPlane);
    // The result must close up and conserve volume; a failed fast split is redone exactly (flat). The check
    // labels the shells of every output on the way; the islands below reuse them.
    std::vector<detail::OutputShells> shells;
    bool sound = false;
    st.time(&FractureTimings::verifyMs,
            [&] { sound = split && detail::splitIsSound(*split, inputVolume, &shells); });
    if (split && !sound && exactRedo) {
        split = detail::makeCorefineBackend()->split(mesh, cells);
        if (split)
            split->exactFallback = true;
        res.stats.rough = false;
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
        return cellsCutNothing();
    res.stats.exactFallback = split->exactFallback;
    st.sinceSplit(&FractureTimings::booleanMs);

    st.startPieces();
    const Aabb focus = cutFocus(cells, meshBox);
    if (!res.stats.rough) { // roughenSplit gave the rough faces theirs
        finishCutFaces(split->remainder, cells, params.uvScale, focus, onPlane);
        finishInsideCutFaces(split->inside, cells, params, focus, onPlane);
    }
    st.sincePieces(&FractureTimings::massMs);
    const double minVolume = std::max(0.0, params.minPieceVolumeFraction) * inputVolume;
    const VolumeIntegrals* whole = split->remainderIntegrals ? &*split->remainderIntegrals : nullptr;
    // Rough pieces are not simplified: its plane tolerance would treat the two sides of a cut differently.
    FractureParams finish = params;
    finish.simplifyPieces = params.simplifyPieces && !res.stats.rough;
    addPieces(std::move(split->remainder), shells[0], -1, minVolume, finish.simplifyPieces, focus, whole, st,
              nullptr, wantTopology);
    return finishPieces(std::move(split->inside), shells, std::move(cells), finish, minVolume, focus,
                        wantTopology, st);
}

/// simplifyPlanarRegions on the triangles around the cut only (the added ones and those sharing a corner
/// with one: only the added triangles' corners can go), written back in place; rest gets the change of the
/// integrals.
void simplifyAroundCut(Mesh& mesh, MeshTopology& topology, std::span<const std::uint32_t> added,
                       const Aabb& focus, double meshDiagonal, VolumeIntegrals& rest) {
    const std::vector<std::uint32_t> near = detail::trianglesAround(mesh, topology, added);
    Mesh local; // the triangles near the cut, their vertices numbered in order of first use
    std::unordered_map<std::uint32_t, std::uint32_t> index;
    std::vector<std::uint32_t> global;
    const bool hasN = mesh.hasNormals();
    for (std::uint32_t t : near) {
        Triangle tri = mesh.triangles[t];
        for (std::uint32_t& v : tri) {
            auto [it, fresh] = index.emplace(v, static_cast<std::uint32_t>(global.size()));
            if (fresh) {
                global.push_back(v);
                local.positions.push_back(mesh.positions[v]);
            }
            v = it->second;
        }
        local.triangles.push_back(tri);
        local.materials.push_back(mesh.materials[t]);
        local.uvs.insert(local.uvs.end(), mesh.uvs.begin() + 3 * t, mesh.uvs.begin() + 3 * t + 3);
        if (hasN)
            local.normals.insert(local.normals.end(), mesh.normals.begin() + 3 * t,
                                 mesh.normals.begin() + 3 * t + 3);
    }
    const double localDiagonal = local.bounds().diagonal();
    if (!(localDiagonal > 0))
        return;
    PlanarSimplifyParams sp;
    sp.focus = focus;
    sp.integralsReference = rest.reference;
    sp.planeTolerance *= meshDiagonal / localDiagonal; // relative to the whole mesh, as for a full pass
    PlanarSimplifyReport report;
    Mesh simple = simplifyPlanarRegions(std::move(local), sp, &report);
    if (report.unchanged)
        return;
    std::vector<std::uint32_t> toGlobal; // the simplified mesh's vertices: the local ones not removed
    toGlobal.reserve(simple.positions.size());
    for (std::uint32_t v = 0, r = 0; v < global.size(); ++v) {
        if (r < report.removedVertices.size() && report.removedVertices[r] == v) {
            ++r;
            continue;
        }
        toGlobal.push_back(global[v]);
    }
    detail::TriangleBatch batch{std::move(simple.triangles), std::move(simple.normals), std::move(simple.uvs),
                                std::move(simple.materials)};
    for (Triangle& tri : batch.triangles)
        for (std::uint32_t& v : tri)
            v = toGlobal[v];
    if (detail::replaceTriangles(mesh, topology, near, {}, std::move(batch)))
        rest.accumulate(report.integralsChange, 1.0);
}

/// runPipeline on a mesh with its topology (held fits mesh; backend is an EditingBackend), edited in place
/// (docs/megamesh.md): the split's remainder is an edit, checked around the cut and then applied; its islands
/// are found by a walk around the cut, with the full labelling as the fallback. A split that fails leaves
/// mesh and topology as they were (a failed edit is redone by Corefine on the intact mesh when exactRedo is
/// set); on success the mesh is consumed.
Status runInPlace(Stages& st, Mesh& mesh, HeldTopology& held, std::vector<ConvexPolytope> cells,
                  const FractureParams& params, const BooleanBackend& backend, bool exactRedo,
                  double inputVolume) {
    const auto* editing = &dynamic_cast<const detail::EditingBackend&>(backend);
    MeshTopology& topology = *held.get();
    FractureResult& res = st.res;
    Aabb meshBox;
    if (Status s = startPipeline(mesh, cells, inputVolume, st, meshBox); !s)
        return s;
    const std::size_t nT = mesh.triangles.size();

    auto split = editing->splitAsEdit(mesh, cells, meshBox);
    const double onPlane = 1e-7 * meshBox.diagonal();
    // Rough cut faces: the edit's new triangles and the cells' pieces, before the checks.
    res.stats.rough = split && params.roughness.active();
    if (res.stats.rough)
        detail::roughenEdit(*split, mesh, cells, params.roughness, params.uvScale, meshBox, onPlane);
    // Rough pieces are not simplified (as in runPipeline).
    FractureParams finish = params;
    finish.simplifyPieces = params.simplifyPieces && !res.stats.rough;
    std::vector<detail::OutputShells> shells;
    std::optional<std::vector<std::uint32_t>> slots;
    bool cutNothing = false;
    st.time(&FractureTimings::verifyMs, [&] {
        if (!split)
            return;
        detail::RemainderEdit& edit = split->remainder;
        const bool remainderEmpty = edit.removed.size() == nT && edit.added.triangles.empty();
        const double rest = remainderEmpty ? 0.0 : split->remainderIntegrals.volume;
        SplitResult debris;
        debris.inside = std::move(split->inside);
        if ((remainderEmpty || rest > 0) && detail::splitIsSound(debris, inputVolume, &shells, rest)) {
            bool hit = false;
            for (const Mesh& m : debris.inside)
                hit |= !m.empty();
            if (!hit) {
                cutNothing = true;
                return;
            }
            const bool noUvs = mesh.uvs.empty(), noMaterials = mesh.materials.empty();
            // The layout every split output has, with room for the edit (as the caller's copy has).
            const std::size_t room = std::max(nT, mesh.triangles.capacity());
            if (noUvs) {
                mesh.uvs.reserve(3 * room);
                mesh.uvs.assign(3 * nT, Vec2f{});
            }
            if (noMaterials) {
                mesh.materials.reserve(room);
                mesh.materials.assign(nT, 0u);
            }
            slots = detail::replaceTriangles(mesh, topology, edit.removed, edit.newPositions,
                                             std::move(edit.added));
            if (!slots && noUvs)
                mesh.uvs.clear();
            if (!slots && noMaterials)
                mesh.materials.clear();
        }
        split->inside = std::move(debris.inside);
    });
    if (cutNothing)
        return cellsCutNothing();
    if (!slots) {
        if (!exactRedo)
            return split ? makeError(ErrorCode::GeometryFailure,
                                     "fracture: the " + backend.name() +
                                         " backend's split is not closed around the cut or does not conserve "
                                         "volume")
                         : split.error();
        const double verifyMs = res.stats.timings.verifyMs, verifyCpuMs = res.stats.cpuTimings.verifyMs;
        if (Status s = runPipeline(st, mesh, std::move(cells), params, *detail::makeCorefineBackend(), false,
                                   inputVolume, true);
            !s)
            return s;
        res.stats.exactFallback = true;
        res.stats.timings.verifyMs += verifyMs;
        res.stats.cpuTimings.verifyMs += verifyCpuMs;
        return {};
    }
    res.stats.editedInPlace = true;
    st.sinceSplit(&FractureTimings::booleanMs);

    st.startPieces();
    const Aabb focus = cutFocus(cells, meshBox);
    if (!res.stats.rough) { // roughenEdit gave the rough faces theirs
        finishCutFaces(mesh, cells, params.uvScale, focus, onPlane, &*slots);
        finishInsideCutFaces(split->inside, cells, params, focus, onPlane);
    }
    // One shell when a walk around the cut joins all new triangles (the kept ones next to the cut touch
    // them); else the full labelling.
    detail::OutputShells rest;
    const std::vector<std::uint32_t>& removed = split->remainder.removed;
    VolumeIntegrals& restIntegrals = split->remainderIntegrals;
    bool one = !mesh.empty() &&
               (removed.empty() ? slots->empty() : detail::stillOneShell(mesh, topology, *slots, focus));
    std::vector<Mesh> chips; // shells that broke off the remainder, found by racing walks
    if (!one && !mesh.empty() && !removed.empty()) {
        res.stats.islandsByRace = true;
        const auto broken = detail::racingIslands(topology, *slots);
        std::vector<std::uint32_t> gone;
        for (const auto& shell : broken)
            gone.insert(gone.end(), shell.begin(), shell.end());
        std::sort(gone.begin(), gone.end());
        std::vector<std::uint32_t> kept; // the added slots that stay in the remainder
        for (std::uint32_t s : *slots)
            if (!std::binary_search(gone.begin(), gone.end(), s))
                kept.push_back(s);
        if (!gone.empty()) { // all out at once, then told apart (linear in what broke off)
            auto taken = detail::takeShells(mesh, topology, gone, &kept);
            if (!taken)
                return makeError(ErrorCode::GeometryFailure, "fracture: an island does not close");
            chips = splitIntoIslands(std::move(*taken));
        }
        for (const Mesh& c : chips)
            restIntegrals.accumulate(volumeIntegrals(c, restIntegrals.reference), -1.0);
        *slots = std::move(kept);
        one = true;
    }
    if (one) {
        rest.count = 1;
    } else if (!mesh.empty()) {
        res.stats.islandsLabelledFully = true;
        const std::int64_t count = detail::closedOrientedShells(mesh, &rest.triangleShell);
        if (count < 1)
            return makeError(ErrorCode::GeometryFailure,
                             "fracture: the remainder edited in place is not closed");
        rest.count = static_cast<std::size_t>(count);
        one = count == 1;
    }
    st.sincePieces(&FractureTimings::massMs);
    if (one && finish.simplifyPieces)
        st.time(&FractureTimings::simplifyMs,
                [&] { simplifyAroundCut(mesh, topology, *slots, focus, meshBox.diagonal(), restIntegrals); });
    const double minVolume = std::max(0.0, params.minPieceVolumeFraction) * inputVolume;
    addPieces(std::move(mesh), rest, -1, minVolume, finish.simplifyPieces && !one, focus, &restIntegrals, st,
              one ? &topology : nullptr, true);
    for (Mesh& chip : chips) // measured: they are small
        addPieces(std::move(chip), detail::OutputShells{{}, 1}, -1, minVolume, finish.simplifyPieces, focus,
                  nullptr, st, nullptr, true);
    const InsideInPlace debris{split->insideKept, meshBox.diagonal()};
    return finishPieces(std::move(split->inside), shells, std::move(cells), finish, minVolume, focus, true,
                        st, &debris);
}

/// Where one fracture cuts, decided once when it starts: the mesh as given, or, when the backend edits and
/// the known facts hold the mesh's topology, the mesh edited in place: the caller's when it handed the mesh
/// and its facts over, else a copy.
class Place {
public:
    /// A fracture of mesh: copied to be edited in place.
    Place(const Mesh& mesh, const MeshFacts& known, bool editing) : mesh_(&mesh), known_(&known) {
        if (!editable(mesh, known, editing))
            return;
        copy_ = mesh;
        copyFacts_ = known;
        mesh_ = edit_ = &copy_;
        known_ = &copyFacts_;
        topology_ = &copyFacts_.topology;
    }
    /// A fracture of a mesh handed over with its facts: edited in place itself.
    Place(Mesh& mesh, MeshFacts& known, bool editing) : mesh_(&mesh), known_(&known) {
        if (editable(mesh, known, editing)) {
            edit_ = &mesh;
            topology_ = &known.topology;
        }
    }
    Place(const Place&) = delete;
    Place& operator=(const Place&) = delete;

    /// The mesh cut.
    const Mesh& mesh() const { return *mesh_; }
    /// Its facts.
    const MeshFacts& known() const { return *known_; }
    /// Cuts the validated mesh by cells into st: runInPlace or runPipeline.
    Status cut(Stages& st, std::vector<ConvexPolytope> cells, const FractureParams& params,
               const BooleanBackend& backend, bool exactRedo, double volume) const {
        if (edit_)
            return runInPlace(st, *edit_, *topology_, std::move(cells), params, backend, exactRedo, volume);
        return runPipeline(st, *mesh_, std::move(cells), params, backend, exactRedo, volume);
    }

private:
    static bool editable(const Mesh& mesh, const MeshFacts& known, bool editing) {
        return editing && known.fit(mesh) && known.topology.fits(mesh);
    }

    const Mesh* mesh_;
    const MeshFacts* known_;
    Mesh* edit_ = nullptr;
    HeldTopology* topology_ = nullptr;
    Mesh copy_;
    MeshFacts copyFacts_;
};

/// Cuts place by given cells after the input's validation, with its timings.
Result<FractureResult> cutWithCells(const Place& place, std::vector<ConvexPolytope> cells,
                                    const FractureParams& params, const BooleanBackend& backend,
                                    bool exactRedo) {
    Stages st;
    if (Status s = validateRoughness(params.roughness); !s)
        return makeError(ErrorCode::InvalidInput, "fracture: " + s.message());
    double volume = 0;
    const VolumeIntegrals* integrals = nullptr;
    if (Status s = prepareInput(place.mesh(), place.known(), volume, integrals); !s)
        return s.error();
    st.sinceStart(&FractureTimings::validateMs);
    if (Status s = place.cut(st, std::move(cells), params, backend, exactRedo, volume); !s)
        return s.error();
    st.sinceStart(&FractureTimings::totalMs);
    return std::move(st.res);
}

/// The backend of params, given the input's integrals when they are known (Fast uses them).
std::unique_ptr<BooleanBackend> backendFor(BooleanKind kind, bool exactFallback,
                                           const VolumeIntegrals* integrals) {
    if (kind == BooleanKind::Fast)
        return detail::makeFastBackend(exactFallback, integrals);
    return makeBooleanBackend(kind);
}

/// fractureWithCells with params' backend.
Result<FractureResult> cutWithCells(const Place& place, std::vector<ConvexPolytope> cells,
                                    const FractureParams& params) {
    const VolumeIntegrals* integrals = place.known().fit(place.mesh()) ? &place.known().integrals : nullptr;
    return cutWithCells(place, std::move(cells), params, *backendFor(params.backend, true, integrals),
                        params.backend == BooleanKind::Fast);
}

/// params with the fracture's seed mixed into the roughness seed (a rough surface per fracture).
FractureParams seeded(const FractureParams& params, std::uint64_t seed) {
    FractureParams p = params;
    if (p.roughness.active())
        p.roughness.seed = mixSeed(seed, p.roughness.seed);
    return p;
}

/// fracture: cells from the seed (redrawn when Fast declines them), cut where place says.
Result<FractureResult> cutAtImpact(const Place& place, const Impact& impact, const FractureParams& original,
                                   std::uint64_t seed) {
    const FractureParams params = seeded(original, seed);
    Stages st;
    if (Status s = validateRoughness(params.roughness); !s)
        return makeError(ErrorCode::InvalidInput, "fracture: " + s.message());
    double volume = 0;
    const VolumeIntegrals* integrals = nullptr;
    if (Status s = checkFractureParams(impact, params); !s)
        return makeError(ErrorCode::InvalidInput, "fracture: " + s.message());
    if (Status s = prepareInput(place.mesh(), place.known(), volume, integrals); !s)
        return s.error();
    st.sinceStart(&FractureTimings::validateMs);
    auto cellsFor = [&](std::uint64_t s) {
        std::vector<ConvexPolytope> cells;
        st.time(&FractureTimings::cellMs,
                [&] { cells = generateCells(place.mesh().bounds(), impact, params, s); });
        return cells;
    };
    auto finish = [&](const Status& s, int redraws) -> Result<FractureResult> {
        if (!s)
            return s.error();
        st.res.stats.redraws = redraws;
        st.sinceStart(&FractureTimings::totalMs);
        return std::move(st.res);
    };
    // The pattern is random: one the clipper declines as near-degenerate is redrawn (from derived seeds)
    // before the exact fallback cuts the seed's own pattern.
    constexpr int kRedraws = 2;
    if (params.backend == BooleanKind::Fast)
        for (int redraw = 0; redraw <= kRedraws; ++redraw) {
            std::vector<ConvexPolytope> cells = cellsFor(redraw == 0 ? seed : mixSeed(seed, 0xDA7A + redraw));
            if (cells.empty())
                break;
            const Status s = place.cut(st, std::move(cells), params,
                                       *detail::makeFastBackend(false, integrals), false, volume);
            if (s || s.error().code != ErrorCode::GeometryFailure)
                return finish(s, redraw);
        }
    std::vector<ConvexPolytope> cells = cellsFor(seed);
    if (cells.empty())
        return makeError(ErrorCode::NoIntersection, "fracture: no cell could be built around the impact");
    return finish(place.cut(st, std::move(cells), params, *backendFor(params.backend, true, integrals),
                            params.backend == BooleanKind::Fast, volume),
                  0);
}

} // namespace

namespace detail {

Result<FractureResult> fractureWithBackend(const Mesh& mesh, std::vector<ConvexPolytope> cells,
                                           const FractureParams& params, const BooleanBackend& backend,
                                           bool exactRedo, const MeshFacts& known) {
    const Place place(mesh, known, dynamic_cast<const EditingBackend*>(&backend) != nullptr);
    return cutWithCells(place, std::move(cells), params, backend, exactRedo);
}

Result<FractureResult> fractureInPlaceWithBackend(Mesh& mesh, MeshFacts& known,
                                                  std::vector<ConvexPolytope> cells,
                                                  const FractureParams& params, const BooleanBackend& backend,
                                                  bool exactRedo) {
    const Place place(mesh, known, dynamic_cast<const EditingBackend*>(&backend) != nullptr);
    return cutWithCells(place, std::move(cells), params, backend, exactRedo);
}

} // namespace detail

Result<MeshFacts> analyzeMesh(const Mesh& mesh) {
    if (Status s = checkSolid(mesh); !s)
        return s.error();
    MeshFacts facts{true, mesh.triangles.size(), mesh.positions.size(), volumeIntegrals(mesh)};
    if (Status s = positiveVolume(facts.integrals.volume); !s)
        return s.error();
    if (mesh.triangles.size() > kTopologyAboveTriangles)
        facts.topology = buildTopology(mesh).value_or(MeshTopology{});
    return facts;
}

namespace {

/// InvalidInput naming the field when request sets both or neither of mesh and consumed, or facts for the
/// one it does not set.
Status checkRequest(const FractureRequest& request) {
    const char* wrong = nullptr;
    if (request.mesh && request.consumed)
        wrong = "sets both mesh and consumed (set one)";
    else if (!request.mesh && !request.consumed)
        wrong = "sets neither mesh nor consumed (set one)";
    else if (request.known && !request.mesh)
        wrong = "sets known without mesh (the facts of consumed go in consumedFacts)";
    else if (request.consumedFacts && !request.consumed)
        wrong = "sets consumedFacts without consumed (the facts of mesh go in known)";
    if (wrong)
        return makeError(ErrorCode::InvalidInput, std::string("fracture: the request ") + wrong);
    return {};
}

/// The shorthands' request for a mesh lent.
FractureRequest lent(const Mesh& mesh, const MeshFacts& known, const FractureParams& params) {
    FractureRequest request;
    request.mesh = &mesh;
    request.known = &known;
    request.params = params;
    return request;
}

/// The shorthands' request for a mesh handed over with its facts.
FractureRequest handedOver(Mesh& mesh, MeshFacts& known, const FractureParams& params) {
    FractureRequest request;
    request.consumed = &mesh;
    request.consumedFacts = &known;
    request.params = params;
    return request;
}

/// request, cut at impact from seed.
FractureRequest atImpact(FractureRequest request, const Impact& impact, std::uint64_t seed) {
    request.impact = impact;
    request.seed = seed;
    return request;
}

/// request, cut by cells.
FractureRequest byCells(FractureRequest request, std::vector<ConvexPolytope> cells) {
    request.cells = std::move(cells);
    return request;
}

} // namespace

Result<FractureResult> fracture(FractureRequest request) {
    if (Status s = checkRequest(request); !s)
        return s.error();
    MeshFacts unknown;
    const bool editing = request.params.backend == BooleanKind::Fast;
    const Place place =
        request.mesh
            ? Place(*request.mesh, request.known ? *request.known : unknown, editing)
            : Place(*request.consumed, request.consumedFacts ? *request.consumedFacts : unknown, editing);
    if (request.cells)
        return cutWithCells(place, std::move(*request.cells), request.params);
    return cutAtImpact(place, request.impact, request.params, request.seed);
}

Result<FractureResult> fractureWithCells(const Mesh& mesh, std::vector<ConvexPolytope> cells,
                                         const FractureParams& params, const MeshFacts& known) {
    return fracture(byCells(lent(mesh, known, params), std::move(cells)));
}

Result<FractureResult> fractureWithCells(Mesh&& mesh, std::vector<ConvexPolytope> cells,
                                         const FractureParams& params, MeshFacts known) {
    return fracture(byCells(handedOver(mesh, known, params), std::move(cells)));
}

Result<FractureResult> fracture(const Mesh& mesh, const Impact& impact, const FractureParams& params,
                                std::uint64_t seed, const MeshFacts& known) {
    return fracture(atImpact(lent(mesh, known, params), impact, seed));
}

Result<FractureResult> fracture(Mesh&& mesh, const Impact& impact, const FractureParams& params,
                                std::uint64_t seed, MeshFacts known) {
    return fracture(atImpact(handedOver(mesh, known, params), impact, seed));
}

} // namespace rubble
