// The structure without a physics engine (rubble/runtime/Structure.hpp): bodies, loads and damage in, break
// and collapse records out; a cantilever checked against its root bending stress.
#include "rubble/runtime/Structure.hpp"
#include "rubble/structure/Material.hpp"

#include <gtest/gtest.h>

#include "BoxSolid.hpp"
#include <cmath>

using namespace rubble;

namespace {

using test::boxSolid;
constexpr double kG = 9.81;

// Welded joints, converged solves.
StructurePolicy welded() {
    StructurePolicy p;
    p.bearingFriction = 0;
    p.stress.method = StressMethod::GaussSeidel;
    return p;
}

constexpr BodyId kWall = 1, kSlab = 2;
constexpr double kH = 0.2, kB = 1.5; // the slab's depth and width

// A slab of `span` sticking out of a held wall at x = 0, its top at y = 2.2, both of one material (a bond
// takes the weaker of its two materials' limits).
Structure cantilever(double span, const char* material, const StructurePolicy& policy = welded()) {
    Structure s(policy);
    EXPECT_TRUE(s.add(kWall, boxSolid({-1, 0, -2}, {0, 4, 2}), material, true));
    EXPECT_TRUE(s.add(kSlab, boxSolid({0, 2, -kB / 2}, {span, 2 + kH, kB / 2}), material));
    return s;
}

// Root bending stress of a self-weighted cantilever: M c / I = 3 rho g L^2 / h.
double rootStress(double span, const char* material) {
    return 3 * findMaterial(material)->density * kG * span * span / kH;
}
} // namespace

// Below the tensile limit it stands; above it the root bond breaks there and the slab falls, as two records.
TEST(Structure, ACantileverBreaksAtItsRootOnceItsBendingStressPassesTheTensileLimit) {
    const double limit = findMaterial("concrete")->tensileStrength * 1e6;
    ASSERT_LT(rootStress(2.5, "concrete"), limit);
    ASSERT_GT(rootStress(3.5, "concrete"), limit);
    Structure standing = cantilever(2.5, "concrete");
    ASSERT_EQ(standing.bonds().size(), 1u);
    for (int i = 0; i < 3; ++i) {
        const StructureStep step = standing.step();
        EXPECT_TRUE(step.breaks.empty());
        EXPECT_TRUE(step.collapses.empty());
        EXPECT_LE(step.residual, 1e-3);
    }
    EXPECT_NEAR(standing.bonds()[0].utilisation, rootStress(2.5, "concrete") / limit, 0.01);

    Structure failing = cantilever(3.5, "concrete");
    const StructureStep step = failing.step();
    ASSERT_EQ(step.breaks.size(), 1u);
    const StructureBreak& k = step.breaks[0];
    EXPECT_EQ(k.frame, 1u);
    EXPECT_EQ(k.a, kWall);
    EXPECT_EQ(k.b, kSlab);
    EXPECT_LT(length(k.position - Vec3{0, 2.1, 0}), 1e-9);
    EXPECT_NEAR(k.area, kB * kH, 1e-12);
    EXPECT_NEAR(k.utilisation, rootStress(3.5, "concrete") / limit, 0.01);
    EXPECT_FALSE(k.damaged);
    EXPECT_EQ(k.materialA, "concrete");
    EXPECT_EQ(k.materialB, "concrete");
    ASSERT_EQ(step.collapses.size(), 1u);
    const StructureCollapse& c = step.collapses[0];
    EXPECT_EQ(c.body, kSlab);
    EXPECT_TRUE(c.byStress);
    EXPECT_NEAR(c.volume, 3.5 * kB * kH, 1e-9);
    EXPECT_NEAR(c.mass, 2400 * c.volume, 1e-6);
    EXPECT_LT(length(c.position - Vec3{1.75, 2.1, 0}), 1e-9);
    EXPECT_EQ(c.material, "concrete");
    EXPECT_FALSE(failing.contains(kSlab)) << "what fell left the structure";
    EXPECT_EQ(failing.size(), 1u);
    EXPECT_TRUE(failing.step().collapses.empty());
}

// The same slab of steel stands (14 MPa against 355); a weight at its tip breaks it only past steel's limit.
TEST(Structure, TheMaterialDecidesAndALoadAtTheTipAddsItsMoment) {
    Structure steel = cantilever(3.5, "steel");
    ASSERT_TRUE(steel.step().breaks.empty());
    const double limit = findMaterial("steel")->tensileStrength * 1e6;
    const double inertia = kB * kH * kH * kH / 12, c = kH / 2;
    const double self = rootStress(3.5, "steel");
    // the tip force that takes the root to 0.8 and then 1.2 times the limit
    for (const double share : {0.8, 1.2}) {
        const double force = (share * limit - self) * inertia / c / 3.5;
        steel.addLoad(kSlab, {0, -force, 0}, {3.5, 2.2, 0});
        const StructureStep step = steel.step();
        EXPECT_EQ(step.breaks.size(), share > 1 ? 1u : 0u) << share;
        EXPECT_EQ(step.collapses.size(), share > 1 ? 1u : 0u) << share;
        if (share < 1) {
            EXPECT_NEAR(steel.bonds()[0].utilisation, 0.8, 0.01);
        }
    }
    EXPECT_FALSE(steel.contains(kSlab));
}

// Hits near the root weaken its bond until the slab's own weight breaks it: a damaged break.
TEST(Structure, HitsNearTheRootWeakenItUntilItBreaks) {
    Structure s = cantilever(2.5, "concrete");
    int hits = 0;
    StructureStep step;
    while (step.breaks.empty() && hits < 100) {
        s.damage({0.05, 2.1, 0}, 2000);
        step = s.step();
        ++hits;
    }
    ASSERT_EQ(step.breaks.size(), 1u);
    EXPECT_GT(hits, 1) << "one hit is not enough";
    EXPECT_EQ(step.collapses.size(), 1u);
    s.damage({0.05, 2.1, 0}, 2000); // on nothing: no bond left
    EXPECT_TRUE(s.step().breaks.empty());
}

// Bad input is refused with a message and changes nothing.
TEST(Structure, BadBodiesAreRefusedAndChangeNothing) {
    Structure s = cantilever(2.5, "concrete");
    const Status unknown = s.add(3, boxSolid({0, 0, 0}, {1, 1, 1}), "Wood");
    ASSERT_FALSE(unknown);
    EXPECT_EQ(unknown.error().code, ErrorCode::InvalidInput);
    EXPECT_NE(unknown.message().find("unknown material 'Wood'"), std::string::npos) << unknown.message();
    EXPECT_FALSE(s.add(0, boxSolid({0, 0, 0}, {1, 1, 1})));
    EXPECT_FALSE(s.add(3, {}));
    EXPECT_FALSE(s.add(3, boxSolid({0, 0, 0}, {1, 0, 1})));
    EXPECT_FALSE(s.contains(3));
    EXPECT_EQ(s.size(), 2u);
    EXPECT_EQ(s.bonds().size(), 1u);
    EXPECT_FALSE(s.remove(3));
    EXPECT_TRUE(s.remove(kSlab));
    EXPECT_TRUE(s.bonds().empty());
}
