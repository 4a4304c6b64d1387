// decompose() and the decomposition cache under a DecomposeControl: progress, cancelling, a job system;
// partConcavity's coverage and the concavity of a fracture's pieces.
#include <algorithm>

#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <mutex>
#include <thread>
#include <vector>

#include "TestSupport.hpp"
#include "rubble/collision/DecomposeControl.hpp"
#include "rubble/collision/PartConcavity.hpp"
#include "rubble/fracture/Fracture.hpp"

namespace rubble {
namespace {

/// A job system that runs every job on a thread of its own (joined on destruction).
class ThreadPerJob final : public JobSystem {
public:
    ~ThreadPerJob() override {
        for (std::thread& t : threads_)
            t.join();
    }
    void submit(std::function<void()> job) override {
        const std::lock_guard lock(mutex_);
        ++submitted;
        threads_.emplace_back(std::move(job));
    }
    int workerCount() const override { return 1; }
    int submitted = 0;

private:
    std::mutex mutex_;
    std::vector<std::thread> threads_;
};

/// A job system whose workers are busy: it runs the jobs only when asked, after decompose() returned.
class BusyJobs final : public JobSystem {
public:
    void submit(std::function<void()> job) override { jobs.push_back(std::move(job)); }
    int workerCount() const override { return 2; }
    std::vector<std::function<void()>> jobs;
};

Mesh torus() {
    return makeTorus({0, 0, 0}, 2, 0.5, 32, 12);
}

/// Every corner of every face of every part, in order.
std::vector<double> coordinates(const Decomposition& d) {
    std::vector<double> out;
    for (const ConvexPolytope& p : d.parts)
        for (const PolytopeFaceView& f : p.faces())
            for (const Vec3& c : f.corners)
                out.insert(out.end(), {c.x, c.y, c.z});
    return out;
}

TEST(DecomposeControl, ProgressIsMonotoneAndEndsAtOne) {
    std::vector<double> seen;
    DecomposeControl control;
    control.progress = [&](double f) {
        seen.push_back(f);
        return true;
    };
    auto d = decompose(torus(), {}, control);
    ASSERT_TRUE(d) << d.error().message;
    ASSERT_GE(seen.size(), 3u); // the search's steps, its end and the end
    for (std::size_t i = 0; i < seen.size(); ++i) {
        EXPECT_GT(seen[i], 0.0);
        EXPECT_LE(seen[i], 1.0);
        if (i > 0) {
            EXPECT_GT(seen[i], seen[i - 1]) << i;
        }
    }
    EXPECT_EQ(seen.back(), 1.0);
    EXPECT_EQ(coordinates(d.value()), coordinates(decompose(torus()).value()));
}

TEST(DecomposeControl, CancelFlagOrRefusingCallbackGivesCancelledAndNoParts) {
    std::atomic<bool> cancel{false};
    DecomposeControl byFlag;
    byFlag.cancel = &cancel;
    int calls = 0;
    byFlag.progress = [&](double) {
        ++calls;
        cancel = true; // as Ctrl-C would, from the first report on
        return true;
    };
    auto d = decompose(torus(), {}, byFlag);
    ASSERT_FALSE(d);
    EXPECT_EQ(d.error().code, ErrorCode::Cancelled);
    EXPECT_NE(d.error().message.find("cancelled"), std::string::npos) << d.error().message;
    EXPECT_EQ(calls, 1); // no report after the cancel

    DecomposeControl byCallback;
    std::vector<double> seen;
    byCallback.progress = [&](double f) {
        seen.push_back(f);
        return seen.size() < 2;
    };
    d = decompose(torus(), {}, byCallback);
    ASSERT_FALSE(d);
    EXPECT_EQ(d.error().code, ErrorCode::Cancelled);
    EXPECT_EQ(seen.size(), 2u);
    EXPECT_LT(seen.back(), 1.0);

    // Nothing is left behind: the next call decomposes as if none had been cancelled.
    EXPECT_EQ(coordinates(decompose(torus(), {}, DecomposeControl{}).value()),
              coordinates(decompose(torus()).value()));
}

TEST(DecomposeControl, JobSystemGivesTheSameBytes) {
    const Mesh meshes[] = {torus(), makeTorus({0, 0, 0}, 1, 0.4, 144, 72)}; // exact and proxied search
    for (const Mesh& mesh : meshes) {
        ThreadPerJob jobs;
        DecomposeControl control;
        control.jobs = &jobs;
        auto shared = decompose(mesh, {}, control);
        auto alone = decompose(mesh);
        ASSERT_TRUE(shared && alone);
        EXPECT_GT(shared->parts.size(), 1u);
        EXPECT_GT(jobs.submitted, 0);
        EXPECT_EQ(coordinates(shared.value()), coordinates(alone.value()));
        EXPECT_EQ(shared->hullVolume, alone->hullVolume);
    }
}

TEST(DecomposeControl, BusyJobSystemDoesNotBlockAndLateJobsDoNothing) {
    BusyJobs jobs;
    DecomposeControl control;
    control.jobs = &jobs;
    auto d = decompose(torus(), {}, control);
    ASSERT_TRUE(d);
    EXPECT_EQ(coordinates(d.value()), coordinates(decompose(torus()).value()));
    EXPECT_FALSE(jobs.jobs.empty());
    for (auto& job : jobs.jobs)
        job(); // after the call returned: must not touch its tasks
}

TEST(DecomposeControl, CacheDecomposesUnderControlAndKeepsNoCancelledEntry) {
    const std::filesystem::path dir = test::tempDir("decompose_cache_control");
    DecompositionCache cache(dir);
    std::atomic<bool> cancel{true};
    DecomposeControl cancelled;
    cancelled.cancel = &cancel;
    auto d = cache.get(torus(), {}, cancelled);
    ASSERT_FALSE(d);
    EXPECT_EQ(d.error().code, ErrorCode::Cancelled);
    EXPECT_EQ(cache.size(), 0u);
    EXPECT_TRUE(std::filesystem::is_empty(dir)); // nothing written

    // A miss decomposes with the control's jobs and progress, to the bytes of decompose().
    ThreadPerJob jobs;
    std::vector<double> seen;
    DecomposeControl control;
    control.jobs = &jobs;
    control.progress = [&](double f) {
        seen.push_back(f);
        return true;
    };
    d = cache.get(torus(), {}, control);
    ASSERT_TRUE(d) << d.error().message;
    EXPECT_GT(jobs.submitted, 0);
    ASSERT_GE(seen.size(), 2u);
    EXPECT_EQ(seen.back(), 1.0);
    EXPECT_EQ(coordinates(d.value()), coordinates(decompose(torus()).value()));
    EXPECT_EQ(cache.hits(), 0u);

    // A hit, in memory and then from the file, reports 1 at once (even with the cancel flag set).
    control.cancel = &cancel;
    DecompositionCache fromDisk(dir);
    for (DecompositionCache* which : {&cache, &fromDisk}) {
        seen.clear();
        auto again = which->get(torus(), {}, control);
        ASSERT_TRUE(again);
        EXPECT_EQ(seen, std::vector<double>{1.0});
        EXPECT_EQ(which->hits(), 1u);
        EXPECT_EQ(coordinates(again.value()), coordinates(d.value()));
    }
}

// A 10k-triangle cube bitten near its top face.
const Mesh& bittenCube() {
    static const Mesh cube = makeSubdividedBox({-1, -1, -1}, {1, 1, 1}, 7);
    return cube;
}

Result<FractureResult> biteTheCube() {
    Impact hit;
    hit.point = {0.3, 1, 0.2};
    hit.normal = {0, 1, 0};
    hit.impulse = 40;
    return fracture(bittenCube(), hit, FractureParams{}, 7);
}

TEST(PieceConcavity, AFractureResultCarriesItWhenAsked) {
    const Mesh& cube = bittenCube();
    auto fr = biteTheCube();
    ASSERT_TRUE(fr) << fr.error().message;
    EXPECT_TRUE(fr->concavity.empty()); // opt-in
    auto parts = updateDecomposition(decompose(cube)->parts, *fr);
    parts.back().clear(); // a piece without parts reads -1
    const std::vector<double>& recorded = recordConcavity(*fr, parts);
    EXPECT_EQ(&recorded, &fr->concavity);
    ASSERT_EQ(fr->concavity.size(), fr->pieces.size());
    EXPECT_EQ(fr->concavity, pieceConcavity(*fr, parts));
    EXPECT_EQ(fr->concavity.back(), -1);
    EXPECT_GT(*std::max_element(fr->concavity.begin(), fr->concavity.end()), 0);
}

TEST(PieceConcavity, EveryPieceOfAFractureAsPartConcavity) {
    const Mesh& cube = bittenCube();
    auto fr = biteTheCube();
    ASSERT_TRUE(fr) << fr.error().message;
    ASSERT_GE(fr->pieces.size(), 2u);
    const auto parts = updateDecomposition(decompose(cube)->parts, *fr);
    const std::vector<double> measured = pieceConcavity(*fr, parts);
    ASSERT_EQ(measured.size(), fr->pieces.size());
    for (std::size_t i = 0; i < fr->pieces.size(); ++i) {
        EXPECT_EQ(measured[i], partConcavity(fr->pieces[i].mesh, parts[i])) << i;
        EXPECT_GE(measured[i], 0) << i;
    }
    // The remainder's parts keep its bite open; its convex hull alone covers the bite and scores its depth.
    std::size_t remainder = 0;
    while (remainder < fr->pieces.size() && fr->pieces[remainder].cell >= 0)
        ++remainder;
    ASSERT_LT(remainder, fr->pieces.size());
    std::vector<std::vector<ConvexPolytope>> hullOnly(fr->pieces.size());
    hullOnly[remainder].push_back(convexHull(fr->pieces[remainder].mesh.positions).value());
    const std::vector<double> covered = pieceConcavity(*fr, hullOnly);
    EXPECT_GT(covered[remainder], 2 * measured[remainder] + 0.01);
    for (std::size_t i = 0; i < fr->pieces.size(); ++i)
        if (i != remainder) {
            EXPECT_EQ(covered[i], -1) << i; // no parts: not measured
        }
}

TEST(PartConcavity, SampleOnAPartsFaceIsCovered) {
    // A 2×1×1 box as two unit cubes: every surface sample lies on a face of the part that holds it.
    const Mesh box = makeBox({0, 0, 0}, {2, 1, 1});
    const std::vector<ConvexPolytope> halves = {ConvexPolytope::fromAabb({{0, 0, 0}, {1, 1, 1}}),
                                                ConvexPolytope::fromAabb({{1, 0, 0}, {2, 1, 1}})};
    EXPECT_LT(partConcavity(box, halves), 1e-12);
    // Without the second half, the samples on its side are up to 1 away (of a diagonal of √6).
    const double hole = partConcavity(box, {halves[0]});
    EXPECT_GT(hole, 0.9 / std::sqrt(6.0));
    EXPECT_LE(hole, 1 / std::sqrt(6.0) + 1e-12);
}

} // namespace
} // namespace rubble
