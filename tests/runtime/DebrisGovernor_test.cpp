// The debris governor's physics-time control, fed known step times (no wall clock).
#include <gtest/gtest.h>

#include "ToyPhysics.hpp"
#include "runtime/BodyTable.hpp"
#include "runtime/DebrisGovernor.hpp"

namespace rubble {
namespace {

// Forty falling pieces, and a governor over them.
struct GovernorRig {
    explicit GovernorRig(double budgetMs) {
        budget.maxAwakeBodies = 50;
        budget.physicsBudgetMs = budgetMs;
        for (BodyId id = 1; id <= 40; ++id) {
            BodyDesc d;
            d.shape.kind = BodyShape::Kind::Box;
            d.mass = 1;
            d.inertia = {1, 1, 1};
            d.transform.translation = {1.0 * id, 50, 0};
            d.linearVelocity = {0, -5, 0};
            physics.createBody(id, d);
            BodyRecord r;
            r.id = id;
            r.role = BodyRole::Piece;
            r.motion = BodyMotionState::Dynamic;
            r.volume = 1;
            bodies.insert(r);
        }
    }
    // The awake budget after `frames` frames whose physics step took `ms` each.
    int run(int frames, double ms, bool deterministic = false) {
        for (int i = 0; i < frames; ++i)
            (void)governor.update(bodies, physics, {}, ms, deterministic, Vec3{});
        return governor.awakeBudget();
    }

    DebrisBudget budget;
    test::ToyPhysics physics;
    detail::BodyTable bodies;
    detail::DebrisGovernor governor{budget};
};

TEST(DebrisGovernor, OneFrameOverThePhysicsBudgetShrinksTheAwakeBudget) {
    GovernorRig rig(8);
    EXPECT_EQ(rig.run(5, 2), 50);
    EXPECT_EQ(rig.run(1, 9), 36) << "90 % of the 40 awake pieces";
}

TEST(DebrisGovernor, AStepCloseToTheBudgetOnAverageShrinksItToLeaveRoomForSpikes) {
    GovernorRig rig(8);
    EXPECT_LT(rig.run(10, 7.5), 40) << "every frame under the budget, but 94 % of it";
}

TEST(DebrisGovernor, TheAwakeBudgetGrowsBackWhenTheStepIsCheap) {
    GovernorRig rig(8);
    const int shrunk = rig.run(1, 12);
    EXPECT_LT(shrunk, 40);
    EXPECT_EQ(rig.run(100, 5), shrunk) << "5 ms is inside the band held (55-75 % of 8 ms)";
    EXPECT_GT(rig.run(20, 1), shrunk);
    rig.run(200, 1);
    EXPECT_EQ(rig.governor.awakeBudget(), 50) << "up to the configured maximum";
}

TEST(DebrisGovernor, TimeDoesNotChangeTheBudgetInDeterministicMode) {
    GovernorRig rig(8);
    EXPECT_EQ(rig.run(10, 100, true), 50);
}

} // namespace
} // namespace rubble
