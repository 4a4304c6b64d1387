// The incremental bond graph (BondGraph, and StructureMonitor over it) against a from-scratch buildBonds over
// real fracture pieces: after any sequence of adds and removes, the same bonds, and untouched bonds keep
// their health and broken state.
#include <gtest/gtest.h>

#include <map>
#include <set>

#include "ShatteredSolids.hpp"
#include "rubble/core/Random.hpp"
#include "rubble/structure/BondGraph.hpp"
#include "runtime/StructureMonitor.hpp"

namespace rubble {
namespace {

using Solids = std::vector<std::vector<ConvexPolytope>>;

// A ground slab and a small frame (two columns, a slab across them, a wall beside), each box shattered.
const Solids& solids() {
    static const Solids s = [] {
        Solids out{{ConvexPolytope::fromAabb({{-4, -1, -4}, {4, 0, 4}})}};
        const Solids pieces = test::shatteredSolids({{{-1.2, 0, -0.2}, {-0.8, 2, 0.2}, {-1, 1, 0.2}},
                                                     {{0.8, 0, -0.2}, {1.2, 2, 0.2}, {1, 0.5, 0.2}},
                                                     {{-1.5, 2, -1}, {1.5, 2.3, 1}, {0, 2.3, 0}, 16},
                                                     {{2, 0, -1}, {2.3, 2, 1}, {2.3, 1, 0}}},
                                                    7);
        out.insert(out.end(), pieces.begin(), pieces.end());
        return out;
    }();
    return s;
}

// buildBonds over the present solids only (absent ones are empty, which buildBonds skips).
std::vector<Bond> fromScratch(const std::vector<bool>& present) {
    Solids s(solids().size());
    for (std::size_t i = 0; i < s.size(); ++i)
        if (present[i])
            s[i] = solids()[i];
    return buildBonds(s, StructurePolicy{}.bonds);
}

} // namespace

TEST(BondGraphUpdate, RealPiecesGiveBondsAcrossCutFacesAndContacts) {
    ASSERT_GT(solids().size(), 30u);
    std::vector<bool> all(solids().size(), true);
    EXPECT_GT(fromScratch(all).size(), solids().size())
        << "pieces bond to each other, not only to the ground";
}

TEST(BondGraphUpdate, AnyAddRemoveSequenceEqualsAFromScratchBuild) {
    const std::size_t n = solids().size();
    BondGraph graph(StructurePolicy{}.bonds, 0.5);
    std::vector<bool> present(n, false);
    Rng rng(3);
    for (int op = 0; op < 400; ++op) {
        const std::uint32_t id = static_cast<std::uint32_t>(rng.below(n));
        if (present[id]) {
            const std::vector<std::uint32_t> neighbours = graph.remove(id);
            for (std::uint32_t m : neighbours)
                EXPECT_TRUE(present[m]);
        } else {
            for (const Bond& b : graph.add(id, solids()[id]))
                EXPECT_TRUE((b.a == id || b.b == id) && b.a < b.b && present[b.a == id ? b.b : b.a]);
        }
        present[id] = !present[id];
        if (op % 20 != 19)
            continue;
        const std::vector<Bond> expected = fromScratch(present), got = graph.bonds();
        ASSERT_EQ(got.size(), expected.size()) << "after " << op + 1 << " operations";
        EXPECT_EQ(graph.bondCount(), expected.size());
        for (std::size_t i = 0; i < got.size(); ++i) {
            EXPECT_EQ(got[i].a, expected[i].a);
            EXPECT_EQ(got[i].b, expected[i].b);
            EXPECT_EQ(got[i].section.area, expected[i].section.area) << "the same computation, bit for bit";
            EXPECT_EQ(got[i].section.corners.size(), expected[i].section.corners.size());
        }
    }
}

// The runtime's monitor: bodies come and go (as a fracture replaces a body by its pieces), hits damage and
// break bonds; every other bond keeps its health, a broken bond stays broken, and the bonds equal a
// from-scratch build (pairs, areas, centroids, normals).
TEST(BondGraphUpdate, TheMonitorKeepsUntouchedBondsAndEqualsAFromScratchBuild) {
    const std::size_t n = solids().size();
    StructurePolicy policy;
    policy.enabled = true;
    policy.damagePerImpulse = 1e-3;
    detail::StructureMonitor monitor(policy);
    const Material& steel = *findMaterial("steel");
    std::vector<bool> present(n, false);
    auto body = [](std::size_t i) { return static_cast<BodyId>(i + 1); };
    using Pair = std::pair<BodyId, BodyId>;
    auto healthByPair = [&] {
        std::map<Pair, double> out;
        for (const StructureBond& b : monitor.bonds()) {
            EXPECT_LT(b.a, b.b);
            out[{b.a, b.b}] = b.health;
        }
        return out;
    };
    std::set<Pair> broken;
    Rng rng(11);
    int checked = 0, damaged = 0;
    for (int op = 0; op < 300; ++op) {
        const std::size_t id = rng.below(n);
        const std::map<Pair, double> before = healthByPair();
        if (present[id])
            monitor.remove(body(id));
        else
            monitor.add(body(id), solids()[id], steel, id == 0, id); // each piece its own solid: bearings off
        present[id] = !present[id];
        const std::map<Pair, double> after = healthByPair();
        for (const auto& [pair, health] : before) {
            if (pair.first == body(id) || pair.second == body(id)) {
                EXPECT_FALSE(after.count(pair)) << "a removed body's bonds go";
                continue;
            }
            ASSERT_TRUE(after.count(pair)) << "an untouched bond stays";
            EXPECT_EQ(after.at(pair), health) << "... with its health";
            ++checked;
        }
        for (const auto& [pair, health] : after) {
            if (!before.count(pair)) {
                EXPECT_EQ(health, 1) << "only the new body's bonds are new";
            }
            EXPECT_FALSE(broken.count(pair)) << "a broken bond stays broken";
        }
        std::erase_if(broken, [&](const Pair& p) { return p.first == body(id) || p.second == body(id); });
        // A hit somewhere in the frame weakens (and may break) bonds near it; gravity off: nothing overloads.
        monitor.damage(rng.inBox({-1.5, 0, -1}, {2.3, 2.3, 1}), rng.uniform(0, 1500));
        int none = 0;
        (void)monitor.step({0, 0, 0}, none);
        const std::map<Pair, double> hit = healthByPair();
        for (const auto& [pair, health] : after) {
            if (!hit.count(pair))
                broken.insert(pair);
            else
                damaged += hit.at(pair) < health;
        }
        if (op % 25 != 24)
            continue;
        const std::vector<Bond> expected = fromScratch(present);
        const std::vector<StructureBond> got = monitor.bonds();
        std::size_t k = 0;
        for (const Bond& e : expected) {
            const Pair p{body(e.a), body(e.b)};
            if (broken.count(p))
                continue;
            ASSERT_LT(k, got.size());
            EXPECT_EQ(Pair(got[k].a, got[k].b), p);
            EXPECT_NEAR(got[k].area, e.section.area, 1e-4 * e.section.area) << "computed from the other side";
            EXPECT_LT(length(got[k].centroid - e.section.centroid), 2 * policy.bonds.gap);
            EXPECT_GT(dot(got[k].normal, e.section.normal), 0.999);
            ++k;
        }
        EXPECT_EQ(k, got.size());
    }
    EXPECT_GT(checked, 1000) << "enough untouched bonds were compared";
    EXPECT_GT(damaged, 50);
    EXPECT_GT(broken.size(), 5u);
}

} // namespace rubble
