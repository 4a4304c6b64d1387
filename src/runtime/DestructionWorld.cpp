#include "rubble/runtime/DestructionWorld.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <fstream>
#include <limits>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <utility>

#include "geometry/ClosestPoint.hpp"
#include "geometry/MeshTopology.hpp"
#include "geometry/ShellScratch.hpp"
#include "rubble/collision/DecomposeControl.hpp"
#include "rubble/core/Log.hpp"
#include "rubble/core/ParameterCheck.hpp"
#include "rubble/core/Random.hpp"
#include "rubble/core/ThreadPool.hpp"
#include "rubble/fracture/FractureRequest.hpp"
#include "rubble/geometry/MassProperties.hpp"
#include "rubble/geometry/MeshCheck.hpp"
#include "rubble/geometry/MeshRepair.hpp"
#include "rubble/runtime/JobSeed.hpp"
#include "rubble/structure/Material.hpp"
#include "runtime/StateAccess.hpp"

namespace rubble {
namespace {

using Clock = std::chrono::steady_clock;

// The world keeps the facts of meshes above this size; a hit on a smaller one finds them again in the worker.
constexpr std::size_t kFactsKeptAboveTriangles = 1000;

double msBetween(Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double, std::milli>(b - a).count();
}

struct PendingImpact {
    Impact impact;
    std::uint64_t frame = 0;
    Clock::time_point time;
};

// Shared between the world and its jobs; outlives the world when a foreign JobSystem still holds jobs.
struct Sync {
    std::mutex mutex;
    std::condition_variable done;
    int outstanding = 0;
    bool cancelled = false;
};

struct Job {
    // inputs (immutable once submitted)
    ObjectId id = 0;
    std::uint32_t version = 0;
    std::vector<PendingImpact> impacts;
    std::vector<Impact> submitted;             // the impacts as submitted (runJob moves `impacts`)
    std::shared_ptr<const ObjectState> object; // its mesh and convex parts (object states never change)
    MeshFacts facts; // analyzeMesh(object->mesh) when the world knows it; else the worker finds it
    FractureParams params;
    bool crumble = false; // over its triangle limit: a shatter as large as the object
    DecompositionParams decomposition;
    std::uint64_t seed = 0;
    std::uint64_t frame = 0;      // frame of the first impact (timing records)
    std::uint64_t readyFrame = 0; // deterministic mode: adopted at this frame
    // outputs (written by the worker, read by the main thread after `finished` under Sync::mutex); the
    // stages' boundaries are shared time points, so that the stages follow one another without gaps
    bool finished = false;
    Clock::time_point started;     // a worker took it: queue → prepare
    Clock::time_point finishStart; // decomposition → finish
    Clock::time_point finishedAt;  // finish → handoff
    bool ok = false;
    ErrorCode errorCode = ErrorCode::Ok;
    std::string error;
    FractureResult result; // its pieces' meshes are moved into localMeshes
    std::vector<Frame> frames;
    std::vector<Mesh> localMeshes;
    std::vector<MassProperties> localMass;
    std::vector<MeshFacts> localFacts; // analyzeMesh(localMeshes[i]) (not validated again: fracture's output)
    std::vector<std::vector<ConvexPolytope>> localParts;
    std::vector<std::uint64_t> meshHashes; // localMeshes[i].hash() by the worker, or 0: when it is read
    std::uint64_t touched = 0;             // triangles the job's own passes read (TimingRecord)
    double queueMs = 0;
    double prepareMs = 0;
    double cellMs = 0;
    double decompositionMs = 0;
    double finishMs = 0;
};

// The impact moved to the nearest surface point of the mesh; an impact farther than the object's own size is
// left alone (docs/architecture.md, "Impacts off the surface").
Impact onSurface(const Mesh& mesh, Impact impact, const FractureParams& params) {
    double best = std::numeric_limits<double>::infinity();
    Vec3 closest = impact.point;
    for (const auto& t : mesh.triangles) {
        const Vec3 q = detail::closestOnTriangle(impact.point, mesh.positions[t[0]], mesh.positions[t[1]],
                                                 mesh.positions[t[2]]);
        const double d = lengthSquared(q - impact.point);
        if (d < best) {
            best = d;
            closest = q;
        }
    }
    const Aabb bounds = mesh.bounds();
    const double reach = std::max(impactCut(params, bounds, impact.impulse).size, bounds.diagonal());
    if (best <= reach * reach)
        impact.point = closest;
    return impact;
}

// The volume integrals of a solid with these mass properties, about its centre of mass (the covariance C
// from inertia = trace(C)·I − C).
VolumeIntegrals integralsOf(const MassProperties& m) {
    VolumeIntegrals v;
    v.reference = m.centerOfMass;
    v.volume = m.volume;
    const double half = 0.5 * (m.inertia.m[0][0] + m.inertia.m[1][1] + m.inertia.m[2][2]);
    for (int i = 0; i < 3; ++i)
        for (int j = i; j < 3; ++j)
            v.cov[i][j] = (i == j ? half : 0.0) - m.inertia.m[i][j];
    return v;
}

// v with 1/16 spare capacity: the growth an in-place edit asks for, so that it does not copy the arrays
// again.
template <class T>
std::vector<T> withRoom(const std::vector<T>& v) {
    std::vector<T> out;
    out.reserve(v.size() + v.size() / 16);
    out.assign(v.begin(), v.end());
    return out;
}

// The job's own copy of an object's mesh and facts for a fracture that edits it in place (the object's stays
// as it is, shared with the engine, until the result is adopted).
std::pair<Mesh, MeshFacts> editableCopy(const Mesh& m, const MeshFacts& f) {
    Mesh c;
    c.positions = withRoom(m.positions);
    c.triangles = withRoom(m.triangles);
    c.normals = withRoom(m.normals);
    c.uvs = withRoom(m.uvs);
    c.materials = withRoom(m.materials);
    c.materialNames = m.materialNames;
    MeshFacts cf{f.known, f.triangles, f.vertices, f.integrals};
    if (const MeshTopology* t = f.topology.get())
        cf.topology = MeshTopology{withRoom(t->twin)};
    return {std::move(c), std::move(cf)};
}

// A remainder above kTopologyAboveTriangles that the kernel edited in place (its facts fit, with a topology):
// it keeps its parent's frame, the kernel's facts and mass properties.
bool keepsParentFrame(const Piece& piece, const Mesh& mesh) {
    return piece.cell < 0 && mesh.triangles.size() > kTopologyAboveTriangles && piece.facts.fit(mesh) &&
           piece.facts.topology.fits(mesh);
}

// Frees the spare capacity of a piece's arrays (the kernel grows them as it cuts).
void shrinkToFit(Mesh& mesh) {
    mesh.positions.shrink_to_fit();
    mesh.triangles.shrink_to_fit();
    mesh.normals.shrink_to_fit();
    mesh.uvs.shrink_to_fit();
    mesh.materials.shrink_to_fit();
    mesh.materialNames.shrink_to_fit();
}

void runJob(Job& job) {
    const Mesh& mesh = job.object->mesh;
    for (PendingImpact& p : job.impacts)
        p.impact = onSurface(mesh, p.impact, job.params);
    // Every fracture runs with the facts analyzeMesh finds (a function of the mesh alone), whether the world
    // kept them or not (a loaded world does not), so that both cut the same bits (docs/megamesh.md).
    if (!job.facts.fit(mesh)) {
        auto facts = analyzeMesh(mesh);
        if (!facts) {
            job.errorCode = facts.error().code;
            job.error = facts.error().message;
            return;
        }
        job.facts = facts.value();
    }
    // Above the threshold a remainder's mass properties come by difference, not from its mesh: its facts'
    // integrals are those of the saved mass properties, so that a loaded world cuts with the same ones.
    if (mesh.triangles.size() > kTopologyAboveTriangles)
        job.facts.integrals = integralsOf(job.object->mass);
    // With a topology the fracture edits a copy in place: made here with room to grow, not by fracture (the
    // copy is part of prepare).
    const bool edits = job.facts.topology.fits(mesh);
    std::pair<Mesh, MeshFacts> editable;
    if (edits)
        editable = editableCopy(mesh, job.facts);
    job.prepareMs = msBetween(job.started, Clock::now());
    FractureRequest request;
    request.params = job.params;
    if (edits) {
        request.consumed = &editable.first;
        request.consumedFacts = &editable.second;
    } else {
        request.mesh = &mesh;
        request.known = &job.facts;
    }
    if (job.impacts.size() == 1) {
        request.impact = job.impacts.front().impact;
        request.seed = mixSeed(job.seed, 0);
    } else {
        // Union of the cells of every merged impact; a cell overlapping an accepted one is skipped so that
        // the cells stay disjoint (the overlapping region is already cut by the earlier impact's cells).
        const auto tc = Clock::now();
        std::vector<ConvexPolytope> cells;
        const Aabb bounds = mesh.bounds();
        for (std::size_t i = 0; i < job.impacts.size(); ++i) {
            const std::size_t earlier = cells.size(); // only cells of earlier impacts are compared
            for (auto& c : generateCells(bounds, job.impacts[i].impact, job.params, mixSeed(job.seed, i))) {
                const Aabb cb = c.bounds();
                bool overlaps = false;
                for (std::size_t a = 0; a < earlier; ++a)
                    overlaps = overlaps || cells[a].bounds().overlaps(cb);
                if (!overlaps)
                    cells.push_back(std::move(c));
            }
        }
        job.cellMs = msBetween(tc, Clock::now());
        request.cells = std::move(cells);
    }
    Result<FractureResult> r = fracture(std::move(request));
    if (!r) {
        job.errorCode = r.error().code;
        job.error = r.error().message;
        return;
    }
    job.result = std::move(r).value();
    job.prepareMs += job.result.stats.timings.validateMs;
    job.cellMs += job.result.stats.timings.cellMs;
    const auto t1 = Clock::now();
    std::vector<Mesh> meshes;
    std::vector<std::int32_t> pieceCells;
    for (auto& p : job.result.pieces) {
        meshes.push_back(std::move(p.mesh));
        pieceCells.push_back(p.cell);
    }
    auto parts =
        updateDecomposition(job.object->convexParts, job.result.cells, meshes, pieceCells, job.decomposition);
    job.finishStart = Clock::now();
    job.decompositionMs = msBetween(t1, job.finishStart);
    // A large remainder edited in place keeps its parent's frame and the kernel's facts (mass properties by
    // difference): no pass over its triangles here, and its hash waits until it is read
    // (docs/runtime-locality.md). Every other piece goes into its principal frame, with the mass properties
    // of that mesh (computed here, not by the main thread at adoption); a small remainder's frame comes from
    // a full sum, so that facts change no piece's bytes.
    for (std::size_t i = 0; i < meshes.size(); ++i) {
        Piece& piece = job.result.pieces[i];
        if (keepsParentFrame(piece, meshes[i])) {
            job.localMass.push_back(piece.mass);
            job.localFacts.push_back(std::move(piece.facts));
            job.meshHashes.push_back(0);
            job.localParts.push_back(i < parts.size() ? std::move(parts[i]) : std::vector<ConvexPolytope>{});
            job.frames.push_back(Frame{});
            continue;
        }
        shrinkToFit(meshes[i]);
        const MassProperties m = piece.cell < 0 ? computeMassProperties(meshes[i]) : piece.mass;
        Frame f{m.principalAxes, m.centerOfMass};
        const Mat3 rt = f.rotation.transposed();
        meshes[i].transform(rt, Vec3{1, 1, 1}, rt * (-1.0 * f.translation));
        MeshFacts facts{true, meshes[i].triangles.size(), meshes[i].positions.size(),
                        volumeIntegrals(meshes[i]), std::move(piece.facts.topology)};
        // The topology analyzeMesh finds (so that a loaded world, which finds it again, cuts the same bits).
        if (meshes[i].triangles.size() <= kTopologyAboveTriangles)
            facts.topology = HeldTopology{};
        else if (!facts.topology.fits(meshes[i]))
            facts.topology = buildTopology(meshes[i]).value_or(MeshTopology{});
        job.localMass.push_back(massProperties(facts.integrals));
        job.localFacts.push_back(std::move(facts));
        job.meshHashes.push_back(meshes[i].hash());
        // mass, transform, integrals and hash: four passes over the piece
        job.touched += 4 * meshes[i].triangles.size();
        std::vector<ConvexPolytope> lp;
        if (i < parts.size())
            for (const auto& p : parts[i])
                lp.push_back(p.transformed(f.inverse()));
        job.localParts.push_back(std::move(lp));
        job.frames.push_back(f);
    }
    job.localMeshes = std::move(meshes);
    job.ok = true; // finishMs ends when the worker marks the job finished
}

} // namespace

double FractureOutcome::dustVolume() const {
    double v = 0;
    for (const DustPiece& d : dust)
        v += d.volume;
    return v;
}

double FractureOutcome::impulse() const {
    double sum = 0;
    for (const Impact& i : impacts)
        sum += i.impulse;
    return sum;
}

struct DestructionWorld::Impl {
    Config config;
    Status configStatus; // checkConfig(config), decided once at construction
    std::unique_ptr<ThreadPool> ownedPool;
    JobSystem* jobs = nullptr;
    std::shared_ptr<Sync> sync = std::make_shared<Sync>();
    // Object states never change once made (a fracture replaces the object by new ones), so jobs share them.
    std::map<ObjectId, std::shared_ptr<const ObjectState>> objects;
    ObjectId nextId = 1;
    std::uint64_t frame = 0;
    DecompositionCache cache;
    std::map<ObjectId, std::vector<PendingImpact>> waiting; // impacts waiting for an in-flight job
    std::vector<std::shared_ptr<Job>> inflight;             // in submission order
    std::vector<TimingRecord> timings;
    std::uint64_t recordsErased = 0; // records dropped from the front of `timings` (sequence numbers stay)
    // A split handed out by collect() and not committed yet: its parent stays until commit() replaces it.
    struct OpenSplit {
        std::uint32_t version = 0;        // the parent's version
        std::vector<AdoptedPiece> pieces; // as handed out (their states become the objects)
        std::vector<MeshFacts> facts;     // analyzeMesh of each piece's mesh
        std::uint64_t record = 0;         // sequence number of its TimingRecord
        Clock::time_point recordEnd;      // where that record's adoption ends so far
    };
    std::map<ObjectId, OpenSplit> open; // by parent
    std::function<void(const JournalEvent&)> journalSink;
    std::uint64_t journalLength = 0;
    std::uint64_t geometrySum = 0; // Σ geometryTerm over live objects with a mesh hash (wrapping)
    std::set<ObjectId> unhashed;   // live objects whose meshHash is not computed yet (0)
    // analyzeMesh of live objects' meshes where known (not saved: a function of the mesh, found again), above
    // kFactsKeptAboveTriangles: a small piece's are found again by the worker that fractures it
    std::map<ObjectId, MeshFacts> facts;
    void keepFacts(ObjectId id, MeshFacts f) {
        if (f.triangles > kFactsKeptAboveTriangles)
            facts[id] = std::move(f);
    }

    static std::uint64_t geometryTerm(const ObjectState& o) {
        return mixSeed(mixSeed(o.id, o.version), o.meshHash);
    }
    void insertObject(std::shared_ptr<const ObjectState> s) {
        const ObjectId id = s->id;
        if (s->meshHash == 0)
            unhashed.insert(id);
        else
            geometrySum += geometryTerm(*s);
        objects.emplace(id, std::move(s));
    }
    void eraseObject(std::map<ObjectId, std::shared_ptr<const ObjectState>>::iterator it) {
        if (unhashed.erase(it->first) == 0)
            geometrySum -= geometryTerm(*it->second);
        facts.erase(it->first);
        objects.erase(it);
    }
    // Computes the mesh hashes not computed yet (a large remainder's waits until something reads it). Object
    // states are made non-const (make_shared<ObjectState>) and no job reads meshHash, so it is written here.
    void hashPending() {
        for (ObjectId id : unhashed) {
            auto& o = const_cast<ObjectState&>(*objects.at(id));
            o.meshHash = o.mesh.hash();
            geometrySum += geometryTerm(o);
        }
        unhashed.clear();
    }
    std::uint64_t jobSeed(const ObjectState& o) const {
        return rubble::jobSeed(config.seed, o.id, o.version);
    }
    void journal(const JournalEvent& e) {
        ++journalLength;
        if (journalSink)
            journalSink(e);
    }

    // Impacts that can no longer run (their object is gone) still leave a stale timing record, so that every
    // accepted impact is accounted for in exactly one record.
    void recordDropped(ObjectId id, const std::vector<PendingImpact>& impacts) {
        if (impacts.empty())
            return;
        TimingRecord rec;
        rec.object = id;
        rec.frame = impacts.front().frame;
        rec.impactsMerged = static_cast<int>(impacts.size());
        rec.stale = true;
        rec.totalMs = msBetween(impacts.front().time, Clock::now());
        record(rec);
    }

    // Appends a record; returns its sequence number.
    std::uint64_t record(const TimingRecord& rec) {
        const std::uint64_t seq = recordsErased + timings.size();
        timings.push_back(rec);
        const std::size_t keep = config.keepTimings;
        if (keep > 0 && timings.size() > 2 * keep) { // amortised: drop the oldest half at once
            const std::size_t drop = timings.size() - keep;
            timings.erase(timings.begin(), timings.begin() + static_cast<std::ptrdiff_t>(drop));
            recordsErased += drop;
        }
        return seq;
    }

    // A job in flight or a split not committed: impacts on it wait.
    bool busy(ObjectId id) const {
        return open.count(id) > 0 ||
               std::any_of(inflight.begin(), inflight.end(), [&](const auto& j) { return j->id == id; });
    }

    // The timing record with this sequence number, or null when it was dropped already.
    TimingRecord* recordAt(std::uint64_t seq) {
        return seq < recordsErased ? nullptr : &timings[static_cast<std::size_t>(seq - recordsErased)];
    }

    std::shared_ptr<Job> launch(ObjectId id, std::vector<PendingImpact> impacts) {
        const std::shared_ptr<const ObjectState>& object = objects.at(id);
        const ObjectState& o = *object;
        auto job = std::make_shared<Job>();
        job->id = id;
        job->version = o.version;
        job->impacts = std::move(impacts);
        for (const PendingImpact& p : job->impacts)
            job->submitted.push_back(p.impact);
        job->object = object;
        if (auto f = facts.find(id); f != facts.end())
            job->facts = f->second;
        job->params = o.fracture;
        if (o.mesh.triangleCount() > o.crumbleAbove) { // too much detail: break it up instead of a crater
            job->crumble = true;
            job->params.pattern = CellPattern::Shatter;
            job->params.cells = std::max(2, config.crumbleCells);
            // The shatter cuts the cells of the K sites nearest the impact among about 2K in a domain of this
            // size (sites crowd the impact): four diagonals make those cells reach across the whole object.
            job->params.sizeLaw.minSize = job->params.sizeLaw.maxSize = 4 * o.mesh.bounds().diagonal();
        }
        job->decomposition = config.decomposition;
        job->seed = jobSeed(o);
        job->frame = job->impacts.front().frame;
        // Adopted delayFrames after the launch (not after the first impact: impacts forwarded to pieces or
        // re-run after a failed job would otherwise be due at once and block the main thread).
        job->readyFrame = frame + static_cast<std::uint64_t>(std::max(0, config.delayFrames));
        inflight.push_back(job);
        {
            std::lock_guard lock(sync->mutex);
            ++sync->outstanding;
        }
        auto s = sync;
        jobs->submit([s, job] {
            {
                std::lock_guard lock(s->mutex);
                if (s->cancelled) {
                    --s->outstanding;
                    job->finished = true;
                    s->done.notify_all();
                    return;
                }
            }
            job->started = Clock::now();
            job->queueMs = msBetween(job->impacts.front().time, job->started);
            runJob(*job);
            std::lock_guard lock(s->mutex);
            job->finishedAt = Clock::now();
            if (job->ok)
                job->finishMs = msBetween(job->finishStart, job->finishedAt);
            job->finished = true;
            --s->outstanding;
            s->done.notify_all();
        });
        return job;
    }

    // The split event of a finished job on a current parent, opened until commit(): the pieces get their ids
    // and states; pieces below the minimum volume become dust.
    FractureOutcome split(Job& job, const ObjectState& parent) {
        FractureOutcome o;
        OpenSplit s;
        s.version = job.version;
        o.parent = job.id;
        o.parentVersion = job.version;
        for (const auto& p : job.impacts)
            o.impacts.push_back(p.impact);
        o.droppedVolume = job.result.droppedVolume;
        for (std::size_t i = 0; i < job.localMeshes.size(); ++i) {
            const std::int32_t cell = job.result.pieces[i].cell;
            if (std::abs(job.localMass[i].volume) < config.minPieceVolume) {
                o.dust.push_back({job.frames[i].translation, std::abs(job.localMass[i].volume), cell});
                continue;
            }
            auto st = std::make_shared<ObjectState>();
            st->id = nextId++;
            st->version = 0;
            st->mesh = std::move(job.localMeshes[i]);
            st->mass = job.localMass[i];
            st->density = parent.density;
            st->destructible = parent.destructible;
            st->impulseThreshold = parent.impulseThreshold;
            st->fracture = parent.fracture;
            st->crumbleAbove = parent.crumbleAbove;
            st->convexParts = std::move(job.localParts[i]);
            st->meshHash = job.meshHashes[i];
            o.pieces.push_back({st->id, job.frames[i], cell, std::move(st)});
            s.facts.push_back(std::move(job.localFacts[i]));
        }
        s.pieces = o.pieces;
        open[job.id] = std::move(s);
        return o;
    }

    bool isFinished(const Job& j) {
        std::lock_guard lock(sync->mutex);
        return j.finished;
    }
    void waitFor(const Job& j) {
        std::unique_lock lock(sync->mutex);
        sync->done.wait(lock, [&] { return j.finished; });
    }
};

DestructionWorld::DestructionWorld(Config config) : impl_(std::make_unique<Impl>()) {
    impl_->config = config;
    impl_->configStatus = checkConfig(config);
    if (config.jobs) {
        impl_->jobs = config.jobs;
    } else {
        impl_->ownedPool = std::make_unique<ThreadPool>(config.workers);
        impl_->jobs = impl_->ownedPool.get();
    }
}

DestructionWorld::~DestructionWorld() {
    {
        std::lock_guard lock(impl_->sync->mutex);
        impl_->sync->cancelled = true; // queued jobs return at once; results of running ones are discarded
    }
    impl_->ownedPool.reset(); // finishes running jobs, drops queued ones (they only hold shared state)
}

namespace {
// The shatter layout of a material's fracture pattern.
ShatterLayout shatterLayout(FracturePattern p) {
    switch (p) {
    case FracturePattern::Radial:
        return ShatterLayout::Radial;
    case FracturePattern::Splinter:
        return ShatterLayout::Splinter;
    case FracturePattern::Uniform:
        return ShatterLayout::Uniform;
    case FracturePattern::Clustered:
        break;
    }
    return ShatterLayout::Clustered;
}
} // namespace

Status DestructionWorld::checkConfig(const Config& c) {
    auto bad = [](const std::string& what) {
        return Status{Error{ErrorCode::InvalidInput, "world config: " + what}};
    };
    if (const Status s = checkDecompositionParams(c.decomposition); !s)
        return bad("decomposition: " + s.message());
    if (c.delayFrames < 0 || c.crumbleCells < 0 || c.workers < -1)
        return bad("delayFrames " + std::to_string(c.delayFrames) + ", crumbleCells " +
                   std::to_string(c.crumbleCells) + " and workers " + std::to_string(c.workers) +
                   " must not be negative (workers -1: automatic)");
    if (!(c.minPieceVolume >= 0 && c.minPieceVolume < 1e300) ||
        !(c.adoptionBudgetMs >= 0 && c.adoptionBudgetMs < 1e300))
        return bad("minPieceVolume " + std::to_string(c.minPieceVolume) + " and adoptionBudgetMs " +
                   std::to_string(c.adoptionBudgetMs) + " must be finite numbers >= 0");
    return {};
}

Result<ObjectId> DestructionWorld::addObject(ObjectDesc desc) {
    if (!impl_->configStatus)
        return Error{ErrorCode::InvalidInput, "addObject: " + impl_->configStatus.message()};
    if (desc.mesh.triangles.empty() || desc.mesh.positions.empty())
        return Error{ErrorCode::InvalidInput, "addObject: empty mesh"};
    for (Status st : {checkParam("density", desc.density), checkParam("cells", desc.fracture.cells)})
        if (!st)
            return Error{ErrorCode::InvalidInput, "addObject: " + st.message()};
    auto state = std::make_shared<ObjectState>();
    ObjectState& s = *state;
    s.id = impl_->nextId++;
    s.density = desc.density;
    s.destructible = desc.destructible;
    s.impulseThreshold = desc.impulseThreshold;
    s.fracture = desc.fracture;
    if (const Material* m = desc.material.empty() ? nullptr : findMaterial(desc.material))
        s.fracture.layout = shatterLayout(m->pattern);
    s.crumbleAbove = impl_->config.crumbleTriangles == 0
                         ? std::numeric_limits<std::size_t>::max()
                         : std::max(impl_->config.crumbleTriangles, 2 * desc.mesh.triangleCount());
    CheckOptions opts;
    MeshReport report = checkMesh(desc.mesh, opts);
    if (!report.valid()) {
        Mesh repaired = desc.mesh;
        repairMesh(repaired);
        MeshReport again = checkMesh(repaired, opts);
        if (again.valid()) {
            s.warning = "mesh was repaired: " +
                        (report.problems.empty() ? std::string("invalid") : report.problems.front());
            logMessage(LogLevel::Warning, "object " + std::to_string(s.id) + ": " + s.warning);
            desc.mesh = std::move(repaired);
            report = std::move(again);
        }
    }
    if (!report.valid()) {
        s.destructible = false;
        s.warning = "mesh is not a valid closed solid";
        if (!report.problems.empty())
            s.warning += ": " + report.problems.front();
        logMessage(LogLevel::Warning, "object " + std::to_string(s.id) + " is indestructible: " + s.warning);
    }
    Result<MeshFacts> facts = Error{ErrorCode::InvalidInput, "not destructible"};
    if (s.destructible && report.valid())
        facts = analyzeMesh(desc.mesh);
    s.mass = facts ? massProperties(facts.value().integrals) : computeMassProperties(desc.mesh);
    s.convexParts = std::move(desc.convexParts);
    if (s.convexParts.empty() && report.valid()) {
        DecomposeControl control; // on the world's workers beside the calling thread
        control.jobs = impl_->jobs;
        auto d = impl_->cache.get(desc.mesh, impl_->config.decomposition, control);
        if (d)
            s.convexParts = d.value().parts;
    }
    s.mesh = std::move(desc.mesh);
    s.meshHash = s.mesh.hash();
    // the calling (main) thread checks meshes only when they are added: it keeps no large work arrays
    detail::trimShellScratch(std::size_t{1} << 20);
    const ObjectId id = s.id;
    impl_->insertObject(std::move(state));
    if (facts)
        impl_->keepFacts(id, std::move(facts).value());
    return id;
}

void DestructionWorld::removeObject(ObjectId id) {
    if (auto o = impl_->open.find(id); o != impl_->open.end()) { // its split is never committed
        if (TimingRecord* r = impl_->recordAt(o->second.record))
            r->stale = true;
        impl_->open.erase(o);
    }
    if (auto it = impl_->objects.find(id); it != impl_->objects.end()) {
        JournalEvent e;
        e.kind = JournalEventKind::Remove;
        e.object = id;
        e.tick = static_cast<std::uint32_t>(impl_->frame);
        impl_->eraseObject(it);
        impl_->journal(e);
    }
    if (auto w = impl_->waiting.find(id); w != impl_->waiting.end()) {
        impl_->recordDropped(id, w->second);
        impl_->waiting.erase(w);
    }
}

const ObjectState* DestructionWorld::object(ObjectId id) const {
    auto it = impl_->objects.find(id);
    return it == impl_->objects.end() ? nullptr : it->second.get();
}

std::vector<ObjectId> DestructionWorld::objects() const {
    std::vector<ObjectId> ids;
    for (const auto& [id, o] : impl_->objects)
        ids.push_back(id);
    return ids;
}

bool DestructionWorld::accepts(ObjectId id, const Impact& impact) const {
    auto it = impl_->objects.find(id);
    if (it == impl_->objects.end() || !it->second->destructible)
        return false;
    const Impact rounded = journalPrecision(impact);
    return rounded.impulse >= it->second->impulseThreshold &&
           checkFractureParams(rounded, it->second->fracture);
}

bool DestructionWorld::submitImpact(ObjectId id, const Impact& impact) {
    if (!accepts(id, impact))
        return false;
    const Impact rounded = journalPrecision(impact);
    const ObjectState& o = *impl_->objects.at(id);
    JournalEvent e;
    e.kind = JournalEventKind::Impact;
    e.object = id;
    e.tick = static_cast<std::uint32_t>(impl_->frame);
    e.point = {static_cast<float>(rounded.point.x), static_cast<float>(rounded.point.y),
               static_cast<float>(rounded.point.z)};
    e.normal = {static_cast<float>(rounded.normal.x), static_cast<float>(rounded.normal.y),
                static_cast<float>(rounded.normal.z)};
    e.impulse = static_cast<float>(rounded.impulse);
    e.pattern = patternByte(o.fracture);
    e.cells = static_cast<std::uint16_t>(std::clamp(o.fracture.cells, 0, 65535));
    e.seed = impl_->jobSeed(o);
    impl_->journal(e);
    PendingImpact p{rounded, impl_->frame, Clock::now()};
    if (impl_->busy(id)) {
        impl_->waiting[id].push_back(p);
    } else {
        impl_->launch(id, {p});
    }
    return true;
}

void DestructionWorld::setJournalSink(std::function<void(const JournalEvent&)> sink) {
    impl_->journalSink = std::move(sink);
}

std::uint64_t DestructionWorld::journalPosition() const {
    return impl_->journalLength;
}

Status DestructionWorld::applyJournalEvent(const JournalEvent& e) {
    const std::string where =
        "journal event at tick " + std::to_string(e.tick) + ", object " + std::to_string(e.object) + ": ";
    auto it = impl_->objects.find(e.object);
    if (it == impl_->objects.end())
        return Error{ErrorCode::InvalidInput, where + "no such object"};
    if (e.kind == JournalEventKind::Remove) {
        removeObject(e.object);
        return Status::ok();
    }
    if (e.kind != JournalEventKind::Impact)
        return Error{ErrorCode::InvalidInput, where + "unknown kind " + std::to_string(int(e.kind))};
    const ObjectState& o = *it->second;
    if (e.pattern != patternByte(o.fracture) ||
        e.cells != static_cast<std::uint16_t>(std::clamp(o.fracture.cells, 0, 65535)))
        return Error{ErrorCode::InvalidInput,
                     where + "pattern differs from the object's fracture parameters"};
    if (e.seed != impl_->jobSeed(o))
        return Error{ErrorCode::InvalidInput, where + "seed differs (another scene or world seed)"};
    if (!submitImpact(e.object, e.impact()))
        return Error{ErrorCode::InvalidInput, where + "the object refuses the impact"};
    return Status::ok();
}

namespace detail {

DestructionWorld::Config& StateAccess::config(DestructionWorld& world) {
    return world.impl_->config;
}

const DestructionWorld::Config& StateAccess::config(const DestructionWorld& world) {
    return world.impl_->config;
}

ObjectId StateAccess::nextId(const DestructionWorld& world) {
    return world.impl_->nextId;
}

std::vector<ObjectState> StateAccess::objects(const DestructionWorld& world) {
    DestructionWorld::Impl& im = *world.impl_;
    im.hashPending();
    std::vector<ObjectState> out;
    for (const auto& [id, o] : im.objects)
        out.push_back(*o);
    return out;
}

std::vector<WorldWork> StateAccess::work(const DestructionWorld& world) {
    const DestructionWorld::Impl& im = *world.impl_;
    std::vector<WorldWork> out;
    for (const auto& job : im.inflight) {
        WorldWork w{job->id, job->version, true, job->readyFrame, {}};
        for (std::size_t i = 0; i < job->impacts.size(); ++i)
            w.impacts.push_back({job->submitted[i], job->impacts[i].frame});
        out.push_back(std::move(w));
    }
    for (const auto& [id, impacts] : im.waiting) {
        auto o = im.objects.find(id);
        WorldWork w{id, o == im.objects.end() ? 0u : o->second->version, false, 0, {}};
        for (const PendingImpact& q : impacts)
            w.impacts.push_back({q.impact, q.frame});
        out.push_back(std::move(w));
    }
    return out;
}

void StateAccess::replace(DestructionWorld& world, std::vector<ObjectState> objects, std::uint64_t frame,
                          ObjectId nextId, std::uint64_t journalPosition) {
    DestructionWorld::Impl& im = *world.impl_;
    im.inflight.clear();
    im.waiting.clear();
    im.open.clear();
    im.objects.clear();
    im.facts.clear();
    im.geometrySum = 0;
    im.unhashed.clear();
    for (ObjectState& o : objects) {
        if (o.meshHash == 0) // a saved state brings its hashes: hashing every mesh again is most of a load
            o.meshHash = o.mesh.hash();
        im.insertObject(std::make_shared<const ObjectState>(std::move(o)));
    }
    im.frame = frame;
    im.nextId = nextId;
    im.journalLength = journalPosition;
}

void StateAccess::resume(DestructionWorld& world, const WorldWork& work) {
    DestructionWorld::Impl& im = *world.impl_;
    const auto now = Clock::now();
    std::vector<PendingImpact> impacts;
    for (const TickedImpact& t : work.impacts)
        impacts.push_back({t.impact, t.tick, now});
    if (work.inFlight)
        im.launch(work.object, std::move(impacts))->readyFrame = work.readyFrame;
    else
        im.waiting[work.object] = std::move(impacts);
}

} // namespace detail

std::uint64_t DestructionWorld::geometryHash() const {
    impl_->hashPending();
    return mixSeed(impl_->geometrySum, impl_->objects.size());
}

void DestructionWorld::beginFrame() {
    ++impl_->frame;
}

std::uint64_t DestructionWorld::frame() const {
    return impl_->frame;
}

std::vector<FractureOutcome> DestructionWorld::collect() {
    std::vector<FractureOutcome> out;
    const auto start = Clock::now();
    Impl& im = *impl_;
    for (std::size_t k = 0; k < im.inflight.size();) {
        auto job = im.inflight[k];
        if (im.config.deterministic) {
            if (job->readyFrame > im.frame) {
                ++k;
                continue;
            }
            im.waitFor(*job);
        } else {
            if (!im.isFinished(*job)) {
                ++k;
                continue;
            }
            if (!out.empty() && msBetween(start, Clock::now()) > im.config.adoptionBudgetMs)
                break;
        }
        im.inflight.erase(im.inflight.begin() + static_cast<std::ptrdiff_t>(k));
        const auto a0 = Clock::now();
        TimingRecord rec;
        rec.object = job->id;
        rec.frame = job->frame;
        rec.impactsMerged = static_cast<int>(job->impacts.size());
        rec.queueMs = job->queueMs;
        rec.prepareMs = job->prepareMs;
        rec.cellMs = job->cellMs;
        rec.booleanMs = job->result.stats.timings.booleanMs;
        rec.islandsMs = job->result.stats.timings.islandsMs;
        rec.decompositionMs = job->decompositionMs;
        rec.finishMs = job->finishMs;
        rec.handoffMs = msBetween(job->finishedAt, a0);
        rec.crumbled = job->crumble;
        rec.touchedTriangles = job->touched;
        auto it = im.objects.find(job->id);
        const bool current = it != im.objects.end() && it->second->version == job->version;
        if (current && job->ok) {
            out.push_back(im.split(*job, *it->second));
            Impl::OpenSplit& s = im.open.at(job->id);
            rec.pieces = static_cast<int>(s.pieces.size());
            s.recordEnd = Clock::now();
            rec.adoptionMs = msBetween(a0, s.recordEnd);
            rec.totalMs = msBetween(job->impacts.front().time, s.recordEnd);
            s.record = im.record(rec);
            continue;
        }
        if (!current) {
            rec.stale = true; // the object was removed or replaced meanwhile: the result is discarded
        } else if (job->errorCode == ErrorCode::NoIntersection) {
            if (job->facts.fit(it->second->mesh)) // what the worker found, for the next hit
                im.keepFacts(job->id, job->facts);
            rec.missed = true; // nothing of the mesh inside the cells: a miss, not a failure
        } else {
            rec.failed = true;
        }
        // A missed, failed or stale job: impacts that waited on it run now on the (unchanged) object if it
        // still exists.
        std::vector<PendingImpact> later;
        if (auto w = im.waiting.find(job->id); w != im.waiting.end()) {
            later = std::move(w->second);
            im.waiting.erase(w);
        }
        const bool relaunch = !later.empty() && im.objects.count(job->id) > 0;
        if (relaunch)
            im.launch(job->id, std::move(later));
        const auto a1 = Clock::now();
        rec.adoptionMs = msBetween(a0, a1);
        rec.totalMs = msBetween(job->impacts.front().time, a1);
        im.record(rec);
        if (!relaunch)
            im.recordDropped(job->id, later);
    }
    return out;
}

void DestructionWorld::commit(const FractureOutcome& split) {
    Impl& im = *impl_;
    auto o = im.open.find(split.parent);
    if (o == im.open.end() || o->second.version != split.parentVersion) // committed, or its parent removed
        return;
    Impl::OpenSplit s = std::move(o->second);
    im.open.erase(o);
    im.eraseObject(im.objects.find(split.parent));
    for (std::size_t i = 0; i < s.pieces.size(); ++i) {
        im.keepFacts(s.pieces[i].id, std::move(s.facts[i]));
        im.insertObject(s.pieces[i].state);
    }
    std::vector<PendingImpact> later;
    if (auto w = im.waiting.find(split.parent); w != im.waiting.end()) {
        later = std::move(w->second);
        im.waiting.erase(w);
    }
    // Impacts that arrived while the job ran go to the piece nearest to their point.
    if (s.pieces.empty())
        im.recordDropped(split.parent, later);
    for (auto& p : s.pieces.empty() ? std::vector<PendingImpact>{} : later) {
        // the piece whose bounds are nearest to the point (containing it: distance 0); among equally near
        // pieces the largest, so that a waiting impact rarely lands on a sliver
        double best = 1e300, bestVolume = 0;
        const AdoptedPiece* target = &s.pieces.front();
        for (const AdoptedPiece& piece : s.pieces) {
            const Aabb b = piece.state->mesh.bounds();
            const Vec3 q = piece.frame.applyInverse(p.impact.point);
            const Vec3 outside = max(b.lo - q, max(q - b.hi, Vec3{}));
            const double d = length(outside);
            if (d < best - 1e-9 || (d <= best + 1e-9 && piece.state->mass.volume > bestVolume)) {
                best = std::min(best, d);
                bestVolume = piece.state->mass.volume;
                target = &piece;
            }
        }
        PendingImpact q = p;
        q.impact.point = target->frame.applyInverse(p.impact.point);
        q.impact.normal = target->frame.rotation.transposed() * p.impact.normal;
        if (im.busy(target->id))
            im.waiting[target->id].push_back(q);
        else
            im.launch(target->id, {q});
    }
    if (TimingRecord* r = im.recordAt(s.record)) { // the adoption ends now that the engine's bodies exist
        const double engineMs = msBetween(s.recordEnd, Clock::now());
        r->adoptionMs += engineMs;
        r->totalMs += engineMs;
    }
}

bool DestructionWorld::waitForResult(Clock::time_point deadline) const {
    Impl& im = *impl_;
    if (im.config.deterministic || im.inflight.empty())
        return false;
    // Only the main thread launches or removes jobs, so `inflight` is stable while this waits; `finished` is
    // written by the workers under the mutex and read here under it.
    std::unique_lock lock(im.sync->mutex);
    return im.sync->done.wait_until(lock, deadline, [&] {
        return std::any_of(im.inflight.begin(), im.inflight.end(), [](const auto& j) { return j->finished; });
    });
}

void DestructionWorld::waitIdle() const {
    std::unique_lock lock(impl_->sync->mutex);
    impl_->sync->done.wait(lock, [&] { return impl_->sync->outstanding == 0; });
}

int DestructionWorld::jobsInFlight() const {
    return static_cast<int>(impl_->inflight.size());
}

const std::vector<TimingRecord>& DestructionWorld::timings() const {
    return impl_->timings;
}

std::uint64_t DestructionWorld::firstTimingRecord() const {
    return impl_->recordsErased;
}

Status DestructionWorld::writeTimingsCsv(const std::filesystem::path& path) const {
    std::ofstream f(path);
    if (!f)
        return Error{ErrorCode::IoError, "cannot write " + path.string()};
    f << "object,frame,impacts_merged,queue_ms,prepare_ms,cell_ms,boolean_ms,islands_ms,decomposition_ms,"
         "finish_ms,handoff_ms,adoption_ms,total_ms,pieces,stale,failed,missed,crumbled\n";
    for (const auto& r : impl_->timings)
        f << r.object << ',' << r.frame << ',' << r.impactsMerged << ',' << r.queueMs << ',' << r.prepareMs
          << ',' << r.cellMs << ',' << r.booleanMs << ',' << r.islandsMs << ',' << r.decompositionMs << ','
          << r.finishMs << ',' << r.handoffMs << ',' << r.adoptionMs << ',' << r.totalMs << ',' << r.pieces
          << ',' << (r.stale ? 1 : 0) << ',' << (r.failed ? 1 : 0) << ',' << (r.missed ? 1 : 0) << ','
          << (r.crumbled ? 1 : 0) << '\n';
    if (!f)
        return Error{ErrorCode::IoError, "write failed: " + path.string()};
    return Status::ok();
}

} // namespace rubble
