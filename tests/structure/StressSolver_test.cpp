#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "BondLookup.hpp"
#include "BoxSolid.hpp"
#include "rubble/structure/StressSolver.hpp"

using namespace rubble;

namespace {

using test::boxSolid;
constexpr double kG = 9.81;

// A structure of boxes: solids, their materials, and which are roots.
struct Scene {
    std::vector<std::vector<ConvexPolytope>> solids;
    std::vector<const Material*> materials;
    std::vector<bool> roots;

    std::uint32_t add(std::vector<ConvexPolytope> s, const char* material, bool root = false) {
        solids.push_back(std::move(s));
        materials.push_back(findMaterial(material));
        roots.push_back(root);
        return static_cast<std::uint32_t>(solids.size() - 1);
    }

    // friction > 0: every bond is a bearing.
    StressSolver solver(StressSettings settings = {}, double friction = 0) const {
        std::vector<StructureNode> nodes;
        for (std::size_t i = 0; i < solids.size(); ++i)
            nodes.push_back(structureNode(solids[i], materials[i]->density, roots[i]));
        std::vector<Bond> bonds = buildBonds(solids, {});
        std::vector<StrengthLimits> limits;
        for (const Bond& b : bonds) {
            limits.push_back(bondLimits(*materials[b.a], *materials[b.b]));
            limits.back().friction = friction;
        }
        StressSolver s(settings);
        s.reset(std::move(nodes), std::move(bonds), std::move(limits));
        return s;
    }
};

using test::bondBetween;
} // namespace

TEST(StressSolver, NodeMassAndInertiaFromTheParts) {
    auto parts = boxSolid({0, 0, 0}, {2, 1, 1});
    parts.push_back(boxSolid({2, 0, 0}, {4, 1, 1})[0]);
    const StructureNode n = structureNode(parts, 1000, false);
    EXPECT_NEAR(n.mass, 4000, 1e-9);
    EXPECT_NEAR(n.centroid.x, 2, 1e-12);
    // A 4 x 1 x 1 box about its centre: m (b^2 + c^2) / 12.
    EXPECT_NEAR(n.inertia.m[1][1], 4000 * (16 + 1) / 12.0, 1e-6);
    EXPECT_NEAR(n.inertia.m[0][0], 4000 * 2 / 12.0, 1e-6);
}

// A cantilever slab bonded to a wall: root bending stress M c / I = 3 rho g L^2 / h (self-weight).
TEST(StressSolver, CantileverBreaksAtItsRootWhenBendingStressExceedsTheTensileLimit) {
    const Material& concrete = *findMaterial("concrete");
    const double h = 0.2, b = 1.5;
    int broke = 0, stood = 0;
    for (double span = 1.0; span <= 5.0; span += 0.25) {
        Scene scene;
        scene.add(boxSolid({-1, 0, -2}, {0, 4, 2}), "concrete", true);
        const std::uint32_t slab = scene.add(boxSolid({0, 2, -b / 2}, {span, 2 + h, b / 2}), "concrete");
        StressSolver s = scene.solver();
        s.solve();
        ASSERT_EQ(s.bondCount(), 1u);
        const double w = concrete.density * kG * b * h; // load per metre
        const double moment = w * span * span / 2;
        const double sigma = moment * (h / 2) / (b * h * h * h / 12);
        EXPECT_NEAR(sigma, 3 * concrete.density * kG * span * span / h, 1e-6 * sigma);
        EXPECT_NEAR(s.stress(0).tension, sigma, 0.01 * sigma) << "L = " << span;
        EXPECT_NEAR(s.stress(0).compression, sigma, 0.01 * sigma) << "L = " << span;
        EXPECT_NEAR(s.stress(0).shear, w * span / (b * h), 0.01 * w * span / (b * h));
        EXPECT_NEAR(length(s.bondMoment(0)), moment, 0.01 * moment);
        const bool breaks = !s.breakOverstressed().empty();
        EXPECT_EQ(breaks, sigma > concrete.tensileStrength * 1e6) << "L = " << span << " sigma = " << sigma;
        EXPECT_EQ(s.unsupported(), breaks ? std::vector<std::uint32_t>{slab} : std::vector<std::uint32_t>{});
        (breaks ? broke : stood)++;
    }
    // The sweep crosses the limit (L = sqrt(f_t h / (3 rho g)) = 2.91 m).
    EXPECT_EQ(stood, 8);
    EXPECT_EQ(broke, 9);
}

// A column carrying a slab and the load of the floors above: F / A at its foot; hits shrink the section.
TEST(StressSolver, ColumnFailsInCompressionOnceHitsReduceItsSection) {
    Scene scene;
    scene.add(boxSolid({-5, -1, -5}, {5, 0, 5}), "concrete", true);
    const std::uint32_t column = scene.add(boxSolid({-0.2, 0, -0.2}, {0.2, 3, 0.2}), "concrete");
    const std::uint32_t slab = scene.add(boxSolid({-2.5, 3, -1}, {2.5, 3.3, 1}), "concrete");
    StressSolver s = scene.solver();
    const double above = 3e6; // N, floors above, on the slab's centre
    const Material& concrete = *findMaterial("concrete");
    const double mColumn = concrete.density * 0.4 * 0.4 * 3, mSlab = concrete.density * 5 * 0.3 * 2;
    const double footForce = above + (mColumn + mSlab) * kG, topForce = above + mSlab * kG;
    const double area = 0.16;
    auto frame = [&] {
        s.addLoad(slab, {0, -above, 0}, {0, 3.3, 0});
        s.solve();
    };
    for (int i = 0; i < 20; ++i)
        frame();
    const std::size_t foot = bondBetween(s, 0, column), top = bondBetween(s, column, slab);
    EXPECT_NEAR(s.stress(foot).compression, footForce / area, 0.01 * footForce / area);
    EXPECT_NEAR(s.stress(top).compression, topForce / area, 0.01 * topForce / area);
    EXPECT_LT(s.stress(foot).tension, 0.01 * footForce / area);
    EXPECT_TRUE(s.breakOverstressed().empty());
    // Each hit at the foot takes 10 % of its section; it fails when F / (A health) > f_c, i.e. below
    // health 19.3 / 30 = 0.64: after the 4th hit.
    const double threshold = footForce / area / (concrete.compressiveStrength * 1e6);
    int hits = 0;
    while (!s.broken(foot) && hits < 10) {
        s.damage({0, 0, 0}, 0.5, 0.1);
        ++hits;
        frame();
        const bool overstressed = !s.breakOverstressed().empty();
        EXPECT_EQ(overstressed, s.health(foot) + 1e-9 < threshold || s.broken(foot)) << "hit " << hits;
    }
    EXPECT_EQ(hits, 4);
    EXPECT_NEAR(s.health(top), 1, 1e-12);
    EXPECT_EQ(s.unsupported(), (std::vector<std::uint32_t>{column, slab}));
}

namespace {
// Ground, two piers and a deck of two halves bonded at mid-span.
struct Bridge {
    Scene scene;
    std::uint32_t pierA = 0, pierB = 0, left = 0, right = 0;
    explicit Bridge(const char* deck, double pier = 1) {
        scene.add(boxSolid({-10, -1, -5}, {10, 0, 5}), "concrete", true);
        pierA = scene.add(boxSolid({-5, 0, -1}, {-5 + pier, 4, 1}), "concrete");
        pierB = scene.add(boxSolid({5 - pier, 0, -1}, {5, 4, 1}), "concrete");
        left = scene.add(boxSolid({-5, 4, -1}, {0, 4.3, 1}), deck);
        right = scene.add(boxSolid({0, 4, -1}, {5, 4.3, 1}), deck);
    }
};

// Solves until the bond forces settle, breaking overstressed bonds each frame; returns what fell.
std::vector<std::uint32_t> settle(StressSolver& s, int frames = 60) {
    for (int i = 0; i < frames; ++i) {
        s.solve();
        s.breakOverstressed();
    }
    return s.unsupported();
}
} // namespace

// Piers 0.4 m x 2 m under a 10 m deck of two 5 x 0.3 x 2 m halves.
TEST(StressSolver, BridgeStandsAndFallsWhenOneSupportIsCut) {
    {
        Bridge b("concrete", 0.4);
        StressSolver s = b.scene.solver();
        EXPECT_EQ(s.bondCount(), 5u);
        EXPECT_TRUE(settle(s).empty());
        for (std::size_t i = 0; i < s.bondCount(); ++i)
            EXPECT_FALSE(s.broken(i)) << i;
        // Equilibrium: the piers' feet carry the whole weight of piers and deck.
        const std::size_t footA = bondBetween(s, 0, b.pierA), footB = bondBetween(s, 0, b.pierB);
        const double weight = (2 * 2400 * 0.4 * 4 * 2 + 2 * 2400 * 3) * kG;
        EXPECT_NEAR(s.bondForce(footA).y + s.bondForce(footB).y, -weight, 0.01 * weight);
        EXPECT_NEAR(s.bondForce(footA).y, s.bondForce(footB).y, 0.01 * weight);
    }
    {
        // Without pier A the deck is a 10 m cantilever off pier B: its joint snaps and the deck falls.
        Bridge b("concrete", 0.4);
        StressSolver s = b.scene.solver();
        settle(s, 5);
        s.detach(b.pierA);
        const auto fell = settle(s);
        EXPECT_TRUE(std::count(fell.begin(), fell.end(), b.left) == 1 &&
                    std::count(fell.begin(), fell.end(), b.right) == 1);
        EXPECT_EQ(std::count(fell.begin(), fell.end(), b.pierA), 0);
    }
}

TEST(StressSolver, BridgeCutAtMidSpanFallsOrHangsByBondStrength) {
    {
        // A concrete half hangs off its pier: M = m g a = 7200 kg * 9.81 * 2.3 m = 162 kN m over the pier's
        // 0.4 x 2 m top, sigma = M c / I = 3.04 MPa > f_t 2.9 MPa: both halves fall.
        Bridge b("concrete", 0.4);
        StressSolver s = b.scene.solver();
        settle(s, 5);
        s.breakBond(bondBetween(s, b.left, b.right));
        EXPECT_EQ(settle(s), (std::vector<std::uint32_t>{b.left, b.right}));
    }
    {
        // A wood half (420 kg/m^3) makes 0.53 MPa there: both halves hang.
        Bridge b("wood", 0.4);
        StressSolver s = b.scene.solver();
        settle(s, 5);
        s.breakBond(bondBetween(s, b.left, b.right));
        EXPECT_TRUE(settle(s).empty());
        const std::size_t joint = bondBetween(s, b.pierA, b.left);
        const double sigma = 1260 * kG * 2.3 * 0.2 / (2 * 0.4 * 0.4 * 0.4 / 12);
        EXPECT_NEAR(s.stress(joint).tension, sigma, 0.05 * sigma);
    }
}

TEST(StressSolver, SolvesAreDeterministic) {
    Bridge b("concrete");
    StressSolver s1 = b.scene.solver(), s2 = b.scene.solver();
    for (int i = 0; i < 3; ++i) {
        s1.solve();
        s2.solve();
    }
    for (std::size_t i = 0; i < s1.bondCount(); ++i) {
        EXPECT_EQ(s1.bondForce(i), s2.bondForce(i));
        EXPECT_EQ(s1.bondMoment(i), s2.bondMoment(i));
    }
}

// A slab resting (not welded) on a pier: it stands while its centre of mass is above the contact (the
// resultant's offset over the contact's half-width, e / (w / 2), is its utilisation); beyond, the bearing
// cannot hold it in equilibrium and it is unsupported: it tips.
TEST(StressSolver, BearingSlabTipsExactlyWhenItsCentreOfMassLeavesTheContact) {
    const double span = 2;
    int stood = 0, tipped = 0;
    for (double start = -1.9; start <= 0.9; start += 0.2) {
        Scene scene;
        scene.add(boxSolid({0, 0, -1}, {1, 1, 1}), "concrete", true);
        const std::uint32_t slab =
            scene.add(boxSolid({start, 1, -0.5}, {start + span, 1.2, 0.5}), "concrete");
        StressSolver s = scene.solver({}, 0.6);
        for (int i = 0; i < 40; ++i)
            s.solve();
        ASSERT_EQ(s.bondCount(), 1u);
        const double lo = std::max(0.0, start), hi = std::min(1.0, start + span);
        const double ratio = std::abs(start + span / 2 - (lo + hi) / 2) / ((hi - lo) / 2);
        const double cg = start + span / 2;
        const bool tips = cg < 0 || cg > 1;
        EXPECT_NEAR(s.utilisation(0), std::min(ratio, 1.0), 0.01 * ratio + 1e-3) << "slab from x = " << start;
        EXPECT_TRUE(s.breakOverstressed().empty()) << "a bearing breaks only by crushing";
        EXPECT_EQ(s.unsupported(), tips ? std::vector<std::uint32_t>{slab} : std::vector<std::uint32_t>{})
            << "slab from x = " << start;
        (tips ? tipped : stood)++;
    }
    EXPECT_GT(stood, 3);
    EXPECT_GT(tipped, 3);
}

// A 2 x 0.2 x 2 m concrete slab (node 1) on a pier (node 0, root) of the same top, after 40 solves with a
// load at a point; friction > 0: a bearing.
namespace {
constexpr std::uint32_t kSlab = 1;
StressSolver loadedSlabOnPier(double friction, const Vec3& load, const Vec3& at) {
    Scene scene;
    scene.add(boxSolid({-1, 0, -1}, {1, 1, 1}), "concrete", true);
    scene.add(boxSolid({-1, 1, -1}, {1, 1.2, 1}), "concrete");
    StressSolver s = scene.solver({}, friction);
    for (int i = 0; i < 40; ++i) {
        s.addLoad(kSlab, load, at);
        s.solve();
    }
    return s;
}
} // namespace

// A bearing carries no tension: a slab lifted by more than its weight is not held; a welded one is.
TEST(StressSolver, BearingLetsGoWhenPulledApartAndAWeldDoesNot) {
    for (const double friction : {0.6, 0.0})
        for (const double lift : {0.5, 1.5}) {
            const double weight = findMaterial("concrete")->density * 0.8 * kG;
            StressSolver s = loadedSlabOnPier(friction, {0, lift * weight, 0}, {0, 1.1, 0});
            EXPECT_TRUE(s.breakOverstressed().empty());
            const bool letsGo = friction > 0 && lift > 1;
            EXPECT_EQ(s.unsupported(),
                      letsGo ? std::vector<std::uint32_t>{kSlab} : std::vector<std::uint32_t>{})
                << "friction " << friction << " lift " << lift;
        }
}

// A bearing slides when the transverse force exceeds friction times compression (a push at the contact).
TEST(StressSolver, BearingSlidesWhenThePushExceedsFrictionTimesWeight) {
    const double mu = 0.6;
    for (const double push : {0.9, 1.1}) {
        const double weight = findMaterial("concrete")->density * 0.8 * kG;
        StressSolver s = loadedSlabOnPier(mu, {push * mu * weight, 0, 0}, {0, 1, 0});
        EXPECT_NEAR(s.utilisation(0), std::min(push, 1.0), 0.01 * push);
        EXPECT_EQ(s.unsupported(),
                  push > 1 ? std::vector<std::uint32_t>{kSlab} : std::vector<std::uint32_t>{});
    }
}

// Statically indeterminate: a slab on two piers with bearings stands; the pier forces sum to its weight and
// balance its moment with each resultant inside its pier's top: W (2 - x1) / (x2 - x1), x1 in [0, 0.5] and
// x2 in [3, 3.5], puts F2 between W / 2 and 2 W / 3.
TEST(StressSolver, BearingSlabOnTwoPiersStandsWithTheLeverRuleForces) {
    Scene scene;
    scene.add(boxSolid({0, 0, -0.5}, {0.5, 2, 0.5}), "concrete", true);
    scene.add(boxSolid({3, 0, -0.5}, {3.5, 2, 0.5}), "concrete", true);
    const std::uint32_t slab = scene.add(boxSolid({0, 2, -0.5}, {4, 2.3, 0.5}), "concrete");
    StressSolver s = scene.solver({}, 0.6);
    for (int i = 0; i < 60; ++i)
        s.solve();
    EXPECT_TRUE(s.unsupported().empty());
    const double weight = scene.materials[slab]->density * 4 * 0.3 * kG;
    const double f1 = length(s.bondForce(bondBetween(s, 0, slab)));
    const double f2 = length(s.bondForce(bondBetween(s, 1, slab)));
    EXPECT_NEAR(f1 + f2, weight, 0.01 * weight);
    EXPECT_GE(f2, 0.5 * weight * 0.99);
    EXPECT_LE(f2, 2 * weight / 3 * 1.01);
}
