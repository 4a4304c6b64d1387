// `rubble-bench scene FILE.cfg [--seconds T | --frames N] [--shots-per-second R] [--workers W] [--seed S]
//  [--deterministic] [--unpaced] [--no-idle-adoption] [--json] [--timings-csv FILE] [--frames-csv FILE]
//  [--append-csv FILE] [--pattern single|shatter] [--cells K] [--max-awake N] [--rough [--runs N] [--out
//  DIR]]`
//
// Headless destruction run of a world.cfg scene through the runtime on the Bullet binding: seeded projectiles
// at the destructible objects (target chosen with probability ∝ volume, aim point uniform in the central 80%
// of its bounding box), fixed 1/60 s frames paced at 60 Hz wall clock like a game (--unpaced: back to back),
// no rendering. Frame time = wall time of the main-thread frame (firing + physics + impact gathering +
// adoption + debris governor); choosing the targets scans every body, which a game would not do, and is not
// timed.
//
// Idle adoption (paced, not --deterministic): after its frame the main thread does not sleep until the next
// 1/60 s tick but waits for fracture results until the tick (DestructionWorld::waitForResult) and adopts each
// as it arrives (DestructionBridge::adoptReady), like a game that adopts right before rendering; a result is
// then adopted in the frame in which its job finished instead of at the start of the next one. That work is
// not part of the frame time: it is reported separately as "idle adoption" (per frame: milliseconds spent
// adopting in the idle time after it; the table's row, idle_adopt_ms in --frames-csv, idle_adoption_ms and
// fractures_idle in --json). --no-idle-adoption sleeps until the tick instead (adoption only at the start of
// a frame, the behaviour before idle adoption; for A/B runs). --unpaced and --deterministic adopt only in
// stepFrame (deterministic adoption is frame-bound so that replays are identical).
//
// Reports frames, frame_ms, impacts, fractures, latency_ms (impact → adopted, wall clock, from
// DestructionWorld timings: nearest-rank percentiles over the jobs whose pieces were adopted; stale, missed
// and failed jobs are counted, not timed — see TimingSummary), pieces_alive, volume_error (|live + retired +
// dropped − start| / start), state_hash (of the final sorted piece set; reproducible in --deterministic mode)
// and peak_rss_mb. A miss is a job whose cells did not intersect the mesh (e.g. an impact re-targeted to a
// piece while its point lies in the crater); a failure is a geometry failure. --json prints those keys and
// the counts and idle-adoption figures; the table adds the physics and adoption shares of the frame and the
// fracture stages. --append-csv adds one summary row to a CSV (header when the file is new), e.g.
// bench/results/scene.csv (scripts/scene-bench.sh writes it). Every report says how many cores the run used
// and how many other processes took meanwhile (cpu_cores: own / other; see bench::CpuMeter): a run with other
// work on the machine has inflated times.
//
// --rough runs the scene flat and with rough cuts by material (SceneLoadOptions::
// materialRoughness, as the demo plays it), alternating, --runs times each, in one process, and writes
// DIR/<scene>_rough.csv (frame and latency percentiles, fractures, triangles per run) and its PNG.
#include "Subcommand.hpp"

#if defined(RUBBLE_HAVE_BULLET)

#include "BenchUtil.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "rubble/bullet/BulletBinding.hpp"
#include "rubble/bullet/PhysicsWorld.hpp"
#include "rubble/core/Random.hpp"
#include "rubble/core/ThreadPool.hpp"
#include "rubble/io/SceneConfig.hpp"
#include "rubble/runtime/DestructionRuntime.hpp"
#include "rubble/runtime/SceneLoader.hpp"
#include "rubble/runtime/TimingReport.hpp"

namespace {

struct SceneArgs {
    std::string file;
    double seconds = 60;
    double shotsPerSecond = 10;
    int workers = -1;
    std::uint64_t seed = 1;
    bool deterministic = false;
    long frames = 0;             // > 0: overrides seconds
    bool unpaced = false;        // run frames back to back instead of at 60 Hz wall clock
    bool noIdleAdoption = false; // paced: sleep until the tick instead of adopting results as they arrive
    bool json = false;
    std::string timingsCsv;
    std::string framesCsv;
    std::string appendCsv;
    std::string pattern = "single";
    int cells = 0;                // shatter cells (0: the library's default)
    int maxAwake = 0;             // awake debris budget (0: the runtime's default)
    double physicsBudgetMs = 0;   // physics step budget (0: the runtime's default)
    double lightPerAwake = -1;    // light pieces per budgeted awake body (< 0: the runtime's default)
    double demolish = 0;          // seconds between demolition charges on standing targets (0: none)
    int maxHullPoints = -1;       // points per convex part's hull (0: uncapped; < 0: the binding's default)
    bool structure = false;       // the stress solver on
    double bearingFriction = 0.6; // with structure: objects rest on each other as bearings (0: welded)
    int structureIterations = 0;  // with structure: solver sweeps per frame (0: the library's)
    bool structureConverged = false; // with structure: the converged Gauss-Seidel solve
    std::string structureSolver;     // with structure: gauss-seidel, conjugate-gradient, direct (or empty)
    double projectileSpeed = 120;
    double projectileMass = 2;
    double projectileRadius = 0.25;
    bool rough = false;             // flat vs rough-by-material runs, alternating (--rough)
    bool materialRoughness = false; // this run's cuts are rough by material
    int runs = 1;                   // with --rough: runs of each
    std::string out = "bench/results";
};

// What one run measured, for the --rough table.
struct SceneSummary {
    double frameP50 = 0, frameP99 = 0, frameMax = 0, latencyP50 = 0, latencyP99 = 0, otherCpu = -1;
    double frameCpuP99 = 0; // the main thread's CPU time in a frame
    long long fractures = 0;
    int maxPieces = 0;
    std::size_t worldTriangles = 0;
};

double percentile(std::vector<double> v, double q) {
    if (v.empty())
        return 0;
    std::sort(v.begin(), v.end());
    const double pos = q * static_cast<double>(v.size() - 1);
    const std::size_t i = static_cast<std::size_t>(pos);
    const double f = pos - static_cast<double>(i);
    return i + 1 < v.size() ? v[i] * (1 - f) + v[i + 1] * f : v[i];
}

double peakRssMb() {
    std::ifstream in("/proc/self/status");
    std::string line;
    while (std::getline(in, line))
        if (line.rfind("VmHWM:", 0) == 0)
            return std::stod(line.substr(6)) / 1024.0;
    return 0;
}

// Where the demo's demolition charges go: static objects, and big static pieces still high above the ground.
std::vector<rubble::Vec3> standingTargets(const rubble::DestructionRuntime& runtime, double groundTop) {
    std::vector<rubble::Vec3> out;
    for (rubble::BodyId id : runtime.bodies()) {
        const rubble::BodyRecord* b = runtime.body(id);
        const rubble::Vec3 c = runtime.motion(id).transform.translation;
        if (b->motion == rubble::BodyMotionState::Static &&
            (b->role == rubble::BodyRole::Object ||
             (b->role == rubble::BodyRole::Piece && b->volume > 150 && c.y > groundTop + 15)))
            out.push_back(c);
    }
    return out;
}

// A shot: from where, how fast.
struct Shot {
    rubble::Vec3 from;
    rubble::Vec3 velocity;
};

// Aims one projectile at a destructible body chosen with probability ∝ volume (bench scaffolding: a scan of
// every body, which a game would not do, so it runs outside the timed frame).
std::optional<Shot> aim(const rubble::DestructionRuntime& runtime, rubble::Rng& rng, const SceneArgs& a) {
    using namespace rubble;
    std::vector<const BodyRecord*> targets;
    double total = 0;
    for (BodyId id : runtime.bodies()) {
        const BodyRecord* b = runtime.body(id);
        if (!b->hasObject || (b->role != BodyRole::Object && b->role != BodyRole::Piece))
            continue;
        const ObjectState* st = runtime.world().object(b->object);
        if (!st || !st->destructible)
            continue;
        targets.push_back(b);
        total += b->volume;
    }
    if (targets.empty() || total <= 0)
        return std::nullopt;
    double pick = rng.uniform(0, total);
    const BodyRecord* target = targets.back();
    for (const BodyRecord* b : targets) {
        if (pick < b->volume) {
            target = b;
            break;
        }
        pick -= b->volume;
    }
    // aim uniformly in the central 80 % of its bounding box
    const Frame f = runtime.motion(target->id).transform * target->objectToBody.inverse();
    const Aabb box = runtime.world().object(target->object)->mesh.bounds();
    const Vec3 local{box.lo.x + rng.uniform(0.1, 0.9) * (box.hi.x - box.lo.x),
                     box.lo.y + rng.uniform(0.1, 0.9) * (box.hi.y - box.lo.y),
                     box.lo.z + rng.uniform(0.1, 0.9) * (box.hi.z - box.lo.z)};
    const Vec3 at = f.apply(local);
    const double phi = rng.uniform(0, 2 * 3.14159265358979);
    const double y = rng.uniform(0.05, 0.6);
    const double r = std::sqrt(1 - y * y);
    const Vec3 dir{r * std::cos(phi), y, r * std::sin(phi)};
    const double distance = 30 + box.diagonal();
    return Shot{at + dir * distance, dir * -a.projectileSpeed};
}

int runScene(const SceneArgs& a, SceneSummary* summary = nullptr) {
    using namespace rubble;
    using namespace rubble::bullet;
    Result<SceneConfig> scene = parseSceneConfig(a.file);
    if (!scene) {
        std::cerr << "rubble-bench scene: " << scene.error().message << "\n";
        return 2;
    }
    DestructionRuntime::Config rc;
    rc.world.workers = a.workers;
    rc.world.deterministic = a.deterministic;
    rc.world.seed = a.seed;
    if (a.maxAwake > 0)
        rc.debris.maxAwakeBodies = a.maxAwake;
    if (a.physicsBudgetMs > 0)
        rc.debris.physicsBudgetMs = a.physicsBudgetMs;
    if (a.lightPerAwake >= 0)
        rc.debris.lightPerAwake = a.lightPerAwake;
    rc.structure.enabled = a.structure;
    rc.structure.bearingFriction = a.bearingFriction;
    if (a.structureIterations > 0) { // a sweep budget per frame
        rc.structure.stress.method = rubble::StressMethod::SweepBudget;
        rc.structure.stress.iterations = a.structureIterations;
        rc.structure.stress.tolerance = 0.05;
    } else if (a.structureSolver == "direct") {
        rc.structure.stress.method = rubble::StressMethod::Direct;
    } else if (a.structureSolver == "conjugate-gradient") {
        rc.structure.stress.method = rubble::StressMethod::ConjugateGradient;
    } else if (a.structureConverged || a.structureSolver == "gauss-seidel") {
        rc.structure.stress.method = rubble::StressMethod::GaussSeidel;
    }
    PhysicsWorld physics;
    BulletBinding::Config bc;
    if (a.maxHullPoints >= 0)
        bc.maxHullPoints = a.maxHullPoints;
    BulletBinding binding(physics, bc);
    DestructionRuntime runtime(binding, rc);
    const DestructionWorld& destruction = runtime.world();
    SceneLoadOptions lo;
    lo.loadVehicle = false;
    lo.materialRoughness = a.materialRoughness;
    lo.fracture.pattern = a.pattern == "shatter" ? CellPattern::Shatter : CellPattern::SingleCell;
    if (a.cells > 0)
        lo.fracture.cells = a.cells;
    const auto tLoad = std::chrono::steady_clock::now();
    const LoadedScene loaded = loadScene(*scene, runtime, lo);
    const double loadMs =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - tLoad).count();
    for (const std::string& w : loaded.warnings)
        std::cerr << "warning: " << w << "\n";
    const double startVolume = runtime.volumes().total();
    std::size_t startTriangles = 0;
    for (ObjectId id : destruction.objects())
        startTriangles += destruction.object(id)->mesh.triangleCount();
    { // distant tiny debris fades with distance from the middle of the scene
        Vec3 centre;
        for (ObjectId id : loaded.objects)
            if (const BodyRecord* b = runtime.bodyOf(id))
                centre += runtime.motion(b->id).transform.translation;
        if (!loaded.objects.empty())
            runtime.setFocus(centre / static_cast<double>(loaded.objects.size()));
    }

    Rng rng(mixSeed(a.seed, 0x5CE7E));
    const double dt = 1.0 / 60;
    const long frames = a.frames > 0 ? a.frames : std::max(1L, std::lround(a.seconds * 60));
    std::vector<double> frameMs, physicsMs, adoptMs, supportMs, idleAdoptMs, structureMs, structureCpuMs,
        residuals;
    std::vector<double> frameCpuMs; // the frame's own work: the main thread's CPU time
    const std::size_t bondsAtStart = a.structure ? runtime.structureBonds().size() : 0;
    long bondsBroken = 0, bondsBrokenFirstSecond = 0;
    frameMs.reserve(static_cast<std::size_t>(frames));
    idleAdoptMs.reserve(static_cast<std::size_t>(frames));
    std::ofstream framesOut;
    if (!a.framesCsv.empty()) {
        framesOut.open(a.framesCsv);
        if (!framesOut)
            std::cerr << "rubble-bench scene: cannot write " << a.framesCsv << "\n";
        framesOut << "frame,frame_ms,physics_ms,adopt_ms,idle_adopt_ms,bodies,pieces_alive,awake_pieces,"
                     "frozen_pieces,jobs_in_flight,fractures\n";
    }
    const bool idleAdoption = !a.unpaced && !a.noIdleAdoption && !a.deterministic;
    long shots = 0, nextCharge = 60;
    std::size_t charges = 0;
    long long idleFractures = 0;
    int maxPieces = 0;
    const rubble::bench::CpuMeter cpu; // whether something else ran meanwhile
    const auto runStart = std::chrono::steady_clock::now();
    const auto period =
        std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(dt));
    for (long f = 0; f < frames; ++f) {
        // like a game: one frame per 1/60 s of wall time (fracture jobs run in the idle part of the frame)
        if (!a.unpaced)
            std::this_thread::sleep_until(runStart + period * f);
        const long due = static_cast<long>(std::floor(static_cast<double>(f) * a.shotsPerSecond / 60.0));
        std::vector<Shot> volley;
        for (; shots < due; ++shots)
            if (std::optional<Shot> shot = aim(runtime, rng, a))
                volley.push_back(*shot);
        if (a.demolish > 0 && f >= nextCharge) { // as the demo's --demolish: the next standing target
            nextCharge = f + std::max(1L, std::lround(a.demolish * 60));
            const std::vector<Vec3> standing = standingTargets(runtime, loaded.groundTop);
            if (!standing.empty())
                runtime.blast(standing[charges++ % standing.size()], 8, 3500);
        }
        const auto t0 = std::chrono::steady_clock::now();
        const double cpu0 = rubble::bench::threadCpuMs();
        for (const Shot& shot : volley)
            runtime.fireProjectile(shot.from, shot.velocity, a.projectileMass, a.projectileRadius);
        const FrameStats fs = runtime.stepFrame(dt);
        const double ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        frameCpuMs.push_back(rubble::bench::threadCpuMs() - cpu0);
        physicsMs.push_back(fs.physicsMs);
        adoptMs.push_back(fs.adoptMs);
        structureMs.push_back(fs.structureMs);
        structureCpuMs.push_back(fs.structureCpuMs);
        residuals.push_back(fs.structureResidual);
        bondsBroken += fs.bondsBroken;
        if (f < 60)
            bondsBrokenFirstSecond += fs.bondsBroken;
        if (fs.fractures > 0) // structural-collapse checks, per adopted outcome
            supportMs.push_back(fs.supportMs / fs.fractures);
        frameMs.push_back(ms);
        // the idle rest of this frame: adopt results as they arrive until the next tick
        double idleMs = 0;
        if (idleAdoption) {
            const auto next = runStart + period * (f + 1);
            while (std::chrono::steady_clock::now() < next && destruction.waitForResult(next)) {
                const FrameStats is = runtime.adoptReady();
                idleMs += is.adoptMs;
                idleFractures += is.fractures;
                if (is.fractures > 0)
                    supportMs.push_back(is.supportMs / is.fractures);
            }
        }
        idleAdoptMs.push_back(idleMs);
        maxPieces = std::max(maxPieces, runtime.livePieces());
        if (framesOut)
            framesOut << f << ',' << ms << ',' << fs.physicsMs << ',' << fs.adoptMs << ',' << idleMs << ','
                      << runtime.bodyCount() << ',' << runtime.livePieces() << ',' << runtime.awakeDebris()
                      << ',' << runtime.frozenDebris() << ',' << destruction.jobsInFlight() << ','
                      << runtime.counters().fractures << '\n';
    }
    // per-impact stages: the runtime's own summary (nearest-rank percentiles over adopted jobs; stale, missed
    // and failed records are counted only)
    const TimingSummary ts = summarizeTimings(destruction.timings());
    const double volumeError =
        startVolume > 0 ? std::abs(runtime.volumes().total() - startVolume) / startVolume : 0;
    const std::uint64_t hash = runtime.stateHash();
    char hashText[32];
    std::snprintf(hashText, sizeof hashText, "%016llx", static_cast<unsigned long long>(hash));
    const RuntimeCounters& c = runtime.counters();
    const double rss = peakRssMb();
    const rubble::bench::CpuMeter::Reading cpuUse = cpu.read();
    const int workers = a.workers > 0 ? a.workers : rubble::ThreadPool::defaultWorkerCount();
    if (summary) {
        *summary = {percentile(frameMs, 0.5),
                    percentile(frameMs, 0.99),
                    percentile(frameMs, 1.0),
                    ts.total.p50,
                    ts.total.p99,
                    cpuUse.other,
                    percentile(frameCpuMs, 0.99),
                    c.fractures,
                    maxPieces,
                    0};
        for (ObjectId id : destruction.objects())
            if (const ObjectState* st = destruction.object(id))
                summary->worldTriangles += st->mesh.triangleCount();
    }

    if (!a.timingsCsv.empty()) {
        if (Status s = destruction.writeTimingsCsv(a.timingsCsv); !s)
            std::cerr << "rubble-bench scene: " << s.message() << "\n";
    }
    if (!a.appendCsv.empty()) {
        const bool fresh =
            !std::filesystem::exists(a.appendCsv) || std::filesystem::file_size(a.appendCsv) == 0;
        std::ofstream out(a.appendCsv, std::ios::app);
        if (!out)
            std::cerr << "rubble-bench scene: cannot write " << a.appendCsv << "\n";
        if (fresh)
            out << "scene,workers,deterministic,seed,shots_per_second,frames,shots,frame_p50_ms,frame_p99_ms,"
                   "frame_max_ms,physics_p50_ms,physics_p99_ms,adopt_p99_ms,impacts,fractures,stale,"
                   "latency_p50_ms,latency_p99_ms,latency_max_ms,queue_p50_ms,boolean_p50_ms,"
                   "decomposition_p50_ms,pieces_alive,pieces_max,pieces_retired,volume_error,state_hash,"
                   "peak_rss_mb,missed,failed,fractures_idle,handoff_p50_ms,adoption_p99_ms,own_cpu_cores,"
                   "other_cpu_cores,pattern,cells,triangles,awake_pieces,frozen_pieces,pieces_collapsed\n";
        out << a.file << ',' << workers << ',' << (a.deterministic ? 1 : 0) << ',' << a.seed << ','
            << a.shotsPerSecond << ',' << frames << ',' << shots << ',' << percentile(frameMs, 0.5) << ','
            << percentile(frameMs, 0.99) << ',' << percentile(frameMs, 1.0) << ','
            << percentile(physicsMs, 0.5) << ',' << percentile(physicsMs, 0.99) << ','
            << percentile(adoptMs, 0.99) << ',' << c.impacts << ',' << c.fractures << ',' << ts.stale << ','
            << ts.total.p50 << ',' << ts.total.p99 << ',' << ts.total.max << ',' << ts.queue.p50 << ','
            << ts.boolean.p50 << ',' << ts.decomposition.p50 << ',' << runtime.livePieces() << ','
            << maxPieces << ',' << c.piecesRetired << ',' << volumeError << ',' << hashText << ',' << rss
            << ',' << ts.missed << ',' << ts.failed << ',' << idleFractures << ',' << ts.handoff.p50 << ','
            << ts.adoption.p99 << ',' << cpuUse.own << ',' << cpuUse.other << ',' << a.pattern << ','
            << (a.cells > 0 ? a.cells : FractureParams{}.cells) << ',' << startTriangles << ','
            << runtime.awakeDebris() << ',' << runtime.frozenDebris() << ',' << c.piecesCollapsed << '\n';
    }
    if (a.json) {
        nlohmann::json j;
        j["frames"] = frames;
        j["frame_ms"] = {{"p50", percentile(frameMs, 0.5)},
                         {"p99", percentile(frameMs, 0.99)},
                         {"max", percentile(frameMs, 1.0)}};
        j["impacts"] = c.impacts;
        j["fractures"] = c.fractures;
        j["latency_ms"] = {{"p50", ts.total.p50}, {"p99", ts.total.p99}, {"max", ts.total.max}};
        j["stale"] = ts.stale;
        j["missed"] = ts.missed;
        j["failed"] = ts.failed;
        j["fractures_idle"] = idleFractures;
        j["idle_adoption_ms"] = {{"p50", percentile(idleAdoptMs, 0.5)},
                                 {"p99", percentile(idleAdoptMs, 0.99)},
                                 {"max", percentile(idleAdoptMs, 1.0)}};
        j["physics_ms"] = {{"p50", percentile(physicsMs, 0.5)},
                           {"p99", percentile(physicsMs, 0.99)},
                           {"max", percentile(physicsMs, 1.0)}};
        j["triangles_at_start"] = startTriangles;
        j["pieces_alive"] = runtime.livePieces();
        j["pieces_max"] = maxPieces;
        j["awake_pieces"] = runtime.awakeDebris();
        j["frozen_pieces"] = runtime.frozenDebris();
        j["light_pieces"] = runtime.lightDebris();
        j["pieces_collapsed"] = c.piecesCollapsed;
        j["bonds_broken"] = c.bondsBroken;
        j["pieces_frozen"] = c.piecesFrozen;
        j["pieces_woken"] = c.piecesWoken;
        j["pieces_light"] = c.piecesLight;
        const VolumeLedger v = runtime.volumes();
        j["volume"] = {{"start", startVolume},
                       {"live", v.live},
                       {"retired", v.retired},
                       {"dust", v.dust},
                       {"dropped", v.dropped}};
        j["shots"] = shots;
        j["pieces_retired"] = c.piecesRetired;
        j["debris_budget"] = {{"max_awake_bodies", runtime.config().debris.maxAwakeBodies},
                              {"physics_ms", runtime.config().debris.physicsBudgetMs},
                              {"light_per_awake", runtime.config().debris.lightPerAwake}};
        j["retired_by"] = {{"dust", c.retired.dust},
                           {"awake_budget", c.retired.awake},
                           {"triangle_budget", c.retired.triangles},
                           {"faded", c.retired.faded},
                           {"fell_out", c.retired.fellOut}};
        if (a.structure)
            j["structure"] = {
                {"bearing_friction", a.bearingFriction},
                {"bonds_at_start", bondsAtStart},
                {"bonds_at_end", runtime.structureBonds().size()},
                {"bonds_broken", bondsBroken},
                {"bonds_broken_first_second", bondsBrokenFirstSecond},
                {"residual", {{"p50", percentile(residuals, 0.5)}, {"max", percentile(residuals, 1.0)}}},
                {"solve_ms", {{"p50", percentile(structureMs, 0.5)}, {"p99", percentile(structureMs, 0.99)}}},
                {"solve_cpu_ms",
                 {{"p50", percentile(structureCpuMs, 0.5)},
                  {"p99", percentile(structureCpuMs, 0.99)},
                  {"max", percentile(structureCpuMs, 1.0)}}}};
        // what the long-lived containers hold at the end (a soak checks that they stay bounded)
        j["bodies"] = runtime.bodyCount();
        j["world_objects"] = destruction.objects().size();
        j["timing_records"] = destruction.timings().size();
        j["debris_particles"] = runtime.particles().size();
        std::size_t triangles = 0, maxTriangles = 0, parts = 0;
        for (ObjectId id : destruction.objects())
            if (const ObjectState* st = destruction.object(id)) {
                triangles += st->mesh.triangleCount();
                maxTriangles = std::max(maxTriangles, st->mesh.triangleCount());
                parts += st->convexParts.size();
            }
        j["world_triangles"] = triangles;
        j["world_max_triangles"] = maxTriangles;
        j["world_convex_parts"] = parts;
        j["volume_error"] = volumeError;
        j["state_hash"] = hashText;
        j["peak_rss_mb"] = rss;
        j["cpu_cores"] = {{"own", cpuUse.own}, {"other", cpuUse.other}};
        std::cout << j.dump(2) << "\n";
        return 0;
    }
    std::printf(
        "scene %s: %ld frames (%.1f s at 1/60 s), %ld shots, %d workers%s%s, seed %llu, load %.1f ms\n",
        a.file.c_str(), frames, static_cast<double>(frames) / 60.0, shots, workers,
        a.deterministic ? " (deterministic)" : "",
        a.unpaced      ? " (unpaced)"
        : idleAdoption ? " (idle adoption)"
                       : "",
        static_cast<unsigned long long>(a.seed), loadMs);
    std::printf("%-28s %10s %10s %10s\n", "", "p50", "p99", "max");
    auto row = [](const char* name, const std::vector<double>& v) {
        std::printf("%-28s %10.3f %10.3f %10.3f\n", name, percentile(v, 0.5), percentile(v, 0.99),
                    percentile(v, 1.0));
    };
    row("frame (ms)", frameMs);
    row("frame, main thread CPU (ms)", frameCpuMs);
    row("  physics step (ms)", physicsMs);
    row("  impacts + adoption (ms)", adoptMs);
    row("  support / adoption (ms)", supportMs);
    row("idle adoption / frame (ms)", idleAdoptMs); // after the frame, not in its time
    std::printf("impact -> adopted, per stage (total = latency): %s", formatTimingSummary(ts).c_str());
    std::printf("%-28s %10lld\n", "impacts", c.impacts);
    std::printf("%-28s %10lld (%lld in idle time)\n", "fractures", c.fractures, idleFractures);
    std::printf("%-28s %10d\n", "stale results", ts.stale);
    std::printf("%-28s %10d\n", "missed (cells off the mesh)", ts.missed);
    std::printf("%-28s %10d\n", "failed (geometry)", ts.failed);
    std::printf("%-28s %10d (max %d; %d awake of which %d light, %d frozen)\n", "pieces alive",
                runtime.livePieces(), maxPieces, runtime.awakeDebris(), runtime.lightDebris(),
                runtime.frozenDebris());
    std::printf(
        "%-28s %10lld (dust %lld, awake budget %lld, triangle budget %lld, faded %lld, fell out %lld)\n",
        "pieces retired", c.piecesRetired, c.retired.dust, c.retired.awake, c.retired.triangles,
        c.retired.faded, c.retired.fellOut);
    std::printf("%-28s %10lld\n", "pieces collapsed", c.piecesCollapsed);
    std::printf("%-28s %10lld (%lld woken)\n", "pieces frozen", c.piecesFrozen, c.piecesWoken);
    std::printf("%-28s %10lld\n", "pieces made light", c.piecesLight);
    std::printf("%-28s %10.3g\n", "volume error", volumeError);
    std::printf("%-28s %10s\n", "state hash", hashText);
    std::printf("%-28s %10.1f\n", "peak RSS (MB)", rss);
    std::printf("%-28s %10.2f (other processes: %.2f of %d)\n", "CPU cores used", cpuUse.own, cpuUse.other,
                static_cast<int>(std::thread::hardware_concurrency()));
    return 0;
}

// --rough: the scene flat and rough by material, alternating, and the table of both.
int runRoughVsFlat(const SceneArgs& args) {
    namespace bench = rubble::bench;
    bench::Table table{{"scene", "cuts", "run", "frames", "frame_p50_ms", "frame_p99_ms", "frame_max_ms",
                        "latency_p50_ms", "latency_p99_ms", "fractures", "max_pieces", "world_triangles",
                        "frame_cpu_p99_ms", "other_cpu_cores"},
                       {}};
    const std::string stem = std::filesystem::path(args.file).stem().string();
    std::string data;
    for (int run = 0; run < args.runs; ++run)
        for (const bool rough : {false, true}) {
            SceneArgs a = args;
            a.materialRoughness = rough;
            std::printf("--- %s, %s cuts, run %d\n", stem.c_str(), rough ? "rough" : "flat", run + 1);
            SceneSummary s;
            if (const int code = runScene(a, &s); code != 0)
                return code;
            table.rows.push_back({stem, rough ? "rough" : "flat", std::to_string(run + 1),
                                  std::to_string(a.frames > 0 ? a.frames : std::lround(a.seconds * 60)),
                                  bench::fixed(s.frameP50), bench::fixed(s.frameP99),
                                  bench::fixed(s.frameMax), bench::fixed(s.latencyP50),
                                  bench::fixed(s.latencyP99), std::to_string(s.fractures),
                                  std::to_string(s.maxPieces), std::to_string(s.worldTriangles),
                                  bench::fixed(s.frameCpuP99), bench::fixed(s.otherCpu, 2)});
            data += (rough ? "" : "\"run " + std::to_string(run + 1) + "\" ") + bench::fixed(s.frameP99) +
                    (rough ? "\n" : " ");
        }
    bench::printTable(table);
    if (!bench::makeResultsDir(args.out) ||
        !bench::writeCsv(std::filesystem::path(args.out) / (stem + "_rough.csv"), table))
        return 1;
    bench::plotPng(
        args.out, stem + "_rough", data,
        "set termoption noenhanced\nset style data histograms\nset style fill solid 0.6\n"
        "set ylabel 'frame p99 (ms)'\nset yrange [0:*]\nset grid ytics\nset key top left\nset title '" +
            stem +
            ": flat vs rough cuts by material, one process'\n"
            "plot $DATA u 2:xtic(1) t 'flat', '' u 3 t 'rough'");
    return 0;
}

rubble::tools::Registrar registrar{
    {"scene", "headless destruction run of a world.cfg scene (Bullet + runtime)", [](CLI::App& app) {
         auto args = std::make_shared<SceneArgs>();
         app.add_option("file", args->file, "scene file (world.cfg format)")->required();
         app.add_option("--seconds", args->seconds, "simulated seconds");
         app.add_option("--shots-per-second", args->shotsPerSecond, "projectiles per simulated second");
         app.add_option("--workers", args->workers, "fracture worker threads (-1 automatic)");
         app.add_option("--seed", args->seed, "random seed")->check(rubble::tools::unsigned64());
         app.add_flag("--deterministic", args->deterministic,
                      "adopt results a fixed number of frames after impact");
         app.add_flag("--json", args->json, "JSON on stdout");
         app.add_flag("--unpaced", args->unpaced,
                      "run frames back to back (default: paced at 60 Hz wall clock, like a game)");
         app.add_flag(
             "--no-idle-adoption", args->noIdleAdoption,
             "paced: sleep until the next tick instead of adopting results as they arrive (A/B runs)");
         app.add_option("--frames", args->frames, "frames to run (overrides --seconds; for soak runs)");
         app.add_option("--timings-csv", args->timingsCsv, "write the per-impact timing records as CSV");
         app.add_option("--frames-csv", args->framesCsv, "write per-frame times and counts as CSV");
         app.add_option("--append-csv", args->appendCsv,
                        "append a summary row to this CSV (e.g. bench/results/scene.csv)");
         app.add_option("--pattern", args->pattern, "cell pattern of every object: single or shatter")
             ->check(CLI::IsMember({"single", "shatter"}));
         app.add_option("--cells", args->cells, "cells of a shatter pattern (default: the library's)");
         app.add_option("--max-awake", args->maxAwake, "awake debris budget (default: the runtime's)");
         app.add_option("--physics-budget-ms", args->physicsBudgetMs,
                        "physics step time the debris governor holds (default: the runtime's, for 60 Hz)");
         app.add_option("--light-per-awake", args->lightPerAwake,
                        "light pieces (colliding with static bodies only) per budgeted awake body; 0: "
                        "pieces over the awake budget retire (default: the runtime's)");
         app.add_option("--demolish", args->demolish,
                        "seconds between demolition charges (8 m, 3,500 N·s) on the next standing target, as "
                        "the demo's --demolish");
         app.add_option("--max-hull-points", args->maxHullPoints,
                        "points per convex part's collision hull (0: uncapped; default: the binding's)");
         app.add_flag("--structure", args->structure, "stress solver on (bonds, breaking under load)");
         app.add_option("--bearing-friction", args->bearingFriction,
                        "with --structure: objects rest on each other as bearings with this friction "
                        "coefficient (0: welded joints)");
         app.add_option(
             "--structure-iterations", args->structureIterations,
             "with --structure: the old solver, Gauss-Seidel with this many sweeps a frame (default: the "
             "library's, converged: direct with bearings, else Gauss-Seidel)");
         app.add_flag(
             "--structure-converged", args->structureConverged,
             "with --structure: the converged Gauss-Seidel solve (relative residual 1e-3 every frame)");
         app.add_option("--structure-solver", args->structureSolver,
                        "with --structure: the converged solve to use (relative residual 1e-3 every frame; "
                        "auto, the default: direct with bearings, else gauss-seidel)")
             ->check(CLI::IsMember({"auto", "gauss-seidel", "conjugate-gradient", "direct"}));
         app.add_option("--projectile-speed", args->projectileSpeed, "m/s");
         app.add_option("--projectile-mass", args->projectileMass, "kg");
         app.add_flag("--rough", args->rough,
                      "run the scene flat and rough by material, alternating, in one process; writes "
                      "OUT/<scene>_rough.csv and .png");
         app.add_option("--runs", args->runs, "with --rough: runs of each")->check(CLI::Range(1, 100));
         app.add_option("--out", args->out, "with --rough: results folder");
         return [args] { return args->rough ? runRoughVsFlat(*args) : runScene(*args); };
     }}};

} // namespace

#endif
