// Cascades on the toy engine: what falls hits and loads what is beneath (docs/structure.md, "Cascades").
#include <gtest/gtest.h>

#include <map>
#include <optional>

#include "StructureRig.hpp"
#include "rubble/runtime/DestructionRuntime.hpp"

namespace rubble {
namespace {

using Rig = test::StructureRig;

// An 850 kg block on two 3 m props over a destructible concrete floor on the ground between them.
struct Drop {
    explicit Drop(const ImpactPolicy& policy) : rig(true, 1, false, 0.6) {
        rig.runtime.setImpactPolicy(policy);
        props = {rig.addBox({-1.7, 0, -0.2}, {-1.3, 3, 0.2}, "concrete"),
                 rig.addBox({1.3, 0, -0.2}, {1.7, 3, 0.2}, "concrete")};
        block = rig.addBox({-1.7, 3, -0.5}, {1.7, 3.5, 0.5}, "concrete");
        floor = rig.addBox({-1, 0, -1}, {1, 0.5, 1}, "concrete", true);
        for (int i = 0; i < 10; ++i)
            rig.runtime.stepFrame();
    }
    // The health of the floor's bond to the ground.
    double floorHealth() const {
        const BodyRecord* f = rig.runtime.bodyOf(floor);
        if (!f)
            return -1;
        for (const StructureBond& b : rig.runtime.structureBonds())
            if (b.a == f->id || b.b == f->id)
                return b.health;
        return -1;
    }
    Rig rig;
    std::vector<ObjectId> props;
    ObjectId block = 0, floor = 0;
};

} // namespace

// The block's 2.5 m fall is an impact on the floor (0.30 of its ground bond's health) only above the policy.
TEST(Cascade, ACollapsingBodyHitsWhatItLandsOnThroughTheImpactPathAboveThePolicysThresholds) {
    for (const int mode : {0, 1, 2}) { // thresholds below the landing, impulse above it, approach above it
        SCOPED_TRACE(mode);
        ImpactPolicy policy;
        if (mode == 1)
            policy.collisionImpulseThreshold = 1e4;
        if (mode == 2)
            policy.minApproachSpeed = 8;
        Drop d(policy);
        ASSERT_EQ(d.rig.motionOf(d.block), BodyMotionState::Static);
        EXPECT_EQ(d.floorHealth(), 1);
        for (ObjectId p : d.props)
            d.rig.runtime.removeBody(d.rig.runtime.bodyOf(p)->id);
        std::optional<double> healthAtImpact;
        bool collapsed = false;
        for (int i = 0; i < 90 && !healthAtImpact; ++i) {
            d.rig.runtime.stepFrame();
            for (const StructureCollapse& c : d.rig.runtime.structureCollapses())
                collapsed = collapsed || c.body == d.rig.runtime.bodyOf(d.block)->id;
            if (d.rig.runtime.counters().impacts > 0)
                healthAtImpact = d.floorHealth();
        }
        for (int i = 0; i < 30; ++i)
            d.rig.runtime.stepFrame();
        EXPECT_TRUE(collapsed) << "the block fell for want of support";
        const RuntimeCounters& c = d.rig.runtime.counters();
        if (mode != 0) {
            EXPECT_FALSE(healthAtImpact);
            EXPECT_EQ(c.impacts, 0);
            EXPECT_TRUE(d.rig.runtime.recentImpacts().empty());
            EXPECT_EQ(c.fractures, 0);
            EXPECT_EQ(d.floorHealth(), 1) << "no damage without an impact";
            continue;
        }
        ASSERT_TRUE(healthAtImpact);
        EXPECT_NEAR(*healthAtImpact, 1 - 850 * std::sqrt(2 * 9.81 * 2.5) * 1e-4 * 0.5, 0.02);
        EXPECT_EQ(c.impacts, 1) << "the floor; the block is indestructible";
        ASSERT_EQ(d.rig.runtime.recentImpacts().size(), 1u);
        const ImpactMark& m = d.rig.runtime.recentImpacts().front();
        EXPECT_NEAR(length(m.point - Vec3{0, 0.5, 0}), 0, 1e-9) << "on the floor's top, under the block";
        EXPECT_GT(m.impulse, 5000);
        EXPECT_EQ(c.fractures, 1);
        EXPECT_EQ(d.rig.runtime.bodyOf(d.floor), nullptr) << "broken into pieces";
    }
}

// A 780 kg slab falls 2.8 m onto a slab on 0.1 m piers: brick bearings crush (13 MPa > 9), steel holds.
TEST(Cascade, AFloorThatCollapsesOntoTheOneBelowBreaksItOnlyIfItsMaterialsSaySo) {
    for (const char* material : {"brick", "steel"})
        for (const bool drop : {true, false}) {
            SCOPED_TRACE(std::string(material) + (drop ? ", dropped" : ", not dropped"));
            Rig rig(true, 1, false, 0.6);
            const ObjectId left = rig.addBox({-2, 0, -0.05}, {-1.9, 3, 0.05}, material);
            const ObjectId right = rig.addBox({1.9, 0, -0.05}, {2, 3, 0.05}, material);
            const ObjectId lower = rig.addBox({-2, 3, -0.75}, {2, 3.2, 0.75}, material);
            const std::vector<ObjectId> props{rig.addBox({-2.6, 0, -0.2}, {-2.2, 6, 0.2}, "concrete"),
                                              rig.addBox({2.2, 0, -0.2}, {2.6, 6, 0.2}, "concrete")};
            const ObjectId upper = rig.addBox({-2.6, 6, -0.75}, {2.6, 6.2, 0.75}, "concrete");
            for (int i = 0; i < 10; ++i)
                rig.runtime.stepFrame();
            ASSERT_EQ(rig.motionOf(lower), BodyMotionState::Static) << "it carries itself";
            ASSERT_EQ(rig.runtime.counters().bondsBroken, 0);
            if (drop)
                for (ObjectId p : props)
                    rig.runtime.removeBody(rig.runtime.bodyOf(p)->id);
            std::vector<StructureBreak> breaks;
            std::uint64_t upperFell = 0, lowerFell = 0;
            for (int i = 0; i < 90; ++i) {
                rig.runtime.stepFrame();
                breaks.insert(breaks.end(), rig.runtime.structureBreaks().begin(),
                              rig.runtime.structureBreaks().end());
                for (const StructureCollapse& c : rig.runtime.structureCollapses()) {
                    if (c.body == rig.runtime.bodyOf(upper)->id)
                        upperFell = c.frame;
                    if (c.body == rig.runtime.bodyOf(lower)->id)
                        lowerFell = c.frame;
                }
            }
            EXPECT_EQ(upperFell > 0, drop);
            const bool fails = drop && std::string(material) == "brick";
            EXPECT_EQ(rig.motionOf(lower), fails ? BodyMotionState::Dynamic : BodyMotionState::Static);
            EXPECT_EQ(lowerFell > 0, fails);
            EXPECT_EQ(rig.motionOf(left) != BodyMotionState::Static, fails);
            EXPECT_EQ(rig.motionOf(right) != BodyMotionState::Static, fails);
            if (!fails) {
                EXPECT_TRUE(breaks.empty());
                EXPECT_EQ(rig.runtime.counters().bondsBroken, 0);
                continue;
            }
            EXPECT_GT(lowerFell, upperFell + 10)
                << "the upper floor fell, landed, then the lower one gave way";
            ASSERT_EQ(breaks.size(), 4u) << "both ends of both piers";
            for (const StructureBreak& b : breaks) {
                EXPECT_EQ(b.frame, lowerFell) << "in the frame the upper floor landed";
                EXPECT_FALSE(b.damaged) << "crushed by the load, not by impact damage";
                EXPECT_GT(b.utilisation, 1);
                EXPECT_TRUE(b.materialA == "brick" || b.materialB == "brick");
            }
            EXPECT_EQ(rig.runtime.counters().impacts, 0) << "nothing destructible: the load alone broke it";
        }
}

// Three brick storeys under a dropped slab: the top, then the middle one give way as each lands.
TEST(Cascade, FloorsFallingOnFloorsBreakThemTopDownOneLandingAtATimeWhileTheirMaterialsGiveWay) {
    for (const char* below : {"brick", "steel"}) {
        SCOPED_TRACE(below);
        Rig rig(true, 1, false, 0.6, StressMethod::GaussSeidel);
        const double sides[3] = {0.22, 0.16, 0.1}; // bottom to top
        std::vector<std::vector<ObjectId>> storeys;
        for (int k = 0; k < 3; ++k) {
            const double y = 3.2 * k, h = sides[k] / 2;
            const char* material = k < 2 ? below : "brick";
            storeys.push_back({rig.addBox({-2, y, -h}, {-2 + 2 * h, y + 2.8, h}, material),
                               rig.addBox({2 - 2 * h, y, -h}, {2, y + 2.8, h}, material),
                               rig.addBox({-2, y + 2.8, -0.75}, {2, y + 3.2, 0.75}, material)});
        }
        const std::vector<ObjectId> props{rig.addBox({-2.6, 0, -0.2}, {-2.2, 12.6, 0.2}, "concrete"),
                                          rig.addBox({2.2, 0, -0.2}, {2.6, 12.6, 0.2}, "concrete")};
        const ObjectId upper = rig.addBox({-2.6, 12.6, -0.75}, {2.6, 12.8, 0.75}, "concrete");
        for (int i = 0; i < 40; ++i) // past the 30 solves that let an unbalanced body go
            rig.runtime.stepFrame();
        ASSERT_EQ(rig.runtime.counters().piecesCollapsed, 0);
        for (ObjectId p : props)
            rig.runtime.removeBody(rig.runtime.bodyOf(p)->id);
        std::map<BodyId, std::uint64_t> fellIn;
        std::map<std::uint64_t, int> breaksIn; // frame -> bonds broken
        for (int i = 0; i < 200; ++i) {
            rig.runtime.stepFrame();
            for (const StructureBreak& b : rig.runtime.structureBreaks()) {
                ++breaksIn[b.frame];
                EXPECT_FALSE(b.damaged);
                EXPECT_GT(b.utilisation, 1);
            }
            for (const StructureCollapse& c : rig.runtime.structureCollapses())
                fellIn[c.body] = c.frame;
        }
        auto fell = [&](int storey) { // the frame its slab fell in (0: standing)
            const auto it = fellIn.find(rig.runtime.bodyOf(storeys[storey][2])->id);
            return it == fellIn.end() ? 0 : it->second;
        };
        const std::uint64_t dropped = fellIn.at(rig.runtime.bodyOf(upper)->id);
        EXPECT_GT(fell(2), dropped + 40) << "the top storey gave way when the slab landed, 3 m below";
        EXPECT_EQ(breaksIn[fell(2)], 4) << "both ends of both top piers";
        for (ObjectId id : storeys[0])
            EXPECT_EQ(rig.motionOf(id), BodyMotionState::Static);
        EXPECT_EQ(rig.runtime.counters().impacts, 0) << "nothing destructible: loads alone";
        if (std::string(below) == "steel") {
            EXPECT_EQ(fell(1), 0u);
            EXPECT_EQ(rig.runtime.counters().bondsBroken, 4);
            continue;
        }
        EXPECT_GT(fell(1), fell(2) + 40)
            << "the middle storey gave way when the top slab landed, 2.8 m below";
        EXPECT_EQ(breaksIn[fell(1)], 4);
        EXPECT_EQ(rig.runtime.counters().bondsBroken, 8);
    }
}

} // namespace rubble
