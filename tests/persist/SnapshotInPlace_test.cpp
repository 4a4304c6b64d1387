// A snapshot whose objects are read where the world keeps them: the same state and bytes as a copy's.
#include "persist/SnapshotInPlace.hpp"

#include <gtest/gtest.h>

#include "JournalScene.hpp"

namespace rubble {
namespace {

TEST(SnapshotInPlace, GivesTheBytesOfTheWorldsSnapshotWithoutCopyingItsObjects) {
    test::JournalRig rig(1);
    rig.play(40);
    for (int i = 0; i < 30 && rig.runtime.world().jobsInFlight() == 0; ++i)
        rig.play(1, 1);
    const DestructionWorld& world = rig.runtime.world();
    ASSERT_GT(world.jobsInFlight(), 0) << "work in flight is captured too";
    const std::vector<ObjectPlacement> placements = rig.runtime.placements();
    const Snapshot copied = takeSnapshot(world, placements);
    ASSERT_GT(copied.world.objects.size(), 3u);

    const detail::StateInPlace in = detail::captureInPlace(world);
    EXPECT_TRUE(in.rest.objects.empty());
    ASSERT_EQ(in.objects.size(), copied.world.objects.size());
    for (std::size_t i = 0; i < in.objects.size(); ++i) {
        EXPECT_EQ(in.objects[i], world.object(copied.world.objects[i].id)) << "where the world keeps it";
        EXPECT_NE(in.objects[i]->meshHash, 0u);
    }
    const Snapshot rest{in.rest, placements, {}, {}};
    EXPECT_EQ(detail::encodeSnapshotWith(rest, in.objects), encodeSnapshot(copied)) << "byte for byte";

    // Some of the objects: the bytes of a snapshot holding copies of just those.
    std::vector<const ObjectState*> odd;
    Snapshot some = copied;
    some.world.objects.clear();
    for (const ObjectState* o : in.objects)
        if (o->id % 2 == 1) {
            odd.push_back(o);
            some.world.objects.push_back(*o);
        }
    ASSERT_LT(odd.size(), in.objects.size());
    EXPECT_EQ(detail::encodeSnapshotWith(rest, odd), encodeSnapshot(some));
    Result<Snapshot> decoded =
        decodeSnapshot(encodeSnapshot(some).data(), encodeSnapshot(some).size(), "odd");
    ASSERT_TRUE(decoded) << decoded.error().message;
    EXPECT_EQ(decoded->world.objects.size(), odd.size());
}

} // namespace
} // namespace rubble
