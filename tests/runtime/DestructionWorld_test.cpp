#include "rubble/runtime/DestructionWorld.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "TestSupport.hpp"
#include "WorldSteps.hpp"
#include "geometry/ShellScratch.hpp"
#include "rubble/core/Log.hpp"
#include "rubble/core/Random.hpp"
#include "rubble/core/ThreadPool.hpp"
#include "rubble/geometry/MassProperties.hpp"
#include "rubble/runtime/Journal.hpp"

namespace rubble {
namespace {

/// Runs jobs only when the test says so (deterministic interleavings).
class HeldJobs final : public JobSystem {
public:
    void submit(std::function<void()> job) override { held.push_back(std::move(job)); }
    int workerCount() const override { return 1; }
    void runAll() {
        auto jobs = std::move(held);
        held.clear();
        for (auto& j : jobs)
            j();
    }
    std::vector<std::function<void()>> held;
};

// The ids of an outcome's pieces.
std::vector<ObjectId> ids(const FractureOutcome& o) {
    std::vector<ObjectId> out;
    for (const AdoptedPiece& p : o.pieces)
        out.push_back(p.id);
    return out;
}

DestructionWorld::Config heldConfig(HeldJobs& jobs) {
    DestructionWorld::Config c;
    c.jobs = &jobs;
    return c;
}

ObjectDesc boxDesc() {
    ObjectDesc d;
    d.mesh = makeSubdividedBox({-1, -1, -1}, {1, 1, 1}, 3);
    d.density = 2;
    d.impulseThreshold = 1;
    return d;
}

Impact centreHit() {
    Impact i;
    i.point = {0, 0, 1};
    i.normal = {0, 0, 1};
    i.impulse = 10;
    return i;
}

// An object that names a material breaks in that material's pattern: glass radially, wood in splinters,
// steel evenly; concrete (and an object without a material) keeps the layout its parameters name.
TEST(DestructionWorld, AMaterialChoosesTheShatterLayout) {
    HeldJobs jobs;
    DestructionWorld world(heldConfig(jobs));
    const std::pair<const char*, ShatterLayout> cases[] = {{"glass", ShatterLayout::Radial},
                                                           {"wood", ShatterLayout::Splinter},
                                                           {"steel", ShatterLayout::Uniform},
                                                           {"concrete", ShatterLayout::Clustered},
                                                           {"", ShatterLayout::Clustered}};
    for (const auto& [material, layout] : cases) {
        ObjectDesc d = boxDesc();
        d.material = material;
        d.fracture.pattern = CellPattern::Shatter;
        Result<ObjectId> id = world.addObject(std::move(d));
        ASSERT_TRUE(id) << material;
        EXPECT_EQ(world.object(*id)->fracture.layout, layout) << material;
    }
    ObjectDesc d = boxDesc();
    d.fracture.layout = ShatterLayout::Radial;
    const ObjectId id = *world.addObject(std::move(d));
    EXPECT_EQ(world.object(id)->fracture.layout, ShatterLayout::Radial) << "no material: the parameters' own";
    EXPECT_EQ(patternByte(world.object(id)->fracture), 0x10) << "single cell, radial layout";
}

TEST(DestructionWorld, ImpactBelowThresholdIgnored) {
    HeldJobs jobs;
    DestructionWorld w(heldConfig(jobs));
    auto id = w.addObject(boxDesc());
    ASSERT_TRUE(id);
    Impact i = centreHit();
    i.impulse = 0.5;
    EXPECT_FALSE(w.submitImpact(id.value(), i));
    EXPECT_EQ(w.jobsInFlight(), 0);
}

// accepts() is the one impact filter: submitImpact takes exactly what it accepts, at journal precision (an
// impulse just below the threshold that rounds up to it counts, as it does when the journal is replayed).
TEST(DestructionWorld, SubmitImpactTakesExactlyWhatTheFilterAccepts) {
    HeldJobs jobs;
    DestructionWorld w(heldConfig(jobs));
    const ObjectId id = *w.addObject(boxDesc()); // threshold 1
    ObjectDesc fixed = boxDesc();
    fixed.destructible = false;
    const ObjectId wall = *w.addObject(std::move(fixed));
    Impact below = centreHit(), rounded = centreHit(), noNormal = centreHit();
    below.impulse = 0.99;
    rounded.impulse = 1 - 1e-9; // 1.0f at single precision
    noNormal.normal = {0, 0, 0};
    const std::tuple<ObjectId, Impact, bool> cases[] = {{id, below, false},         {id, noNormal, false},
                                                        {wall, centreHit(), false}, {999, centreHit(), false},
                                                        {id, rounded, true},        {id, centreHit(), true}};
    for (const auto& [object, impact, expected] : cases) {
        EXPECT_EQ(w.accepts(object, impact), expected) << object << " " << impact.impulse;
        EXPECT_EQ(w.submitImpact(object, impact), expected) << object << " " << impact.impulse;
    }
    EXPECT_EQ(w.journalPosition(), 2u);
}

TEST(DestructionWorld, OpenMeshWithAPlanarHoleIsClosedAndDestructible) {
    HeldJobs jobs;
    DestructionWorld w(heldConfig(jobs));
    ObjectDesc d = boxDesc();
    d.mesh.triangles.pop_back(); // a triangular hole: repair closes it
    auto id = w.addObject(d);
    ASSERT_TRUE(id);
    EXPECT_TRUE(w.object(id.value())->destructible);
    EXPECT_NEAR(w.object(id.value())->mass.volume, 8.0, 1e-9);
}

TEST(DestructionWorld, OpenMeshIsIndestructible) {
    HeldJobs jobs;
    DestructionWorld w(heldConfig(jobs));
    ObjectDesc d = boxDesc();
    // Two adjacent faces missing: one hole bent at a right angle, which repair does not close.
    std::erase_if(d.mesh.triangles, [&](const Triangle& t) {
        const auto all = [&](auto on) {
            return on(d.mesh.positions[t[0]]) && on(d.mesh.positions[t[1]]) && on(d.mesh.positions[t[2]]);
        };
        return all([](const Vec3& p) { return p.z == 1; }) || all([](const Vec3& p) { return p.y == -1; });
    });
    std::vector<std::string> logged;
    setLogFunction([&](LogLevel level, std::string_view message) {
        logged.push_back(std::string(toString(level)) + ": " + std::string(message));
    });
    testing::internal::CaptureStderr();
    auto id = w.addObject(d);
    const std::string printed = testing::internal::GetCapturedStderr();
    setLogFunction({});
    ASSERT_TRUE(id);
    ASSERT_NE(w.object(id.value()), nullptr);
    EXPECT_FALSE(w.object(id.value())->destructible);
    EXPECT_FALSE(w.object(id.value())->warning.empty());
    EXPECT_FALSE(w.submitImpact(id.value(), centreHit()));
    // The warning goes to the log function, not to stderr.
    ASSERT_EQ(logged.size(), 1u);
    EXPECT_EQ(logged[0], "warning: object " + std::to_string(*id) +
                             " is indestructible: " + w.object(id.value())->warning);
    EXPECT_EQ(printed, "");
}

TEST(DestructionWorld, ImpactConservesVolumeAndMass) {
    HeldJobs jobs;
    DestructionWorld w(heldConfig(jobs));
    auto id = w.addObject(boxDesc()).value();
    const double v0 = w.object(id)->mass.volume;
    ASSERT_TRUE(w.submitImpact(id, centreHit()));
    jobs.runAll();
    w.beginFrame();
    auto out = collectAndCommit(w);
    ASSERT_EQ(out.size(), 1u);
    EXPECT_EQ(w.object(id), nullptr);
    double v = out[0].droppedVolume;
    for (const ObjectId p : ids(out[0])) {
        ASSERT_NE(w.object(p), nullptr);
        v += w.object(p)->mass.volume;
        EXPECT_NEAR(length(w.object(p)->mass.centerOfMass), 0, 1e-9);
        EXPECT_EQ(w.object(p)->density, 2);
    }
    EXPECT_NEAR(v, v0, 1e-6 * v0);
    ASSERT_EQ(w.timings().size(), 1u);
}

// A piece holds no spare capacity in its mesh's arrays (the kernel grows them as it cuts).
TEST(DestructionWorld, PiecesHoldNoSpareCapacity) {
    HeldJobs jobs;
    DestructionWorld w(heldConfig(jobs));
    ObjectDesc d = boxDesc();
    d.mesh.computeFlatNormals();
    for (std::size_t c = 0; c < 3 * d.mesh.triangles.size(); ++c)
        d.mesh.uvs.push_back({0.1 * static_cast<double>(c % 7), 0.2 * static_cast<double>(c % 5)});
    d.fracture.pattern = CellPattern::Shatter;
    d.fracture.cells = 8;
    auto id = w.addObject(std::move(d)).value();
    ASSERT_TRUE(w.submitImpact(id, centreHit()));
    jobs.runAll();
    w.beginFrame();
    auto out = collectAndCommit(w);
    ASSERT_EQ(out.size(), 1u);
    ASSERT_GT(out[0].pieces.size(), 2u);
    for (const ObjectId p : ids(out[0])) {
        const Mesh& m = w.object(p)->mesh;
        ASSERT_TRUE(m.hasNormals() && m.hasUvs());
        EXPECT_EQ(m.positions.capacity(), m.positions.size());
        EXPECT_EQ(m.triangles.capacity(), m.triangles.size());
        EXPECT_EQ(m.normals.capacity(), m.normals.size());
        EXPECT_EQ(m.uvs.capacity(), m.uvs.size());
        EXPECT_EQ(m.materials.capacity(), m.materials.size());
    }
}

// The thread that adds a large object keeps no large work arrays of the mesh check (a fracture worker does).
TEST(DestructionWorld, AddingALargeMeshLeavesNoLargeWorkArraysOnTheCallingThread) {
    HeldJobs jobs;
    DestructionWorld w(heldConfig(jobs));
    ObjectDesc d;
    d.mesh = makeSphere({0, 0, 0}, 1, 200, 100); // 40k triangles
    d.convexParts = {ConvexPolytope::fromAabb(d.mesh.bounds())};
    ASSERT_TRUE(analyzeMesh(d.mesh));                             // as addObject does
    ASSERT_GT(detail::shellScratchBytes(), std::size_t{1} << 20); // what the check keeps on its own
    ASSERT_TRUE(w.addObject(std::move(d)));
    EXPECT_LE(detail::shellScratchBytes(), std::size_t{1} << 20);
}

// Pieces below Config::minPieceVolume never become objects: the outcome reports them as dust, and pieces +
// dust + dropped slivers still add up to the parent.
TEST(DestructionWorld, PiecesBelowTheMinimumVolumeBecomeDust) {
    HeldJobs jobs;
    DestructionWorld::Config c = heldConfig(jobs);
    c.minPieceVolume = 0.05;
    DestructionWorld w(c);
    ObjectDesc d = boxDesc();
    d.fracture.pattern = CellPattern::Shatter;
    d.fracture.cells = 16;
    const ObjectId id = w.addObject(d).value();
    const double v0 = w.object(id)->mass.volume;
    ASSERT_TRUE(w.submitImpact(id, centreHit()));
    jobs.runAll();
    w.beginFrame();
    auto out = collectAndCommit(w);
    ASSERT_EQ(out.size(), 1u);
    ASSERT_FALSE(out[0].dust.empty()) << "a 16-cell shatter leaves small pieces";
    double v = out[0].droppedVolume + out[0].dustVolume();
    for (const DustPiece& dust : out[0].dust)
        EXPECT_LT(dust.volume, c.minPieceVolume);
    for (const AdoptedPiece& p : out[0].pieces) {
        EXPECT_GE(p.state->mass.volume, c.minPieceVolume);
        EXPECT_EQ(w.object(p.id), p.state.get());
        v += p.state->mass.volume;
    }
    EXPECT_NEAR(v, v0, 1e-9 * v0);
    EXPECT_EQ(w.timings().back().pieces, static_cast<int>(out[0].pieces.size()));
}

TEST(DestructionWorld, ImpactsDuringJobAreMergedNotLost) {
    HeldJobs jobs;
    DestructionWorld w(heldConfig(jobs));
    auto id = w.addObject(boxDesc()).value();
    ASSERT_TRUE(w.submitImpact(id, centreHit()));
    Impact j = centreHit();
    j.point = {1, 0, 0};
    j.normal = {1, 0, 0};
    ASSERT_TRUE(w.submitImpact(id, j));
    Impact k = j;
    k.point = {-1, 0, 0};
    k.normal = {-1, 0, 0};
    ASSERT_TRUE(w.submitImpact(id, k));
    jobs.runAll();
    w.beginFrame();
    ASSERT_EQ(collectAndCommit(w).size(), 1u);
    // The two waiting impacts were forwarded to pieces: a job is in flight for them.
    EXPECT_GE(w.jobsInFlight(), 1);
    for (int round = 0; round < 4 && w.jobsInFlight() > 0; ++round) {
        jobs.runAll();
        w.beginFrame();
        collectAndCommit(w);
    }
    int handled = 0;
    for (const auto& r : w.timings())
        handled += r.impactsMerged;
    EXPECT_EQ(handled, 3);
}

TEST(DestructionWorld, ImpactsWaitingOnAMissedJobAreMergedIntoOneJob) {
    HeldJobs jobs;
    DestructionWorld w(heldConfig(jobs));
    auto id = w.addObject(boxDesc()).value();
    Impact miss = centreHit();
    miss.point = {50, 50, 50}; // the cells miss the mesh: the job misses and the object stays
    ASSERT_TRUE(w.submitImpact(id, miss));
    Impact j = centreHit();
    j.point = {1, 0, 0};
    j.normal = {1, 0, 0};
    Impact k = j;
    k.point = {-1, 0, 0};
    k.normal = {-1, 0, 0};
    ASSERT_TRUE(w.submitImpact(id, j));
    ASSERT_TRUE(w.submitImpact(id, k));
    jobs.runAll();
    w.beginFrame();
    EXPECT_TRUE(collectAndCommit(w).empty());
    ASSERT_NE(w.object(id), nullptr);
    ASSERT_EQ(w.jobsInFlight(), 1);
    jobs.runAll();
    w.beginFrame();
    const auto out = collectAndCommit(w);
    ASSERT_EQ(out.size(), 1u);
    EXPECT_EQ(out[0].impacts.size(), 2u);
    ASSERT_EQ(w.timings().size(), 2u);
    EXPECT_TRUE(w.timings()[0].missed);
    EXPECT_FALSE(w.timings()[0].failed) << "a miss is not a geometry failure";
    EXPECT_FALSE(w.timings()[1].missed);
    EXPECT_FALSE(w.timings()[1].failed);
    EXPECT_EQ(w.timings()[1].impactsMerged, 2);
    double v = out[0].droppedVolume;
    for (const ObjectId p : ids(out[0]))
        v += w.object(p)->mass.volume;
    EXPECT_NEAR(v, 8.0, 8e-6);
}

TEST(DestructionWorld, ImpactReportedOffTheSurfaceStillFractures) {
    // A predictive CCD contact reports the projectile's centre, a radius away from the surface: the cells are
    // centred on the nearest surface point. Without that, this cell domain (edge ~0.66) would miss the box.
    HeldJobs jobs;
    DestructionWorld w(heldConfig(jobs));
    auto id = w.addObject(boxDesc()).value();
    Impact i = centreHit();
    i.point = {0.1, 0.2, 1.4};
    ASSERT_TRUE(w.submitImpact(id, i));
    jobs.runAll();
    w.beginFrame();
    const auto out = collectAndCommit(w);
    ASSERT_EQ(out.size(), 1u);
    EXPECT_GE(out[0].pieces.size(), 2u);
    double v = out[0].droppedVolume;
    for (const ObjectId p : ids(out[0]))
        v += w.object(p)->mass.volume;
    EXPECT_NEAR(v, 8.0, 8e-6);
}

TEST(DestructionWorld, StaleResultDiscarded) {
    HeldJobs jobs;
    DestructionWorld w(heldConfig(jobs));
    auto id = w.addObject(boxDesc()).value();
    ASSERT_TRUE(w.submitImpact(id, centreHit()));
    w.removeObject(id);
    jobs.runAll();
    w.beginFrame();
    EXPECT_TRUE(collectAndCommit(w).empty());
    ASSERT_EQ(w.timings().size(), 1u);
    EXPECT_TRUE(w.timings()[0].stale);
}

std::vector<std::uint64_t> pieceHashes(DestructionWorld::Config cfg, const Roughness& roughness = {}) {
    DestructionWorld w(cfg);
    ObjectDesc desc = boxDesc();
    desc.fracture.roughness = roughness;
    auto id = w.addObject(desc).value();
    EXPECT_TRUE(w.submitImpact(id, centreHit()));
    w.waitIdle();
    std::vector<std::uint64_t> h;
    for (int f = 0; f < 5; ++f) {
        w.beginFrame();
        for (const auto& o : collectAndCommit(w))
            for (const ObjectId p : ids(o))
                h.push_back(w.object(p)->mesh.hash());
    }
    std::sort(h.begin(), h.end());
    return h;
}

TEST(DestructionWorld, DeterministicAcrossWorkerCounts) {
    DestructionWorld::Config one;
    one.workers = 1;
    DestructionWorld::Config two;
    two.workers = 2;
    DestructionWorld::Config det;
    det.workers = 2;
    det.deterministic = true;
    const auto a = pieceHashes(one);
    EXPECT_FALSE(a.empty());
    EXPECT_EQ(a, pieceHashes(two));
    EXPECT_EQ(a, pieceHashes(det));
    // Rough cut faces (docs/roughness.md): their own pieces, the same on 1 and 2 workers.
    const Roughness concrete = roughnessPreset("concrete");
    const auto rough = pieceHashes(one, concrete);
    EXPECT_FALSE(rough.empty());
    EXPECT_NE(a, rough);
    EXPECT_EQ(rough, pieceHashes(two, concrete));
    EXPECT_EQ(rough, pieceHashes(det, concrete));
}

TEST(DestructionWorld, DestroyWithJobsInFlight) {
    {
        DestructionWorld::Config cfg;
        cfg.workers = 1;
        DestructionWorld w(cfg);
        for (int i = 0; i < 3; ++i) {
            auto id = w.addObject(boxDesc()).value();
            w.submitImpact(id, centreHit());
        }
    }
    SUCCEED();
}

TEST(DestructionWorld, RemoveObjectRecordsItsWaitingImpacts) {
    HeldJobs jobs;
    DestructionWorld w(heldConfig(jobs));
    auto id = w.addObject(boxDesc()).value();
    ASSERT_TRUE(w.submitImpact(id, centreHit())); // runs
    Impact j = centreHit();
    j.point = {1, 0, 0};
    ASSERT_TRUE(w.submitImpact(id, j)); // waits
    ASSERT_TRUE(w.submitImpact(id, j)); // waits
    w.removeObject(id);
    ASSERT_EQ(w.timings().size(), 1u); // the two waiting impacts, recorded at once
    EXPECT_TRUE(w.timings()[0].stale);
    EXPECT_EQ(w.timings()[0].impactsMerged, 2);
    EXPECT_EQ(w.timings()[0].object, id);
    jobs.runAll();
    w.beginFrame();
    EXPECT_TRUE(collectAndCommit(w).empty());
    EXPECT_EQ(w.jobsInFlight(), 0);
    ASSERT_EQ(w.timings().size(), 2u); // and the running job, discarded as stale
    EXPECT_TRUE(w.timings()[1].stale);
    EXPECT_EQ(w.timings()[1].impactsMerged, 1);
}

TEST(DestructionWorld, DeterministicModeAdoptsExactlyDelayFramesAfterLaunch) {
    DestructionWorld::Config cfg;
    cfg.workers = 2;
    cfg.deterministic = true;
    cfg.delayFrames = 3;
    DestructionWorld w(cfg);
    auto id = w.addObject(boxDesc()).value();
    ASSERT_TRUE(w.submitImpact(id, centreHit())); // frame 0
    Impact j = centreHit();
    j.point = {1, 0.2, 0.1};
    j.normal = {1, 0, 0};
    ASSERT_TRUE(w.submitImpact(id, j)); // waits for the first job
    w.waitIdle();                       // ready long before it is due
    std::vector<std::uint64_t> adoptedAt;
    for (int f = 0; f < 12; ++f) {
        w.beginFrame();
        for (const auto& o : collectAndCommit(w)) {
            (void)o;
            adoptedAt.push_back(w.frame());
        }
        w.waitIdle();
    }
    // the first at frame 3; the waiting impact is forwarded to a piece at frame 3 and adopted 3 frames later
    ASSERT_EQ(adoptedAt.size(), 2u);
    EXPECT_EQ(adoptedAt[0], 3u);
    EXPECT_EQ(adoptedAt[1], 6u);
}

TEST(DestructionWorld, JobsOutlivingTheWorldAreHarmless) {
    HeldJobs jobs; // a foreign job system that runs the jobs after the world is gone
    {
        DestructionWorld w(heldConfig(jobs));
        for (int i = 0; i < 3; ++i) {
            auto id = w.addObject(boxDesc()).value();
            ASSERT_TRUE(w.submitImpact(id, centreHit()));
        }
        ASSERT_EQ(jobs.held.size(), 3u);
    }
    jobs.runAll(); // must neither crash nor touch freed memory (checked under ASan/TSan)
    SUCCEED();
}

TEST(DestructionWorld, EveryAcceptedImpactEndsInExactlyOneRecord) {
    // Random submissions and removals on a real pool: after draining, the records account for every accepted
    // impact (adopted, merged, forwarded to pieces, stale or dropped with its object).
    DestructionWorld::Config cfg;
    cfg.workers = 2;
    DestructionWorld w(cfg);
    Rng rng(5);
    for (int i = 0; i < 3; ++i)
        ASSERT_TRUE(w.addObject(boxDesc()));
    int accepted = 0;
    for (int f = 0; f < 40; ++f) {
        const auto ids = w.objects();
        if (ids.empty())
            break;
        const ObjectId id = ids[rng.below(ids.size())];
        const Aabb b = w.object(id)->mesh.bounds();
        Impact im;
        im.point = b.center();
        im.normal = {0, 0, 1};
        im.impulse = 10;
        if (w.submitImpact(id, im))
            ++accepted;
        if (rng.uniform(0, 1) < 0.15)
            w.removeObject(ids.front());
        w.beginFrame();
        collectAndCommit(w);
    }
    for (int round = 0; round < 50 && w.jobsInFlight() > 0; ++round) {
        w.waitIdle();
        w.beginFrame();
        collectAndCommit(w);
    }
    EXPECT_EQ(w.jobsInFlight(), 0);
    int recorded = 0;
    for (const auto& r : w.timings())
        recorded += r.impactsMerged;
    EXPECT_GT(accepted, 10);
    EXPECT_EQ(recorded, accepted);
}

// Soak (issue #7): a long run must not leave state behind. Chained fractures where the caller keeps only the
// largest piece (like the bridge's piece cap) leave exactly one live object and one timing record per job.
TEST(DestructionWorld, RemovedPiecesLeaveNoStateBehindOverChainedFractures) {
    HeldJobs jobs;
    DestructionWorld w(heldConfig(jobs));
    ObjectId live = w.addObject(boxDesc()).value();
    const double v0 = w.object(live)->mass.volume;
    double removed = 0, dropped = 0;
    int fractures = 0;
    const int rounds = 25;
    for (int r = 0; r < rounds; ++r) {
        const Aabb b = w.object(live)->mesh.bounds();
        Impact i;
        i.point = {0.5 * (b.lo.x + b.hi.x), 0.5 * (b.lo.y + b.hi.y), b.hi.z};
        i.normal = {0, 0, 1};
        i.impulse = 10;
        ASSERT_TRUE(w.submitImpact(live, i)) << "round " << r;
        jobs.runAll();
        w.beginFrame();
        auto out = collectAndCommit(w);
        ASSERT_LE(out.size(), 1u);
        EXPECT_EQ(w.timings().size(), static_cast<std::size_t>(r + 1)) << "one record per job, no more";
        if (out.empty())
            continue; // a failed job leaves the object as it was
        ++fractures;
        dropped += out[0].droppedVolume;
        ASSERT_FALSE(out[0].pieces.empty());
        ObjectId largest = out[0].pieces.front().id;
        for (const ObjectId p : ids(out[0]))
            if (w.object(p)->mass.volume > w.object(largest)->mass.volume)
                largest = p;
        for (const ObjectId p : ids(out[0]))
            if (p != largest) {
                removed += w.object(p)->mass.volume;
                w.removeObject(p);
            }
        live = largest;
        EXPECT_EQ(w.objects().size(), 1u) << "round " << r;
    }
    EXPECT_GE(fractures, rounds / 2);
    EXPECT_NEAR(w.object(live)->mass.volume + removed + dropped, v0, 1e-9 * v0);
}

// Idle adoption: a finished job is reported to the waiting main thread, which can adopt it in the same frame.
TEST(DestructionWorld, WaitForResultReportsAFinishedJobForAdoptionInTheSameFrame) {
    DestructionWorld::Config cfg;
    cfg.workers = 1;
    DestructionWorld w(cfg);
    const auto soon = [] { return std::chrono::steady_clock::now() + std::chrono::minutes(1); };
    EXPECT_FALSE(w.waitForResult(soon())) << "nothing in flight: returns at once";
    auto id = w.addObject(boxDesc()).value();
    w.beginFrame();
    ASSERT_TRUE(w.submitImpact(id, centreHit()));
    ASSERT_TRUE(w.waitForResult(soon()));
    const auto out = collectAndCommit(w); // no beginFrame in between: the frame of the impact
    ASSERT_EQ(out.size(), 1u);
    EXPECT_EQ(out[0].parent, id);
    ASSERT_EQ(w.timings().size(), 1u);
    EXPECT_EQ(w.timings()[0].frame, w.frame());
    EXPECT_FALSE(w.waitForResult(soon()));
}

TEST(DestructionWorld, WaitForResultTimesOutWhileTheJobHasNotRun) {
    HeldJobs jobs;
    DestructionWorld w(heldConfig(jobs));
    auto id = w.addObject(boxDesc()).value();
    ASSERT_TRUE(w.submitImpact(id, centreHit()));
    EXPECT_FALSE(w.waitForResult(std::chrono::steady_clock::now() + std::chrono::milliseconds(20)));
    EXPECT_FALSE(w.waitForResult(std::chrono::steady_clock::now() - std::chrono::seconds(1))); // a poll
    jobs.runAll();
    EXPECT_TRUE(w.waitForResult(std::chrono::steady_clock::now() - std::chrono::seconds(1)));
    EXPECT_EQ(collectAndCommit(w).size(), 1u);
}

TEST(DestructionWorld, WaitForResultIsAlwaysFalseInDeterministicMode) {
    DestructionWorld::Config cfg;
    cfg.workers = 1;
    cfg.deterministic = true;
    cfg.delayFrames = 2;
    DestructionWorld w(cfg);
    auto id = w.addObject(boxDesc()).value();
    ASSERT_TRUE(w.submitImpact(id, centreHit()));
    w.waitIdle(); // finished, but not due before frame 2
    EXPECT_FALSE(w.waitForResult(std::chrono::steady_clock::now() + std::chrono::minutes(1)));
    w.beginFrame();
    EXPECT_TRUE(collectAndCommit(w).empty());
    EXPECT_TRUE(collectAndCommit(w).empty()) << "collect() again in the same frame adopts nothing early";
    w.beginFrame();
    EXPECT_EQ(collectAndCommit(w).size(), 1u);
}

// An impact that waited on an in-flight job is re-targeted to the nearest piece; when its point lies deep in
// the crater the first job cut, farther from the remaining surface than its own cell reaches, its cells miss
// the mesh: a miss (the object stays), not a geometry failure.
TEST(DestructionWorld, ReTargetedImpactInTheCraterBreaksTheCraterWall) {
    HeldJobs jobs;
    DestructionWorld w(heldConfig(jobs));
    ObjectDesc d = boxDesc();  // [-1, 1]^3
    d.fracture.seedPoints = 0; // the cell is the whole domain: a cube of edge sizeFor(impulse) at the point
    d.fracture.sizeLaw.base = 0.05;
    d.fracture.sizeLaw.scale = 0.05;
    auto id = w.addObject(d).value();
    Impact big = centreHit(); // (0, 0, 1)
    big.impulse = 400;        // cube of edge 1.05: everything within 0.525 of the point is cut away
    ASSERT_TRUE(w.submitImpact(id, big));
    Impact small = centreHit();
    small.point = {0, 0, 0.9};              // in the crater, ≥ 0.425 from what remains
    small.impulse = 1;                      // cube of edge 0.1: reaches 0.1 at most, from the crater's wall
    ASSERT_TRUE(w.submitImpact(id, small)); // waits for the first job
    jobs.runAll();
    w.beginFrame();
    const auto out = collectAndCommit(w);
    ASSERT_EQ(out.size(), 1u);
    ObjectId largest = 0;
    for (const ObjectId p : ids(out[0]))
        if (!largest || w.object(p)->mass.volume > w.object(largest)->mass.volume)
            largest = p;
    const double remainder = w.object(largest)->mass.volume;
    ASSERT_EQ(w.jobsInFlight(), 1); // the waiting impact, re-targeted
    jobs.runAll();
    w.beginFrame();
    const auto again = collectAndCommit(w);
    ASSERT_EQ(again.size(), 1u) << "the impact moved onto the nearest surface: the crater's wall";
    ASSERT_EQ(w.timings().size(), 2u);
    const TimingRecord& r = w.timings()[1];
    EXPECT_EQ(r.object, largest) << "re-targeted to the remainder, whose bounds contain the point";
    EXPECT_FALSE(r.missed);
    EXPECT_FALSE(r.failed);
    EXPECT_GE(r.pieces, 2);
    double v = again[0].droppedVolume;
    for (const ObjectId p : ids(again[0]))
        v += w.object(p)->mass.volume;
    EXPECT_NEAR(v, remainder, 1e-9 * remainder);
}

// An impact farther from the mesh than the object's own size is no contact: its job is a miss (not a failure)
// and the object stays as it was.
TEST(DestructionWorld, AnImpactFarFromTheObjectIsAMissNotAFailure) {
    HeldJobs jobs;
    DestructionWorld w(heldConfig(jobs));
    auto id = w.addObject(boxDesc()).value(); // [-1, 1]^3, diagonal 3.46
    const std::uint64_t hash = w.object(id)->mesh.hash();
    Impact far = centreHit();
    far.point = {0, 0, 6}; // 5 from the top face
    ASSERT_TRUE(w.submitImpact(id, far));
    jobs.runAll();
    w.beginFrame();
    EXPECT_TRUE(collectAndCommit(w).empty());
    ASSERT_EQ(w.timings().size(), 1u);
    EXPECT_TRUE(w.timings()[0].missed);
    EXPECT_FALSE(w.timings()[0].failed);
    EXPECT_EQ(w.timings()[0].pieces, 0);
    ASSERT_NE(w.object(id), nullptr) << "a miss leaves the object as it was";
    EXPECT_EQ(w.object(id)->mesh.hash(), hash);
}

// A piece hit again and again cannot grow without bound: once its mesh has more triangles than
// max(crumbleTriangles, twice the object's original count), a hit crumbles it into a few large pieces.
TEST(DestructionWorld, AnObjectOverItsTriangleLimitCrumbles) {
    HeldJobs jobs;
    DestructionWorld::Config c = heldConfig(jobs);
    c.crumbleTriangles = 1;
    DestructionWorld w(c);
    ObjectId live = w.addObject(boxDesc()).value();
    const std::size_t limit = w.object(live)->crumbleAbove;
    EXPECT_EQ(limit, 2 * w.object(live)->mesh.triangleCount());
    const double v0 = w.object(live)->mass.volume;
    double elsewhere = 0;
    int crumbles = 0;
    for (int r = 0; r < 60 && crumbles == 0; ++r) {
        const ObjectState* o = w.object(live);
        const bool over = o->mesh.triangleCount() > limit;
        const double before = o->mass.volume;
        const Aabb b = o->mesh.bounds();
        Impact i;
        i.point = {b.lo.x + (b.hi.x - b.lo.x) * (0.2 + 0.6 * ((r * 7) % 10) / 10.0),
                   b.lo.y + (b.hi.y - b.lo.y) * (0.2 + 0.6 * ((r * 3) % 10) / 10.0), b.hi.z};
        i.normal = {0, 0, 1};
        i.impulse = 10;
        ASSERT_TRUE(w.submitImpact(live, i));
        jobs.runAll();
        w.beginFrame();
        auto out = collectAndCommit(w);
        if (out.empty())
            continue;
        EXPECT_EQ(w.timings().back().crumbled, over) << "round " << r;
        ObjectId largest = out[0].pieces.front().id;
        for (const ObjectId p : ids(out[0])) {
            EXPECT_EQ(w.object(p)->crumbleAbove, limit) << "pieces inherit the limit";
            if (w.object(p)->mass.volume > w.object(largest)->mass.volume)
                largest = p;
        }
        elsewhere += out[0].droppedVolume;
        if (over) {
            ++crumbles;
            EXPECT_GE(out[0].pieces.size(), 2u);
            EXPECT_LT(w.object(largest)->mass.volume, 0.9 * before) << "no piece keeps most of it";
        }
        for (const ObjectId p : ids(out[0]))
            if (p != largest) {
                elsewhere += w.object(p)->mass.volume;
                w.removeObject(p);
            }
        live = largest;
    }
    EXPECT_EQ(crumbles, 1);
    EXPECT_NEAR(w.object(live)->mass.volume + elsewhere, v0, 1e-9 * v0);

    DestructionWorld::Config never = heldConfig(jobs);
    never.crumbleTriangles = 0;
    DestructionWorld w2(never);
    EXPECT_EQ(w2.object(w2.addObject(boxDesc()).value())->crumbleAbove,
              std::numeric_limits<std::size_t>::max());
}

// A long game does not accumulate timing records forever: the latest keepTimings .. 2 × keepTimings stay.
TEST(DestructionWorld, TimingRecordsKeepOnlyTheLatest) {
    HeldJobs jobs;
    DestructionWorld::Config c = heldConfig(jobs);
    c.keepTimings = 3;
    DestructionWorld w(c);
    auto id = w.addObject(boxDesc()).value();
    Impact far = centreHit();
    far.point = {0, 0, 6}; // a miss: one record per job, the object stays
    for (int i = 0; i < 20; ++i) {
        ASSERT_TRUE(w.submitImpact(id, far));
        jobs.runAll();
        w.beginFrame();
        collectAndCommit(w);
        ASSERT_GE(w.timings().size(), std::min<std::size_t>(3, static_cast<std::size_t>(i + 1)));
        ASSERT_LE(w.timings().size(), 6u);
        EXPECT_EQ(w.timings().back().frame + 1, w.frame()) << "the latest is kept (submitted last frame)";
        EXPECT_EQ(w.firstTimingRecord() + w.timings().size(), static_cast<std::uint64_t>(i + 1))
            << "sequence numbers count every record of the game";
    }
}

// The stages of a record follow one another: their sum is the total, up to the few microseconds of
// bookkeeping between them. On a 19,200-triangle box, work left out of every stage (the input check, the
// pieces' frames and mass properties were untimed once: about 1.5 ms here) would break the bound.
double stageSum(const TimingRecord& r) {
    return r.queueMs + r.prepareMs + r.cellMs + r.booleanMs + r.islandsMs + r.decompositionMs + r.finishMs +
           r.handoffMs + r.adoptionMs;
}

// Checks that the stages do not overlap; returns the time outside every stage (preemption included).
double expectStagesAddUp(const TimingRecord& r) {
    for (double stage : {r.queueMs, r.prepareMs, r.cellMs, r.booleanMs, r.islandsMs, r.decompositionMs,
                         r.finishMs, r.handoffMs, r.adoptionMs})
        EXPECT_GE(stage, 0);
    EXPECT_LE(stageSum(r), r.totalMs + 1e-9) << "stages overlap";
    return r.totalMs - stageSum(r);
}

ObjectDesc fineBoxDesc() {
    ObjectDesc d = boxDesc();
    d.mesh = makeSubdividedBox({-1, -1, -1}, {1, 1, 1}, 40); // 19,200 triangles
    return d;
}

TEST(DestructionWorld, TimingStagesAddUpToTheTotal) {
    using namespace std::chrono_literals;
    HeldJobs jobs;
    DestructionWorld w(heldConfig(jobs));
    auto id = w.addObject(fineBoxDesc()).value();
    ASSERT_TRUE(w.submitImpact(id, centreHit()));
    std::this_thread::sleep_for(5ms); // waiting for a worker
    jobs.runAll();
    std::this_thread::sleep_for(5ms); // finished, waiting for the main thread
    w.beginFrame();
    auto out = collectAndCommit(w);
    ASSERT_EQ(out.size(), 1u);
    ASSERT_EQ(w.timings().size(), 1u);
    const TimingRecord& r = w.timings()[0];
    EXPECT_GE(r.queueMs, 5);
    EXPECT_GE(r.handoffMs, 5);
    EXPECT_GT(r.prepareMs, 0) << "the input check and the move onto the surface are timed";
    EXPECT_GT(r.finishMs, 0) << "the pieces' frames and mass properties are timed";
    double smallestGap = expectStagesAddUp(r);

    // Merged impacts (cells of several impacts cut in one job): the cells are timed by the runtime.
    const ObjectId piece = out[0].pieces.front().id;
    Impact a = centreHit(), b = centreHit();
    a.point = {0, 0, 0}; // snapped onto the piece's surface
    b.point = {0.5, 0.5, 0};
    ASSERT_TRUE(w.submitImpact(piece, a));
    ASSERT_TRUE(w.submitImpact(piece, b)); // waits on the first job
    jobs.runAll();
    w.beginFrame();
    collectAndCommit(w); // the first job; the waiting impact runs now on the largest piece near it
    jobs.runAll();
    w.beginFrame();
    collectAndCommit(w);
    ASSERT_EQ(w.timings().size(), 3u);
    for (const TimingRecord& t : w.timings())
        if (!t.stale && !t.missed && !t.failed)
            smallestGap = std::min(smallestGap, expectStagesAddUp(t));
    EXPECT_LT(smallestGap, 0.25) << "time outside every stage, in every record";
}

// A split changes the world only when it is committed (after the engine made its bodies): until then the
// parent stays and impacts on it wait; commit replaces it by the pieces once, sends the waiting impacts to
// them and ends the timing record there.
TEST(DestructionWorld, CommitReplacesTheParentOnceAndEndsTheRecord) {
    using namespace std::chrono_literals;
    HeldJobs jobs;
    DestructionWorld w(heldConfig(jobs));
    auto id = w.addObject(boxDesc()).value();
    ASSERT_TRUE(w.submitImpact(id, centreHit()));
    jobs.runAll();
    w.beginFrame();
    const std::uint64_t hash = w.geometryHash();
    auto out = w.collect();
    ASSERT_EQ(out.size(), 1u);
    ASSERT_GE(out[0].pieces.size(), 2u);
    EXPECT_NE(w.object(id), nullptr) << "the parent stays until the split is committed";
    for (const AdoptedPiece& p : out[0].pieces)
        EXPECT_EQ(w.object(p.id), nullptr);
    EXPECT_EQ(w.geometryHash(), hash);
    ASSERT_TRUE(w.submitImpact(id, centreHit()));
    EXPECT_EQ(w.jobsInFlight(), 0) << "an impact on an uncommitted parent waits for the split";
    const TimingRecord before = w.timings().back();
    std::this_thread::sleep_for(10ms); // the engine builds the pieces' bodies
    w.commit(out[0]);
    EXPECT_EQ(w.object(id), nullptr);
    for (const AdoptedPiece& p : out[0].pieces)
        EXPECT_EQ(w.object(p.id), p.state.get());
    EXPECT_NE(w.geometryHash(), hash);
    EXPECT_EQ(w.jobsInFlight(), 1) << "the waiting impact went to a piece";
    const TimingRecord after = w.timings().back();
    EXPECT_GE(after.adoptionMs - before.adoptionMs, 10);
    EXPECT_NEAR(after.totalMs - before.totalMs, after.adoptionMs - before.adoptionMs, 1e-9);
    (void)expectStagesAddUp(after);
    const std::vector<ObjectId> objects = w.objects();
    w.commit(out[0]); // twice: no effect
    EXPECT_EQ(w.objects(), objects);
    EXPECT_EQ(w.timings().back().totalMs, after.totalMs);
    EXPECT_EQ(w.jobsInFlight(), 1);

    // A parent removed before its split is committed: the split is dropped, its record stale.
    jobs.runAll();
    w.beginFrame();
    const auto dropped = w.collect();
    ASSERT_EQ(dropped.size(), 1u);
    w.removeObject(dropped[0].parent);
    EXPECT_TRUE(w.timings().back().stale);
    w.commit(dropped[0]);
    for (const AdoptedPiece& p : dropped[0].pieces)
        EXPECT_EQ(w.object(p.id), nullptr);
    EXPECT_EQ(w.object(dropped[0].parent), nullptr);
}

} // namespace
} // namespace rubble
