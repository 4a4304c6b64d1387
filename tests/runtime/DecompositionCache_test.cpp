// The in-memory DecompositionCache is bounded (issue #7, soak): DestructionWorld keeps one for the life of
// the world and adds an entry for every object added without convex parts.
#include <atomic>

#include <gtest/gtest.h>

#include "TestSupport.hpp"
#include "rubble/collision/ConvexDecomposition.hpp"
#include "rubble/core/ThreadPool.hpp"
#include "rubble/runtime/DestructionWorld.hpp"

namespace rubble {
namespace {

Mesh boxOfWidth(int i) {
    const double w = 1.0 + 0.25 * i;
    return makeSubdividedBox({0, 0, 0}, {w, 1, 1}, 1);
}

/// A job system that counts the jobs it passes on to a pool.
class CountingJobs final : public JobSystem {
public:
    void submit(std::function<void()> job) override {
        ++submitted;
        pool.submit(std::move(job));
    }
    int workerCount() const override { return pool.workerCount(); }
    std::atomic<int> submitted{0};
    ThreadPool pool{1};
};

TEST(DecompositionCacheBound, AWorldDecomposesAnAddedObjectOnItsOwnWorkers) {
    CountingJobs jobs;
    DestructionWorld::Config config;
    config.jobs = &jobs;
    DestructionWorld world(config);
    ObjectDesc desc;
    desc.mesh = makeTorus({0, 0, 0}, 1.0, 0.3, 24, 10); // concave: the search tries cuts
    auto id = world.addObject(desc);
    ASSERT_TRUE(id) << id.error().message;
    EXPECT_GT(world.object(*id)->convexParts.size(), 1u);
    EXPECT_GT(jobs.submitted.load(), 0) << "the decomposition ran on the calling thread alone";
}

TEST(DecompositionCacheBound, EntriesNeverExceedCapacityAfterManyDistinctMeshes) {
    DecompositionCache cache({}, 4);
    EXPECT_EQ(cache.capacity(), 4u);
    for (int i = 0; i < 40; ++i) {
        ASSERT_TRUE(cache.get(boxOfWidth(i)));
        EXPECT_LE(cache.size(), 4u) << "after " << i + 1 << " distinct meshes";
    }
    EXPECT_EQ(cache.size(), 4u);
    EXPECT_EQ(cache.hits(), 0u); // every mesh was distinct
}

TEST(DecompositionCacheBound, EvictsLeastRecentlyUsed) {
    DecompositionCache cache({}, 3);
    for (int i = 0; i < 3; ++i)
        ASSERT_TRUE(cache.get(boxOfWidth(i)));
    ASSERT_TRUE(cache.get(boxOfWidth(0))); // 0 is now the most recent; 1 the least
    EXPECT_EQ(cache.hits(), 1u);
    ASSERT_TRUE(cache.get(boxOfWidth(3))); // evicts 1
    EXPECT_EQ(cache.size(), 3u);
    for (int i : {0, 2, 3})
        ASSERT_TRUE(cache.get(boxOfWidth(i)));
    EXPECT_EQ(cache.hits(), 4u); // 0, 2 and 3 were still held
    ASSERT_TRUE(cache.get(boxOfWidth(1)));
    EXPECT_EQ(cache.hits(), 4u); // 1 was evicted: recomputed, not a hit
    EXPECT_EQ(cache.size(), 3u);
}

TEST(DecompositionCacheBound, EvictedEntryIsRecomputedIdentically) {
    DecompositionCache cache({}, 1);
    auto first = cache.get(boxOfWidth(0));
    ASSERT_TRUE(first);
    ASSERT_TRUE(cache.get(boxOfWidth(1)));
    auto again = cache.get(boxOfWidth(0));
    ASSERT_TRUE(again);
    EXPECT_EQ(cache.hits(), 0u);
    ASSERT_EQ(first->parts.size(), again->parts.size());
    EXPECT_DOUBLE_EQ(first->hullVolume, again->hullVolume);
    EXPECT_DOUBLE_EQ(first->meshVolume, again->meshVolume);
}

TEST(DecompositionCacheBound, ZeroCapacityHoldsOne) {
    DecompositionCache cache({}, 0);
    EXPECT_EQ(cache.capacity(), 1u);
    ASSERT_TRUE(cache.get(boxOfWidth(0)));
    ASSERT_TRUE(cache.get(boxOfWidth(0)));
    EXPECT_EQ(cache.hits(), 1u);
    EXPECT_EQ(cache.size(), 1u);
}

} // namespace
} // namespace rubble
