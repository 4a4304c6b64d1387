// The debris governor's physics-time control, fed known step times (no wall clock), its light pieces and
// its wakes.
#include <gtest/gtest.h>

#include <set>

#include "ToyPhysics.hpp"
#include "rubble/geometry/Mesh.hpp"
#include "rubble/runtime/DestructionWorld.hpp"
#include "runtime/BodyTable.hpp"
#include "runtime/DebrisGovernor.hpp"
#include "runtime/ImpactCollector.hpp"

namespace rubble {
namespace {

test::ToyPhysics::Config toyConfig(bool filtersPairs) {
    test::ToyPhysics::Config c;
    c.filtersPairs = filtersPairs;
    return c;
}

// Falling pieces (forty by default), and a governor over them.
struct GovernorRig {
    explicit GovernorRig(double budgetMs, int pieces = 40, bool filtersPairs = false)
        : physics(toyConfig(filtersPairs)) {
        budget.maxAwakeBodies = 50;
        budget.physicsBudgetMs = budgetMs;
        for (BodyId id = 1; id <= static_cast<BodyId>(pieces); ++id) {
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
            (void)governor.update(bodies, physics, {}, ms, deterministic, Vec3{}, 1.0 / 60);
        return governor.awakeBudget();
    }
    // One frame whose step took `ms`, its decisions applied as the runtime does; returns the retirements.
    int apply(double ms, bool deterministic) {
        const detail::GovernorActions a =
            governor.update(bodies, physics, {}, ms, deterministic, Vec3{}, 1.0 / 60);
        for (BodyId id : a.lighten)
            physics.setCollidesWithMoving(id, false);
        for (const auto& [id, why] : a.retire) {
            EXPECT_EQ(why, detail::RetireReason::Awake);
            governor.removed(id);
            bodies.erase(id);
            physics.removeBody(id);
        }
        return static_cast<int>(a.retire.size());
    }

    DebrisBudget budget;
    test::ToyPhysics physics;
    detail::BodyTable bodies;
    detail::DebrisGovernor governor{budget};
};

TEST(DebrisGovernor, AFrameOverThePhysicsBudgetShrinksTheAwakeBudgetUnlessItIsALoneSpike) {
    GovernorRig rig(8);
    EXPECT_EQ(rig.run(5, 2), 50);
    EXPECT_EQ(rig.run(1, 9), 50) << "one spike over a cheap average: a stall, not a load";
    EXPECT_EQ(rig.run(1, 2), 50);
    EXPECT_EQ(rig.run(2, 9), 36) << "two in a row: 90 % of the 40 awake pieces";
    GovernorRig busy(8);
    EXPECT_EQ(busy.run(30, 5), 50) << "5 ms is inside the band held (55-75 % of 8 ms)";
    EXPECT_EQ(busy.run(1, 9), 36) << "a spike over an average in the band";
}

TEST(DebrisGovernor, AStepCloseToTheBudgetOnAverageShrinksItToLeaveRoomForSpikes) {
    GovernorRig rig(8);
    EXPECT_LT(rig.run(10, 7.5), 40) << "every frame under the budget, but 94 % of it";
}

TEST(DebrisGovernor, TheAwakeBudgetGrowsBackWhenTheStepIsCheap) {
    GovernorRig rig(8);
    const int shrunk = rig.run(2, 12);
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

// A piece launched at `velocity` from 20 m above a ground slab, governed every frame with the default budget:
// the frame it was frozen (-1: never) and its height then.
std::pair<int, double> frozenFrame(const Vec3& velocity) {
    DebrisBudget budget;
    budget.freezeSleeping = false; // the velocity rule alone
    test::ToyPhysics physics;
    detail::BodyTable bodies;
    detail::DebrisGovernor governor{budget};
    BodyDesc ground;
    ground.shape.kind = BodyShape::Kind::Box;
    ground.shape.halfExtents = {50, 0.5, 50};
    ground.transform.translation = {0, -0.5, 0};
    physics.createBody(1, ground);
    BodyDesc d;
    d.shape.kind = BodyShape::Kind::Box;
    d.shape.halfExtents = {0.2, 0.2, 0.2};
    d.mass = 1;
    d.inertia = {1, 1, 1};
    d.transform.translation = {0, 20, 0};
    d.linearVelocity = velocity;
    physics.createBody(2, d);
    BodyRecord r;
    r.id = 2;
    r.role = BodyRole::Piece;
    r.motion = BodyMotionState::Dynamic;
    r.volume = 0.064;
    bodies.insert(r);
    std::vector<ContactReport> contacts;
    for (int frame = 0; frame < 600; ++frame) {
        physics.step(1.0 / 60, contacts);
        const detail::GovernorActions a = governor.update(bodies, physics, {}, 1, true, Vec3{}, 1.0 / 60);
        if (!a.freeze.empty())
            return {frame, physics.motion(2).transform.translation.y};
    }
    return {-1, 0};
}

TEST(DebrisGovernor, APieceFreezesOnlyOnceItRestsNeverInFlight) {
    // From rest it is slower than the freeze speed for its first frames, but gaining g·dt a frame.
    const auto [dropped, droppedAt] = frozenFrame({0, 0, 0});
    ASSERT_GE(dropped, 0);
    EXPECT_LT(droppedAt, 0.25) << "frozen on the ground, not as it started to fall";
    // Thrown straight up, it is slow around the top of its arc for 0.1 s (12 frames at 1 m/s).
    const auto [thrown, thrownAt] = frozenFrame({0, 5, 0});
    ASSERT_GE(thrown, 0);
    EXPECT_LT(thrownAt, 0.25) << "frozen on the ground, not at the top of its arc";
    EXPECT_GT(thrown, dropped);
}

// Moving pieces over the awake budget become light (static bodies only) while there is room for
// lightPerAwake of them per budgeted awake body; only the rest retire, as all do without pair filtering.
TEST(DebrisGovernor, MovingPiecesOverTheBudgetBecomeLightBeforeAnyRetires) {
    for (const bool filters : {true, false}) {
        GovernorRig rig(8, 40, filters);
        rig.budget.maxAwakeBodies = 10;
        rig.budget.lightPerAwake = 2;
        int retired = 0;
        for (int f = 0; f < 30; ++f)
            retired += rig.apply(0, true);
        EXPECT_EQ(retired, filters ? 10 : 30) << filters;
        EXPECT_EQ(rig.governor.light().size(), filters ? 20u : 0u) << filters;
        for (BodyId id : rig.governor.light())
            EXPECT_FALSE(rig.physics.collidesWithMoving(id));
        EXPECT_EQ(rig.bodies.awake(), filters ? 30 : 10) << "the full ones stay within the budget";
    }
}

// A light piece that stays slow but jitters (its velocity flips each frame, so it never rests by the
// velocity rule) is over the awake budget already: once settled, it freezes where it is.
TEST(DebrisGovernor, ASettledLightPieceFreezesEvenWhileItJitters) {
    GovernorRig rig(8, 40, true);
    rig.budget.maxAwakeBodies = 10;
    rig.budget.lightPerAwake = 2;
    for (int f = 0; f < 15; ++f)
        rig.apply(0, true);
    ASSERT_EQ(rig.governor.light().size(), 20u);
    const std::set<BodyId> light = rig.governor.light();
    std::set<BodyId> frozen;
    for (int f = 0; f < 30; ++f) {
        for (BodyId id : rig.bodies.awakeIds())
            rig.physics.setVelocity(id, {0, f % 2 ? 0.3 : -0.3, 0}, {});
        const detail::GovernorActions a =
            rig.governor.update(rig.bodies, rig.physics, {}, 0, true, Vec3{}, 1.0 / 60);
        for (BodyId id : a.freeze) {
            rig.physics.setMass(id, 0, {});
            rig.bodies.setMotion(*rig.bodies.find(id), BodyMotionState::Frozen);
            rig.governor.frozen(id, rig.physics.motion(id).transform.translation, 0.5);
            frozen.insert(id);
        }
    }
    for (BodyId id : light)
        EXPECT_TRUE(frozen.count(id)) << id;
}

// When a slow step shrinks the awake budget, the room for light pieces shrinks with it: light pieces retire.
TEST(DebrisGovernor, LightPiecesRetireWhenTheBudgetShrinks) {
    GovernorRig rig(8, 100, true);
    rig.budget.lightPerAwake = 1;
    for (int f = 0; f < 20; ++f)
        EXPECT_EQ(rig.apply(0, true), 0);
    EXPECT_EQ(rig.governor.light().size(), 50u);
    int retired = 0;
    for (int f = 0; f < 20; ++f)
        retired += rig.apply(100, false);
    EXPECT_EQ(rig.governor.awakeBudget(), 32) << "the floor";
    EXPECT_GT(retired, 0);
    EXPECT_LE(static_cast<int>(rig.governor.light().size()), rig.governor.awakeBudget());
    EXPECT_LE(rig.bodies.awake() - static_cast<int>(rig.governor.light().size()), rig.governor.awakeBudget());
}

// A light piece (over the awake budget) that lands hard on frozen debris neither wakes nor breaks it, nor
// breaks itself: a wake spends awake budget there is none of, and the pieces of a break would be light too.
// The same landing by a piece within the budget does both.
TEST(DebrisGovernor, ALightPieceLandingOnFrozenDebrisNeitherWakesNorBreaksIt) {
    ImpactPolicy policy;
    policy.graceFrames = 0;
    detail::ImpactCollector collector(policy);
    DestructionWorld::Config wc;
    wc.workers = 1;
    wc.deterministic = true;
    DestructionWorld world(wc);
    test::ToyPhysics physics(toyConfig(true));
    detail::BodyTable bodies;
    for (BodyId id : {BodyId{1}, BodyId{2}}) { // 1 falls onto 2, which is frozen
        ObjectDesc d;
        d.mesh = makeBox({-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5});
        d.impulseThreshold = 1;
        const Result<ObjectId> object = world.addObject(std::move(d));
        ASSERT_TRUE(object);
        BodyDesc b;
        b.mass = id == 1 ? 1000 : 0;
        b.transform.translation = {0, id == 1 ? 1.0 : 0.0, 0};
        physics.createBody(id, b);
        BodyRecord r;
        r.id = id;
        r.role = BodyRole::Piece;
        r.motion = id == 1 ? BodyMotionState::Dynamic : BodyMotionState::Frozen;
        r.hasObject = true;
        r.object = *object;
        r.volume = 1;
        bodies.insert(r);
    }
    ContactReport c; // 1 t closing at 8 m/s: 8,000 N·s, over the collision threshold and the wake impulse
    c.a = 1;
    c.b = 2;
    c.pointOnA = c.pointOnB = {0, 0.5, 0};
    c.normalOnB = {0, 1, 0};
    c.relativeVelocity = {0, -8, 0};
    c.impulse = 8000;
    for (const bool light : {false, true}) {
        collector.gather({c}, bodies, world, physics, 100, 1.0,
                         light ? std::set<BodyId>{1} : std::set<BodyId>{});
        const detail::ImpactBatch batch = collector.take(1.0 / 60);
        EXPECT_EQ(batch.frozenHits.count(2), light ? 0u : 1u) << "light " << light;
        EXPECT_EQ(batch.impacts.size(), light ? 0u : 2u) << "light " << light;
    }
}

// Frozen debris that lost its support wakes within the awake budget; the rest waits, frozen, for room: a wake
// over the budget only turns another moving piece light, and its fall through the pile wakes more.
TEST(DebrisGovernor, WhatLostItsSupportWakesOnlyWithinTheAwakeBudget) {
    GovernorRig rig(8, 4); // four falling pieces, ids 1-4
    rig.budget.maxAwakeBodies = 5;
    for (BodyId id = 11; id <= 13; ++id) { // three frozen pieces in a row
        BodyDesc d;
        d.shape.kind = BodyShape::Kind::Box;
        d.transform.translation = {1.0 * id, 0, 0};
        rig.physics.createBody(id, d);
        BodyRecord r;
        r.id = id;
        r.role = BodyRole::Piece;
        r.motion = BodyMotionState::Frozen;
        r.volume = 1;
        rig.bodies.insert(r);
        rig.governor.frozen(id, d.transform.translation, 0.5);
    }
    auto update = [&] {
        const detail::GovernorActions a =
            rig.governor.update(rig.bodies, rig.physics, {}, 0, true, Vec3{}, 1.0 / 60);
        for (BodyId id : a.wake) {
            rig.governor.thawed(id);
            rig.physics.setMass(id, 1, {1, 1, 1});
            rig.bodies.setMotion(*rig.bodies.find(id), BodyMotionState::Dynamic);
        }
        return a.wake;
    };
    rig.governor.wakeNear(Aabb{{10, -1, -1}, {14, 1, 1}}, 0.1); // what they rested on left
    EXPECT_EQ(update(), std::vector<BodyId>{11}) << "4 of 5 awake: room for one";
    EXPECT_EQ(rig.governor.waiting(), (std::set<BodyId>{12, 13}));
    EXPECT_TRUE(update().empty()) << "no room";
    for (BodyId id = 1; id <= 3; ++id) { // three falling pieces leave
        rig.governor.removed(id);
        rig.bodies.erase(id);
        rig.physics.removeBody(id);
    }
    EXPECT_EQ(update(), (std::vector<BodyId>{12, 13}));
    EXPECT_TRUE(rig.governor.waiting().empty());
}

} // namespace
} // namespace rubble
