// ImpactCollector: the collision fracture budget (ImpactPolicy::collisionFracturesPerSecond).

#include <gtest/gtest.h>

#include <map>
#include <memory>
#include <set>
#include <vector>

#include "ToyPhysics.hpp"
#include "rubble/geometry/Mesh.hpp"
#include "rubble/runtime/DestructionWorld.hpp"
#include "runtime/BodyTable.hpp"
#include "runtime/ImpactCollector.hpp"

namespace rubble {
namespace {

// Five moving pieces (bodies 1-5), each landing on static scenery (body 100) every frame, harder by id.
struct LandingRig {
    LandingRig() {
        DestructionWorld::Config wc;
        wc.workers = 1;
        wc.deterministic = true;
        world = std::make_unique<DestructionWorld>(wc);
        BodyDesc ground;
        physics.createBody(100, ground);
        BodyRecord g;
        g.id = 100;
        g.role = BodyRole::Scenery;
        g.motion = BodyMotionState::Static;
        bodies.insert(g);
        for (BodyId id = 1; id <= 5; ++id) {
            ObjectDesc d;
            d.mesh = makeBox({-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5});
            d.impulseThreshold = 1;
            const Result<ObjectId> object = world->addObject(std::move(d));
            EXPECT_TRUE(object);
            BodyDesc b;
            b.mass = 1000;
            b.transform.translation = {3.0 * static_cast<double>(id), 1, 0};
            physics.createBody(id, b);
            BodyRecord r;
            r.id = id;
            r.role = BodyRole::Piece;
            r.motion = BodyMotionState::Dynamic;
            r.hasObject = true;
            r.object = object ? *object : 0;
            r.volume = 1;
            bodies.insert(r);
            objectOf[r.object] = id;
            ContactReport c;
            c.a = id;
            c.b = 100;
            c.pointOnA = c.pointOnB = b.transform.translation - Vec3{0, 0.5, 0};
            c.normalOnB = {0, 1, 0};
            c.relativeVelocity = {0, -8, 0};
            c.impulse = 3000 + 1000 * static_cast<double>(id);
            contacts.push_back(c);
        }
    }
    // The bodies whose impacts one frame of landings lets through.
    std::vector<BodyId> frame(detail::ImpactCollector& collector, int& overBudget) {
        collector.gather(contacts, bodies, *world, physics, 100, 1.0, {});
        const detail::ImpactBatch batch = collector.take(1.0 / 60);
        overBudget += batch.collisionsOverBudget;
        std::vector<BodyId> out;
        for (const detail::PendingImpact& p : batch.impacts)
            out.push_back(objectOf.at(p.object));
        return out;
    }
    test::ToyPhysics physics;
    std::unique_ptr<DestructionWorld> world;
    detail::BodyTable bodies;
    std::vector<ContactReport> contacts;
    std::map<ObjectId, BodyId> objectOf;
};

TEST(ImpactCollector, CollisionFracturesStayWithinTheirBudgetStrongestFirst) {
    ImpactPolicy policy;
    policy.graceFrames = 0;
    LandingRig rig;
    {
        detail::ImpactCollector unlimited(policy);
        int over = 0;
        EXPECT_EQ(rig.frame(unlimited, over).size(), 5u) << "no budget: every landing";
        EXPECT_EQ(over, 0);
    }
    policy.collisionFracturesPerSecond = 6; // a quarter second's worth, 1.5, may be saved up
    detail::ImpactCollector collector(policy);
    int over = 0;
    std::size_t taken = 0;
    const std::vector<BodyId> first = rig.frame(collector, over);
    ASSERT_EQ(first.size(), 1u) << "the saved-up 1.5 allow one";
    EXPECT_EQ(first[0], 5) << "the strongest landing";
    taken += first.size();
    for (int f = 1; f < 120; ++f) { // two seconds in all
        const std::vector<BodyId> got = rig.frame(collector, over);
        ASSERT_LE(got.size(), 1u);
        if (!got.empty()) {
            EXPECT_EQ(got[0], 5);
        }
        taken += got.size();
    }
    EXPECT_GE(taken, 12u) << "6 a second";
    EXPECT_LE(taken, 14u) << "6 a second plus what was saved up";
    EXPECT_EQ(static_cast<std::size_t>(over) + taken, 5u * 120) << "the rest are counted, not submitted";
}

} // namespace
} // namespace rubble
