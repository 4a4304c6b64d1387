// The converged stress solve against statics: column, cantilever, simply supported beam, three-hinged arch
// and a stack on bearings, each within 1 % of the textbook value (docs/structure.md, "Checked against
// statics").
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "BondLookup.hpp"
#include "rubble/structure/StressSolver.hpp"

using namespace rubble;

namespace {
constexpr double kG = 9.81;

ConvexPolytope box(Vec3 lo, Vec3 hi) {
    Aabb b;
    b.extend(lo);
    b.extend(hi);
    return ConvexPolytope::fromAabb(b);
}

// Solids with densities; bonds of a solid with friction are bearings, the others welds.
struct Lattice {
    std::vector<std::vector<ConvexPolytope>> solids;
    std::vector<double> density;
    std::vector<bool> roots;
    std::vector<double> friction; // > 0: the node's bonds are bearings with this friction

    std::uint32_t add(ConvexPolytope p, double rho, bool root = false, double bearings = 0) {
        solids.push_back({std::move(p)});
        density.push_back(rho);
        roots.push_back(root);
        friction.push_back(bearings);
        return static_cast<std::uint32_t>(solids.size() - 1);
    }
    StressSolver solver(StressSettings settings) const {
        std::vector<StructureNode> nodes;
        for (std::size_t i = 0; i < solids.size(); ++i)
            nodes.push_back(structureNode(solids[i], density[i], roots[i]));
        std::vector<Bond> bonds = buildBonds(solids, {});
        std::vector<StrengthLimits> limits;
        for (const Bond& b : bonds) {
            limits.emplace_back();
            limits.back().friction = std::max(friction[b.a], friction[b.b]);
        }
        StressSolver s(settings);
        s.reset(std::move(nodes), std::move(bonds), std::move(limits));
        return s;
    }
    double mass(std::uint32_t i) const { return structureNode(solids[i], density[i], false).mass; }
};

using test::bondBetween;

// The converged solvers (one solve from zero forces reaches the residual).
std::vector<StressSettings> converged() {
    StressSettings gs, cg, direct;
    gs.method = StressMethod::GaussSeidel;
    cg.method = StressMethod::ConjugateGradient;
    direct.method = StressMethod::Direct;
    gs.residual = cg.residual = direct.residual = 1e-3;
    gs.maxSweeps = cg.maxSweeps = direct.maxSweeps = 100000;
    return {gs, cg, direct};
}

// The solvers that handle bearings exactly (projected Gauss-Seidel, the active set).
std::vector<StressSettings> withBearings() {
    const std::vector<StressSettings> all = converged();
    return {all.front(), all.back()};
}

const char* name(const StressSettings& s) {
    return s.method == StressMethod::GaussSeidel         ? "gauss-seidel"
           : s.method == StressMethod::ConjugateGradient ? "conjugate gradient"
                                                         : "direct";
}

// Every bond's force and couple in s equal the reference's to `tolerance` of the reference's largest.
void expectSameForces(const StressSolver& s, const StressSolver& reference, double tolerance) {
    double force = 0, moment = 0;
    for (std::size_t k = 0; k < reference.bondCount(); ++k) {
        force = std::max(force, length(reference.bondForce(k)));
        moment = std::max(moment, length(reference.bondMoment(k)));
    }
    for (std::size_t k = 0; k < reference.bondCount(); ++k) {
        EXPECT_LE(length(s.bondForce(k) - reference.bondForce(k)), tolerance * force) << "bond " << k;
        EXPECT_LE(length(s.bondMoment(k) - reference.bondMoment(k)), tolerance * moment) << "bond " << k;
    }
}

// The force node b exerts on node a (a < b as bonds store it), as seen from `on`.
Vec3 forceOn(const StressSolver& s, std::size_t bond, std::uint32_t on) {
    return s.bond(bond).a == on ? s.bondForce(bond) : -1.0 * s.bondForce(bond);
}
} // namespace

// A column of 12 welded blocks under a 2 MN load: every joint carries the load and the blocks above, sigma =
// F / A.
TEST(StressAnalytic, ColumnJointsCarryTheWeightAboveOverTheirArea) {
    for (const StressSettings& settings : converged()) {
        SCOPED_TRACE(name(settings));
        Lattice l;
        const std::uint32_t ground = l.add(box({-2, -1, -2}, {2, 0, 2}), 2400, true);
        std::vector<std::uint32_t> blocks;
        for (int i = 0; i < 12; ++i)
            blocks.push_back(l.add(box({-0.2, 0.25 * i, -0.15}, {0.2, 0.25 * (i + 1), 0.15}), 2400));
        StressSolver s = l.solver(settings);
        const double load = 2e6, area = 0.4 * 0.3;
        s.addLoad(blocks.back(), {0, -load, 0}, {0, 3, 0});
        s.solve();
        EXPECT_LE(s.residual(), settings.residual);
        for (int i = 0; i < 12; ++i) {
            double above = load;
            for (int j = i; j < 12; ++j)
                above += l.mass(blocks[static_cast<std::size_t>(j)]) * kG;
            const std::size_t joint = bondBetween(s, i ? blocks[static_cast<std::size_t>(i - 1)] : ground,
                                                  blocks[static_cast<std::size_t>(i)]);
            EXPECT_NEAR(s.stress(joint).compression, above / area, 0.01 * above / area) << "joint " << i;
            EXPECT_NEAR(s.stress(joint).tension, 0, 0.01 * above / area) << "joint " << i;
        }
    }
}

// A cantilever of 16 welded segments with a tip load: the moment at x from the tip is P x + w x^2 / 2, the
// root's F L, and its fibres carry M c / I.
TEST(StressAnalytic, CantileverMomentGrowsToFLAtTheRootWithStressMcOverI) {
    for (const StressSettings& settings : converged()) {
        SCOPED_TRACE(name(settings));
        Lattice l;
        const double span = 4, b = 0.3, h = 0.4, rho = 2400;
        const int n = 16;
        const double seg = span / n;
        const std::uint32_t wall = l.add(box({-1, -2, -1}, {0, 2, 1}), rho, true);
        std::vector<std::uint32_t> segs;
        for (int i = 0; i < n; ++i)
            segs.push_back(l.add(box({seg * i, -h / 2, -b / 2}, {seg * (i + 1), h / 2, b / 2}), rho));
        StressSolver s = l.solver(settings);
        const double tip = 20e3, w = rho * b * h * kG;
        s.addLoad(segs.back(), {0, -tip, 0}, {span, 0, 0});
        s.solve();
        EXPECT_LE(s.residual(), settings.residual);
        for (int i = 0; i < n; ++i) {
            const double x = span - seg * i; // from the tip to joint i
            const double moment = tip * x + w * x * x / 2, shear = tip + w * x;
            const std::size_t joint = bondBetween(s, i ? segs[static_cast<std::size_t>(i - 1)] : wall,
                                                  segs[static_cast<std::size_t>(i)]);
            EXPECT_NEAR(length(s.bondMoment(joint)), moment, 0.01 * moment) << "joint " << i;
            EXPECT_NEAR(length(s.bondForce(joint)), shear, 0.01 * shear) << "joint " << i;
            const double sigma = moment * (h / 2) / (b * h * h * h / 12);
            EXPECT_NEAR(s.stress(joint).tension, sigma, 0.01 * sigma) << "joint " << i;
            EXPECT_NEAR(s.stress(joint).compression, sigma, 0.01 * sigma) << "joint " << i;
        }
        EXPECT_NEAR(length(s.bondMoment(bondBetween(s, wall, segs[0]))), tip * span + w * span * span / 2,
                    1e-2 * tip * span);
    }
}

// A beam of 10 welded segments on a knife-edge bearing and a roller, with a point load off centre: the
// reactions P (L - a) / L + W / 2 and P a / L + W / 2, and the moment at mid-span.
TEST(StressAnalytic, SimplySupportedBeamReactionsAndMidSpanMoment) {
    for (const StressSettings& settings : converged()) {
        SCOPED_TRACE(name(settings));
        Lattice l;
        const double span = 6, b = 0.3, h = 0.3, rho = 7850, edge = 0.01;
        const int n = 10;
        const double seg = span / n;
        // knife edges under the beam's ends, centred at x = 0 and x = span
        const std::uint32_t left = l.add(box({-edge / 2, -1, -b / 2}, {edge / 2, 0, b / 2}), rho, true, 0.6);
        const std::uint32_t right = // a roller: no friction
            l.add(box({span - edge / 2, -1, -b / 2}, {span + edge / 2, 0, b / 2}), rho, true, 1e-9);
        std::vector<std::uint32_t> segs;
        segs.push_back(l.add(box({-edge / 2, 0, -b / 2}, {seg, h, b / 2}), rho));
        for (int i = 1; i < n - 1; ++i)
            segs.push_back(l.add(box({seg * i, 0, -b / 2}, {seg * (i + 1), h, b / 2}), rho));
        segs.push_back(l.add(box({span - seg, 0, -b / 2}, {span + edge / 2, h, b / 2}), rho));
        StressSolver s = l.solver(settings);
        const double load = 50e3, x = 2.5 * seg; // on the third segment's top centre (1.5 m)
        s.addLoad(segs[2], {0, -load, 0}, {x, h, 0});
        s.solve();
        EXPECT_LE(s.residual(), settings.residual);
        double weight = 0, moment0 = 0; // the beam's weight and its moment about x = 0
        for (std::uint32_t i : segs) {
            const StructureNode node = structureNode(l.solids[i], rho, false);
            weight += node.mass * kG;
            moment0 += node.mass * kG * node.centroid.x;
        }
        const double rightReaction = (load * x + moment0) / span;
        const double leftReaction = load + weight - rightReaction;
        const double rl = forceOn(s, bondBetween(s, left, segs.front()), segs.front()).y;
        const double rr = forceOn(s, bondBetween(s, right, segs.back()), segs.back()).y;
        EXPECT_NEAR(rl, leftReaction, 0.01 * leftReaction);
        EXPECT_NEAR(rr, rightReaction, 0.01 * rightReaction);
        // Mid-span (x = span / 2): the right reaction's moment less the right half's weight.
        double mid = rightReaction * span / 2;
        for (int i = n / 2; i < n; ++i) {
            const StructureNode node = structureNode(l.solids[segs[static_cast<std::size_t>(i)]], rho, false);
            mid -= node.mass * kG * (node.centroid.x - span / 2);
        }
        const std::size_t joint = bondBetween(s, segs[n / 2 - 1], segs[n / 2]);
        EXPECT_NEAR(length(s.bondMoment(joint)), mid, 0.01 * mid);
        EXPECT_NEAR(s.stress(joint).tension, mid * (h / 2) / (b * h * h * h / 12),
                    0.01 * mid * 6 / (b * h * h));
    }
}

namespace {
// A rafter of a three-hinged arch: its foot a horizontal face on [foot, foot + t] at y = 0, its crown end the
// vertical face x = crown, y in [rise - d, rise + d] (mirrored for the right rafter).
ConvexPolytope rafter(double foot, double t, double crown, double rise, double d, double depth) {
    const double sign = crown > foot ? 1 : -1;
    const double lo = std::min({foot, foot + sign * t, crown}), hi = std::max({foot, foot + sign * t, crown});
    ConvexPolytope p = box({lo, 0, -depth / 2}, {hi, rise + d, depth / 2});
    auto side = [&](Vec3 a, Vec3 b, Vec3 inside) {
        Vec3 n = cross(b - a, Vec3{0, 0, 1});
        if (dot(n, inside - a) > 0)
            n = -1.0 * n;
        p = p.clipped(Plane::fromPointNormal(a, n));
    };
    const Vec3 inner{(foot + crown) / 2 + sign * t / 4, rise / 2, 0};
    side({foot + sign * t, 0, 0}, {crown, rise - d, 0}, inner); // underside
    side({foot, 0, 0}, {crown, rise + d, 0}, inner);            // upper side
    return p;
}
} // namespace

// Two rafters on knife-edge bearings leaning on a key at the crown (a three-hinged arch): the horizontal
// thrust at each foot is H = W e / f (W a rafter's weight, e its centroid's distance from the foot's hinge,
// f the crown's height above it), within 1 %; the feet carry it by friction.
TEST(StressAnalytic, ThreeHingedArchThrustsHorizontallyAsStaticsSays) {
    for (const StressSettings& settings : withBearings()) {
        SCOPED_TRACE(name(settings));
        Lattice l;
        const double half = 2.0, rise = 2.5, t = 0.3, d = 0.15, depth = 0.4, edge = 0.004, key = 0.1,
                     rho = 2400;
        const double hingeL = -half - t / 2, hingeR = half + t / 2;
        const std::uint32_t footL = l.add(
            box({hingeL - edge / 2, -1, -depth / 2}, {hingeL + edge / 2, 0, depth / 2}), rho, true, 0.6);
        const std::uint32_t footR = l.add(
            box({hingeR - edge / 2, -1, -depth / 2}, {hingeR + edge / 2, 0, depth / 2}), rho, true, 0.6);
        const std::uint32_t left = l.add(rafter(-half - t, t, -key / 2, rise, d, depth), rho, false, 0.6);
        const std::uint32_t right = l.add(rafter(half + t, t, key / 2, rise, d, depth), rho, false, 0.6);
        const std::uint32_t crown =
            l.add(box({-key / 2, rise - edge / 2, -depth / 2}, {key / 2, rise + edge / 2, depth / 2}), rho,
                  false, 0.6);
        StressSolver s = l.solver(settings);
        s.solve();
        EXPECT_LE(s.residual(), settings.residual);
        const StructureNode r = structureNode(l.solids[left], rho, false);
        const double keyWeight = l.mass(crown) * kG;
        // Moments about the left foot's hinge: H f = W e + (key weight / 2) (crown's x - hinge)
        const double thrust =
            (r.mass * kG * (r.centroid.x - hingeL) + keyWeight / 2 * (-key / 2 - hingeL)) / rise;
        const Vec3 fl = forceOn(s, bondBetween(s, footL, left), left);
        const Vec3 fr = forceOn(s, bondBetween(s, footR, right), right);
        EXPECT_NEAR(fl.x, thrust, 0.01 * thrust);
        EXPECT_NEAR(-fr.x, thrust, 0.01 * thrust);
        EXPECT_NEAR(fl.y, r.mass * kG + keyWeight / 2, 0.01 * r.mass * kG);
        EXPECT_LT(thrust, 0.6 * fl.y) << "friction holds the feet";
        const Vec3 atCrown = forceOn(s, bondBetween(s, left, crown), crown);
        EXPECT_NEAR(atCrown.x, thrust, 0.01 * thrust) << "the key carries the thrust across";
        EXPECT_TRUE(s.unsupported().empty());
    }
}

namespace {
// The lowest `count` joints of a stack of three equal blocks on `ground` each carry the weight above them
// (`top` a block's) and the horizontal force `shear` on the top block, within 1 %.
void expectStackCarries(const StressSolver& s, std::uint32_t ground, const std::vector<std::uint32_t>& blocks,
                        double top, double shear, int count) {
    for (int i = 0; i < count; ++i) {
        const std::uint32_t below = i ? blocks[static_cast<std::size_t>(i - 1)] : ground;
        const Vec3 f = forceOn(s, bondBetween(s, below, blocks[static_cast<std::size_t>(i)]),
                               blocks[static_cast<std::size_t>(i)]);
        const double weight = top * (3 - i);
        EXPECT_NEAR(f.y, weight, 0.01 * weight) << "interface " << i;
        EXPECT_NEAR(-f.x, shear, 0.01 * shear) << "interface " << i;
    }
}
} // namespace

// Three blocks stacked on bearings, the top one pushed sideways: each interface carries the weight above in
// compression and the push in friction; a push over mu times the top block's weight slides it off, and the
// blocks below, pressed harder, hold.
TEST(StressAnalytic, StackOnBearingsCarriesWeightAndFrictionUpToItsLimit) {
    for (StressSettings settings : withBearings())
        for (const double ratio : {0.9, 1.3}) {
            SCOPED_TRACE(name(settings));
            SCOPED_TRACE(ratio);
            settings.maxSweeps = 2000; // a block that slides never converges
            Lattice l;
            const double rho = 2400;
            const std::uint32_t ground = l.add(box({-2, -1, -2}, {2, 0, 2}), rho, true, 0.6);
            std::vector<std::uint32_t> blocks;
            for (int i = 0; i < 3; ++i)
                blocks.push_back(
                    l.add(box({-0.5, 0.5 * i, -0.5}, {0.5, 0.5 * (i + 1), 0.5}), rho, false, 0.6));
            StressSolver s = l.solver(settings);
            const double top = l.mass(blocks[2]) * kG, push = ratio * 0.6 * top;
            for (int frame = 0; frame < settings.unbalancedSolves + 1; ++frame) {
                s.addLoad(blocks[2], {push, 0, 0}, {0, 1.25, 0});
                s.solve();
                if (frame > 0) { // the sliding block is left out after stallSweeps, not iterated to maxSweeps
                    EXPECT_LT(s.sweeps(), 256) << "frame " << frame;
                }
            }
            if (ratio < 1) {
                EXPECT_LE(s.residual(), settings.residual);
                EXPECT_TRUE(s.unsupported().empty());
                expectStackCarries(s, ground, blocks, top, push, 3);
            } else {
                EXPECT_GT(s.residual(), settings.residual) << "no equilibrium to converge to";
                EXPECT_EQ(s.unsupported(), std::vector<std::uint32_t>{blocks[2]});
            }
        }
}

// A load that changes between solves is passed down the welds beneath it before the iteration: a welded
// column balances a new off-centre load at its top, and its removal, in 0 sweeps with every joint exact,
// where the iteration alone needs sweeps to carry it down.
TEST(StressAnalytic, ALoadChangeIsPassedDownAColumnBeforeTheIteration) {
    for (const bool routed : {true, false}) {
        SCOPED_TRACE(routed);
        StressSettings settings = converged().front();
        settings.routeLoads = routed;
        Lattice l;
        const std::uint32_t ground = l.add(box({-2, -1, -2}, {2, 0, 2}), 2400, true);
        for (int i = 0; i < 12; ++i)
            l.add(box({-0.2, 0.25 * i, -0.15}, {0.2, 0.25 * (i + 1), 0.15}), 2400);
        const std::uint32_t top = ground + 12;
        StressSolver s = l.solver(settings);
        s.solve();
        ASSERT_LE(s.residual(), 1e-3);
        const std::size_t foot = bondBetween(s, ground, ground + 1);
        const Vec3 before = forceOn(s, foot, ground + 1);
        const Vec3 load{4e3, -2e4, 1e3};
        s.addLoad(top, load, {0.2, 3, 0.15});
        s.solve();
        EXPECT_LE(s.residual(), 1e-3);
        // Routed: exact. Iterated: within the residual, 1e-3 of the top block's acceleration under the load.
        const double tolerance = (routed ? 1e-9 : 0.05) * length(load);
        const Vec3 change = forceOn(s, foot, ground + 1) - before;
        EXPECT_NEAR(change.x, -load.x, tolerance);
        EXPECT_NEAR(change.y, -load.y, tolerance);
        EXPECT_NEAR(change.z, -load.z, tolerance);
        if (routed) {
            EXPECT_EQ(s.sweeps(), 0);
        } else {
            EXPECT_GT(s.sweeps(), 2);
        }
        s.solve(); // the load is gone
        EXPECT_LE(s.residual(), 1e-3);
        EXPECT_NEAR(length(forceOn(s, foot, ground + 1) - before), 0, tolerance);
        if (routed) {
            EXPECT_EQ(s.sweeps(), 0);
        }
    }
}

// What the sweep budget left: one frame's 12 sweeps from zero forces leave a 40-block column far from
// equilibrium, where the converged solve is within its residual in the same frame.
TEST(StressAnalytic, TheSweepBudgetLeavesATallColumnUnconvergedInAFrame) {
    Lattice l;
    const std::uint32_t ground = l.add(box({-2, -1, -2}, {2, 0, 2}), 2400, true);
    std::uint32_t last = ground;
    for (int i = 0; i < 40; ++i)
        last = l.add(box({-0.2, 0.25 * i, -0.15}, {0.2, 0.25 * (i + 1), 0.15}), 2400);
    StressSettings budget;
    budget.method = StressMethod::SweepBudget;
    budget.iterations = 12;
    StressSolver old = l.solver(budget);
    old.solve();
    StressSettings converged;
    converged.method = StressMethod::GaussSeidel;
    StressSolver now = l.solver(converged);
    now.solve();
    EXPECT_GT(old.residual(), 0.1);
    EXPECT_LE(now.residual(), 1e-3);
    const double weight = 40 * l.mass(last) * kG;
    const std::size_t foot = bondBetween(now, ground, ground + 1);
    EXPECT_NEAR(now.bondForce(foot).y, -weight, 0.01 * weight);
    EXPECT_GT(std::abs(old.bondForce(foot).y + weight), 0.1 * weight);
}

// The direct solve against Gauss-Seidel, both to a residual of 1e-5: on the column and the cantilever
// (statically determinate, one answer) every joint's force and couple agree to 1e-3 of the largest.
TEST(StressAnalytic, TheDirectSolveGivesConvergedGaussSeidelsForces) {
    for (const bool cantilever : {false, true}) {
        SCOPED_TRACE(cantilever ? "cantilever" : "column");
        Lattice l;
        l.add(box({-2, -1, -2}, {0, 2, 2}), 2400, true);
        for (int i = 0; i < 12; ++i)
            l.add(cantilever ? box({0.25 * i, 0, -0.15}, {0.25 * (i + 1), 0.4, 0.15})
                             : box({-0.2, 2 + 0.25 * i, -0.15}, {0, 2 + 0.25 * (i + 1), 0.15}),
                  2400);
        StressSettings tight = converged().front(), direct = converged().back();
        tight.residual = direct.residual = 1e-5;
        StressSolver reference = l.solver(tight), s = l.solver(direct);
        for (StressSolver* solver : {&reference, &s}) {
            solver->addLoad(12, {1e3, -2e4, 0}, {cantilever ? 3.0 : -0.1, cantilever ? 0.4 : 5.0, 0});
            solver->solve();
        }
        ASSERT_LE(reference.residual(), 1e-5);
        EXPECT_LE(s.residual(), 1e-5) << s.sweeps() << " solves and sweeps, " << s.factorizations();
        EXPECT_GE(s.factorizations(), 1);
        expectSameForces(s, reference, 1e-3);
    }
}

// A beam of ten welded segments on three knife-edge bearings 2 m apart, its load's resultant 0.2 m inside
// the right one: statics leaves the left one between 0 and 0.05 of the load (the middle one 0.1 less twice
// that). Holding every corner (the first active set) pulls on one of them, so the active set lets it lift
// off and the other two carry the load by the lever rule, before the Gauss-Seidel that follows (clamping the
// pull and iterating instead needs more sweeps along the beam). Gauss-Seidel alone lands inside the range.
TEST(StressAnalytic, ABeamOnThreeBearingsLiftsOffOneThatWouldPull) {
    Lattice l;
    const double edge = 0.004, rho = 2400;
    std::vector<std::uint32_t> piers, segs;
    for (const double x : {-1.75, 0.25, 2.25})
        piers.push_back(l.add(box({x - edge / 2, -1, -0.5}, {x + edge / 2, 0, 0.5}), rho, true, 0.6));
    for (int i = 0; i < 10; ++i)
        segs.push_back(l.add(box({-2.5 + 0.5 * i, 0, -0.5}, {-2 + 0.5 * i, 0.4, 0.5}), rho));
    double weight = 0;
    for (std::uint32_t i : segs)
        weight += l.mass(i) * kG;
    const double load = weight * 2.05 / (2.4 - 2.05), total = weight + load; // resultant at x = 2.05
    const std::uint32_t over[3] = {segs[1], segs[5], segs[9]};
    for (const StressSettings& settings : withBearings()) {
        SCOPED_TRACE(name(settings));
        StressSolver s = l.solver(settings);
        s.addLoad(segs[9], {0, -load, 0}, {2.4, 0.4, 0});
        s.solve();
        EXPECT_LE(s.residual(), settings.residual);
        double r[3];
        for (int i = 0; i < 3; ++i)
            r[i] = forceOn(s, bondBetween(s, piers[static_cast<std::size_t>(i)], over[i]), over[i]).y;
        EXPECT_NEAR(r[0] + r[1] + r[2], total, 1e-2 * total);
        EXPECT_GE(r[0], -1e-3 * total);
        EXPECT_GE(r[1], -1e-3 * total);
        EXPECT_NEAR(r[1], 0.1 * total - 2 * r[0], 0.01 * total);
        EXPECT_NEAR(r[2], 0.9 * total + r[0], 0.01 * total);
        if (settings.method == StressMethod::Direct) {
#ifdef RUBBLE_HAVE_CHOLMOD
            EXPECT_EQ(s.factorizations(), 1) << "the pulling pier's corners left as a downdate";
#else
            EXPECT_GE(s.factorizations(), 2) << "a pulling pier's corners left the active set";
#endif
            EXPECT_LE(s.sweeps(), 12) << "the active set settles it, not the Gauss-Seidel that follows";
            EXPECT_NEAR(std::min(r[0], r[1]), 0, 1e-3 * total) << "one bearing lifts off";
        }
        EXPECT_TRUE(s.unsupported().empty());
    }
}

// A propped cantilever whose prop lets go: the direct solve after the break reuses the symbolic
// factorisation (the broken bond stays in the pattern) and gives the forces a fresh solver finds for the
// cantilever alone (statically determinate) to 1e-3 of the root's.
TEST(StressAnalytic, AFactorisationReusedAfterABreakMatchesAFreshOne) {
    Lattice l;
    const double rho = 2400;
    const std::uint32_t ground = l.add(box({-2, -1, -2}, {6, 0, 2}), rho, true);
    for (const double x : {0.0, 4.0})
        for (int i = 0; i < 4; ++i)
            l.add(box({x - 0.2, 0.5 * i, -0.2}, {x + 0.2, 0.5 * (i + 1), 0.2}), rho);
    std::vector<std::uint32_t> arm;
    for (int j = 0; j < 9; ++j)
        arm.push_back(l.add(box({-0.2 + 0.5 * j, 2, -0.2}, {0.3 + 0.5 * j, 2.4, 0.2}), rho));
    const std::uint32_t propTop = ground + 8;
    StressSettings direct = converged().back();
    StressSolver reused = l.solver(direct), fresh = l.solver(direct);
    const std::size_t prop = bondBetween(reused, propTop, arm.back());
    reused.solve();
    ASSERT_LE(reused.residual(), 1e-3);
    EXPECT_LT(reused.bondForce(prop).y, 0) << "the prop carries the arm";
    reused.breakBond(prop);
    reused.solve();
    fresh.breakBond(prop);
    fresh.solve();
    EXPECT_LE(reused.residual(), 1e-3);
    EXPECT_LE(fresh.residual(), 1e-3);
    EXPECT_EQ(reused.analyses(), 1) << "the break kept the symbolic factorisation";
    const std::size_t root = bondBetween(fresh, ground + 4, arm.front());
    const double force = length(fresh.bondForce(root)), moment = length(fresh.bondMoment(root));
    for (std::size_t k = 0; k < fresh.bondCount(); ++k) {
        EXPECT_LE(length(reused.bondForce(k) - fresh.bondForce(k)), 1e-3 * force) << "bond " << k;
        EXPECT_LE(length(reused.bondMoment(k) - fresh.bondMoment(k)), 1e-3 * moment) << "bond " << k;
    }
    EXPECT_TRUE(reused.unsupported().empty());
}

// A block of 8 x 7 x 8 welded bricks (2,688 unknowns) on the ground, loaded off-centre: after one bond inside
// breaks, the solve runs against the factorisation from before the break (conjugate gradient with it as
// preconditioner) instead of refactorising, and gives the forces of a copy that refactorises from the same
// state to 1e-9 of the largest.
TEST(StressAnalytic, ABreakIsSolvedAgainstTheFactorisationBeforeIt) {
    Lattice l;
    const double rho = 1900;
    l.add(box({-1, -1, -1}, {9, 0, 9}), rho, true);
    for (int y = 0; y < 7; ++y)
        for (int x = 0; x < 8; ++x)
            for (int z = 0; z < 8; ++z)
                l.add(box({double(x), 0.5 * y, double(z)}, {x + 1.0, 0.5 * (y + 1), z + 1.0}), rho);
    StressSettings direct = converged().back();
    direct.residual = 1e-8;
    StressSolver updated = l.solver(direct);
    const std::uint32_t top = static_cast<std::uint32_t>(l.solids.size() - 1);
    updated.addLoad(top, {2e4, -1e5, 0}, {8, 3.5, 8});
    updated.solve();
    ASSERT_LE(updated.residual(), direct.residual);
    const std::size_t inside = bondBetween(updated, 1 + 3 * 64 + 3 * 8 + 3, 1 + 4 * 64 + 3 * 8 + 3);
    StressSolver fresh = updated; // the same forces; its next solve factorises anew
    for (StressSolver* s : {&fresh, &updated}) {
        s->breakBond(inside);
        s->addLoad(top, {2e4, -1e5, 0}, {8, 3.5, 8});
        s->solve();
        EXPECT_LE(s->residual(), direct.residual);
    }
    EXPECT_GE(fresh.factorizations(), 1);
    EXPECT_EQ(updated.factorizations(), 0) << "solved against the factorisation from before the break";
    expectSameForces(updated, fresh, 1e-9);
}

// The beam on three knife-edge bearings, its load moved from near the right end to the left end: the active
// set changes (the pier that lifted off carries again, another lets go). The island is small, so each change
// up- and down-dates the factorisation instead of refactorising, and the forces equal those of a copy that
// factorises from the same state to 1e-9 of the largest (both at residual 1e-8).
TEST(StressAnalytic, AnActiveSetChangeUpdatesTheFactorisation) {
    Lattice l;
    const double edge = 0.004, rho = 2400;
    std::vector<std::uint32_t> segs;
    for (const double x : {-1.75, 0.25, 2.25})
        l.add(box({x - edge / 2, -1, -0.5}, {x + edge / 2, 0, 0.5}), rho, true, 0.6);
    for (int i = 0; i < 10; ++i)
        segs.push_back(l.add(box({-2.5 + 0.5 * i, 0, -0.5}, {-2 + 0.5 * i, 0.4, 0.5}), rho));
    StressSettings direct = converged().back();
    direct.residual = 1e-8;
    StressSolver updated = l.solver(direct);
    updated.addLoad(segs[9], {0, -2e5, 0}, {2.4, 0.4, 0});
    updated.solve();
    ASSERT_LE(updated.residual(), direct.residual);
    StressSolver fresh = updated; // the same forces and active set; its next solve factorises anew
    for (StressSolver* s : {&fresh, &updated}) {
        s->addLoad(segs[0], {0, -2e4, 0}, {-2.4, 0.4, 0});
        s->solve();
        EXPECT_LE(s->residual(), direct.residual);
        EXPECT_TRUE(s->unsupported().empty());
    }
    EXPECT_GE(fresh.factorizations(), 1);
#ifdef RUBBLE_HAVE_CHOLMOD
    EXPECT_EQ(updated.factorizations(), 0) << "the active set's changes were up/down-dates";
#endif
    EXPECT_EQ(updated.analyses(), 1);
    expectSameForces(updated, fresh, 1e-9);
}

// A 3 x 3 x 3 block of welded bricks whose top middle brick is replaced by two halves (as a fracture replaces
// a body by its pieces): the solve after it makes the blocks of the halves' nine new bonds only, keeping
// every other bond's, and its forces equal, bit for bit, those of a copy that makes every block anew.
TEST(StressAnalytic, AFractureMakesOnlyItsNewBondsBlocks) {
    Lattice l;
    const double rho = 1900;
    l.add(box({-1, -1, -1}, {4, 0, 4}), rho, true);
    for (int y = 0; y < 3; ++y)
        for (int x = 0; x < 3; ++x)
            for (int z = 0; z < 3; ++z)
                l.add(box({double(x), 0.5 * y, double(z)}, {x + 1.0, 0.5 * (y + 1), z + 1.0}), rho);
    StressSettings direct = converged().back();
    direct.residual = 1e-8;
    StressSolver s = l.solver(direct);
    s.solve();
    ASSERT_LE(s.residual(), direct.residual);
    EXPECT_EQ(s.blocksMade(), static_cast<int>(s.bondCount())) << "the first solve makes every block";
    const std::uint32_t top = 1 + 2 * 9 + 1 * 3 + 1; // y = 2, x = 1, z = 1
    s.removeNode(top);
    const std::vector<ConvexPolytope> halves[2] = {{box({1, 1, 1}, {1.5, 1.5, 2})},
                                                   {box({1.5, 1, 1}, {2, 1.5, 2})}};
    std::uint32_t ids[2];
    for (int h = 0; h < 2; ++h)
        ids[h] = s.addNode(structureNode(halves[h], rho, false));
    int added = 0;
    auto bond = [&](std::uint32_t a, const std::vector<ConvexPolytope>& pa, std::uint32_t b,
                    const std::vector<ConvexPolytope>& pb) {
        Bond k;
        k.a = std::min(a, b);
        k.b = std::max(a, b);
        k.section = a < b ? bondInterface(pa, pb, {}) : bondInterface(pb, pa, {});
        if (k.section.area > 0) {
            s.addBond(k, {});
            ++added;
        }
    };
    bond(ids[0], halves[0], ids[1], halves[1]);
    for (int h = 0; h < 2; ++h)
        for (std::uint32_t other = 1; other < l.solids.size(); ++other)
            if (other != top)
                bond(ids[h], halves[h], other, l.solids[other]);
    ASSERT_EQ(added, 9) << "between the halves, to the brick beneath and to three side bricks each";
    StressSolver fresh = s; // the same state; its next solve makes every block anew
    for (StressSolver* x : {&fresh, &s}) {
        x->addLoad(ids[1], {1e4, -5e4, 0}, {1.8, 1.5, 1.5});
        x->solve();
        EXPECT_LE(x->residual(), direct.residual);
    }
    EXPECT_EQ(s.blocksMade(), added) << "the other bonds' blocks were kept";
    EXPECT_GT(fresh.blocksMade(), 50);
    expectSameForces(s, fresh, 0);
}

// Two welded columns on the ground are two islands, each with its own factorisation: removing the top block
// of one refactorises that one only, while the other, loaded anew, is solved with the factorisation it kept.
TEST(StressAnalytic, EachIslandKeepsItsOwnFactorisation) {
    Lattice l;
    const double rho = 2400;
    const std::uint32_t ground = l.add(box({-2, -1, -2}, {6, 0, 2}), rho, true);
    std::vector<std::uint32_t> columns[2];
    for (int c = 0; c < 2; ++c)
        for (int i = 0; i < 6; ++i)
            columns[c].push_back(
                l.add(box({4.0 * c - 0.2, 0.5 * i, -0.2}, {4.0 * c + 0.2, 0.5 * (i + 1), 0.2}), rho));
    StressSolver s = l.solver(converged().back());
    s.solve();
    ASSERT_LE(s.residual(), 1e-3);
    EXPECT_EQ(s.factorizations(), 2) << "one per island";
    EXPECT_EQ(s.analyses(), 2);
    const double load = 5e4;
    s.removeNode(columns[0].back());
    s.addLoad(columns[1].back(), {0, -load, 0}, {4, 3, 0});
    s.solve();
    EXPECT_LE(s.residual(), 1e-3);
    EXPECT_EQ(s.factorizations(), 1) << "the loaded column kept its factorisation";
    EXPECT_EQ(s.analyses(), 3);
    double weight[2] = {0, 0};
    for (int c = 0; c < 2; ++c)
        for (std::size_t i = 0; i + (c == 0) < columns[c].size(); ++i)
            weight[c] += l.mass(columns[c][i]) * kG;
    for (int c = 0; c < 2; ++c) {
        const double expected = weight[c] + (c == 1 ? load : 0.0);
        EXPECT_NEAR(forceOn(s, bondBetween(s, ground, columns[c].front()), columns[c].front()).y, expected,
                    1e-2 * expected)
            << "column " << c;
    }
}

// A stack of three blocks on bearings whose top block is pushed at 0.9 of its friction limit, then at 1.3:
// in the direct solve where it first slides (it held in the last one), the Gauss-Seidel polish leaves it out
// once its acceleration stops changing, instead of sweeping to maxSweeps; the blocks beneath still converge
// around it (their joints carry the weights and the top's friction within 1 %), and it falls after
// unbalancedSolves as before.
TEST(StressAnalytic, TheDirectSolvesPolishStopsOnABodyThatBeginsToSlide) {
    Lattice l;
    const double rho = 2400;
    const std::uint32_t ground = l.add(box({-2, -1, -2}, {2, 0, 2}), rho, true, 0.6);
    std::vector<std::uint32_t> blocks;
    for (int i = 0; i < 3; ++i)
        blocks.push_back(l.add(box({-0.5, 0.5 * i, -0.5}, {0.5, 0.5 * (i + 1), 0.5}), rho, false, 0.6));
    StressSettings settings = converged().back();
    StressSolver s = l.solver(settings);
    const double top = l.mass(blocks[2]) * kG;
    for (int frame = 0; frame < 3; ++frame) {
        s.addLoad(blocks[2], {0.9 * 0.6 * top, 0, 0}, {0, 1.25, 0});
        s.solve();
    }
    ASSERT_LE(s.residual(), settings.residual);
    s.addLoad(blocks[2], {1.3 * 0.6 * top, 0, 0}, {0, 1.25, 0});
    s.solve();
    EXPECT_LT(s.sweeps(), 256) << "the sliding block is stalled, not swept to maxSweeps";
    EXPECT_GT(s.residual(), settings.residual) << "the sliding block still counts";
    expectStackCarries(s, ground, blocks, top, 0.6 * top, 2);
    s.addLoad(blocks[2], {1.3 * 0.6 * top, 0, 0}, {0, 1.25, 0});
    s.solve();
    EXPECT_LT(s.sweeps(), 40) << "unbalanced in the last solve too: set aside at the polish's first check";
    expectStackCarries(s, ground, blocks, top, 0.6 * top, 2);
    for (int frame = 1; frame < settings.unbalancedSolves; ++frame) {
        s.addLoad(blocks[2], {1.3 * 0.6 * top, 0, 0}, {0, 1.25, 0});
        s.solve();
    }
    EXPECT_EQ(s.unsupported(), std::vector<std::uint32_t>{blocks[2]});
}

// The same stack with `unbalanced` above the top block's acceleration (1.8 m/s^2 against 5): the block never
// counts as unbalanced, so only the polish's own rule (its acceleration stops changing) keeps each solve from
// sweeping to maxSweeps; it is left out within 256 sweeps every solve, still counts in the residual, and is
// not dropped (below `unbalanced`).
TEST(StressAnalytic, TheDirectSolvesPolishStopsBelowTheUnbalancedThreshold) {
    Lattice l;
    const double rho = 2400;
    l.add(box({-2, -1, -2}, {2, 0, 2}), rho, true, 0.6);
    std::vector<std::uint32_t> blocks;
    for (int i = 0; i < 3; ++i)
        blocks.push_back(l.add(box({-0.5, 0.5 * i, -0.5}, {0.5, 0.5 * (i + 1), 0.5}), rho, false, 0.6));
    StressSettings settings = converged().back();
    settings.unbalanced = 5;
    StressSolver s = l.solver(settings);
    const double top = l.mass(blocks[2]) * kG;
    for (int frame = 0; frame < 5; ++frame) {
        s.addLoad(blocks[2], {1.3 * 0.6 * top, 0, 0}, {0, 1.25, 0});
        s.solve();
        EXPECT_LT(s.sweeps(), 256) << "frame " << frame;
        EXPECT_GT(s.residual(), settings.residual) << "frame " << frame;
    }
    EXPECT_TRUE(s.unsupported().empty());
}
