// Which nodes a chain of bonds links to the ground is kept up to date from the bonds lost and gained, and a
// fracture changes the forces only where its load goes: a brick of a welded block replaced by its Voronoi
// pieces balances among them and its neighbours beneath, and what it no longer weighs goes down its column
// to the ground, with no sweep over the rest of the block (docs/structure.md, "Local balance").
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "BoxSolid.hpp"
#include "rubble/fracture/Fracture.hpp"
#include "rubble/structure/BondGraph.hpp"
#include "rubble/structure/StressSolver.hpp"

using namespace rubble;

namespace {

using test::boxSolid;

constexpr double kDensity = 1900;

// Voronoi pieces of a brick (12 cells from a hit on its top, clipped to it), each one solid.
std::vector<std::vector<ConvexPolytope>> shatter(const Aabb& brick) {
    FractureParams params;
    params.pattern = CellPattern::Shatter;
    params.cells = 12;
    params.sizeLaw.base = 1.5;
    params.sizeLaw.scale = 0;
    const Impact hit{{brick.center().x, brick.hi.y, brick.center().z}, {0, 1, 0}, 1000};
    std::vector<std::vector<ConvexPolytope>> out;
    for (ConvexPolytope cell : generateCells(brick, hit, params, 3)) {
        for (int axis = 0; axis < 3 && !cell.empty(); ++axis) {
            Vec3 n;
            n[axis] = 1;
            cell = cell.clipped({n, brick.hi[axis]}).clipped({-1.0 * n, -brick.lo[axis]});
        }
        if (!cell.empty() && cell.volume() > 1e-9)
            out.push_back({std::move(cell)});
    }
    return out;
}

// A welded block of 3 x 4 x 3 bricks (1 x 0.5 x 1 m) on a held ground, converged.
struct Block {
    BondGraph graph;
    StressSolver solver;
    std::uint32_t ground = 0;

    std::uint32_t add(const std::vector<ConvexPolytope>& parts, bool root = false) {
        const std::uint32_t slot = solver.addNode(structureNode(parts, kDensity, root));
        for (Bond& b : graph.add(slot, parts))
            (void)solver.addBond(std::move(b), {});
        return slot;
    }
    std::uint32_t brick(int x, int y, int z) const {
        return 1 + static_cast<std::uint32_t>((y * 3 + z) * 3 + x);
    }
    Block() {
        ground = add(boxSolid({-1, -1, -1}, {4, 0, 4}), true);
        for (int y = 0; y < 4; ++y)
            for (int z = 0; z < 3; ++z)
                for (int x = 0; x < 3; ++x)
                    add(boxSolid({double(x), 0.5 * y, double(z)}, {x + 1.0, 0.5 * y + 0.5, z + 1.0}));
        solver.settings().method = StressMethod::GaussSeidel;
        solver.solve();
    }
    // The bond between two nodes (the first found).
    std::size_t between(std::uint32_t a, std::uint32_t b) const {
        for (std::size_t k : solver.bondsOf(a))
            if (solver.bond(k).other(a) == b)
                return k;
        ADD_FAILURE() << "no bond " << a << "-" << b;
        return 0;
    }
};

} // namespace

TEST(StressLocality, AFracturedBrickBalancesAmongItsPiecesAndPassesWhatItLostDownItsColumn) {
    Block block;
    ASSERT_LE(block.solver.residual(), 1e-3);
    const std::size_t bonds = block.solver.bondCount();
    std::vector<Vec3> before(bonds);
    for (std::size_t k = 0; k < bonds; ++k)
        before[k] = block.solver.bondForce(k);
    const std::uint32_t victim = block.brick(1, 2, 1); // third layer, centre column
    const std::size_t foot = block.between(block.ground, block.brick(1, 0, 1));
    const double footBefore = block.solver.bondForce(foot).y;

    // The brick goes; its pieces but the last (thrown) take its place.
    Aabb bounds;
    bounds.extend(Vec3{1, 1, 1});
    bounds.extend(Vec3{2, 1.5, 2});
    std::vector<std::vector<ConvexPolytope>> pieces = shatter(bounds);
    ASSERT_GE(pieces.size(), 6u);
    pieces.pop_back();
    double kept = 0;
    for (const auto& p : pieces)
        kept += p.front().volume();
    const double lost = (0.5 - kept) * kDensity * 9.81; // the thrown piece and what the cells left out
    ASSERT_GT(lost, 0);
    (void)block.graph.remove(victim);
    block.solver.removeNode(victim);
    std::vector<std::uint32_t> made;
    for (const auto& p : pieces)
        made.push_back(block.add(p));
    block.solver.solve();

    EXPECT_LE(block.solver.residual(), 1e-3);
    EXPECT_EQ(block.solver.sweeps(), 0) << "no sweep over the block: the pieces and the column took it all";
    // Every bond that is neither the pieces' nor in the column beneath them carries what it carried.
    auto piece = [&](std::uint32_t n) { return std::find(made.begin(), made.end(), n) != made.end(); };
    int unchanged = 0;
    for (std::size_t k = 0; k < bonds; ++k) {
        const Bond& b = block.solver.bond(k);
        if (block.solver.broken(k) || piece(b.a) || piece(b.b))
            continue;
        const Vec3 c = b.section.centroid;
        const bool column = c.x > 1 && c.x < 2 && c.z > 1 && c.z < 2 && c.y < 1.01;
        if (!column) {
            EXPECT_EQ(block.solver.bondForce(k), before[k]) << "bond " << k << " at " << c.x << " " << c.y;
            ++unchanged;
        }
    }
    EXPECT_GT(unchanged, 40);
    // The column's foot carries what the brick lost less (to the residual the block was solved to, 1e-3).
    EXPECT_NEAR(std::abs(block.solver.bondForce(foot).y), std::abs(footBefore) - lost,
                1e-3 * std::abs(footBefore));
}

// After any sequence of removed nodes, added nodes and broken bonds, the nodes the solver finds unsupported
// (kept up to date from the changes) are those no chain of intact bonds links to the ground.
TEST(StressLocality, WhatIsCutOffFromTheGroundIsFoundFromTheChangesAlone) {
    BondGraph graph;
    StressSolver solver;
    solver.settings().method = StressMethod::SweepBudget;
    solver.settings().iterations = 1;
    auto add = [&](const std::vector<ConvexPolytope>& parts, bool root = false) {
        const std::uint32_t slot = solver.addNode(structureNode(parts, kDensity, root));
        for (Bond& b : graph.add(slot, parts))
            (void)solver.addBond(std::move(b), {});
        return slot;
    };
    (void)add(boxSolid({-1, -1, -1}, {7, 0, 7}), true);
    // Sixteen columns of six bricks, apart, and slabs on top joining them in pairs: cycles through the top.
    std::vector<std::vector<ConvexPolytope>> cells;
    for (int z = 0; z < 4; ++z)
        for (int x = 0; x < 4; ++x)
            for (int y = 0; y < 6; ++y)
                cells.push_back(
                    boxSolid({1.5 * x, 0.5 * y, 1.5 * z}, {1.5 * x + 1, 0.5 * y + 0.5, 1.5 * z + 1}));
    for (int z = 0; z < 4; ++z)
        for (int x : {0, 2})
            cells.push_back(boxSolid({1.5 * x, 3, 1.5 * z}, {1.5 * x + 2.5, 3.5, 1.5 * z + 1}));
    std::vector<std::int64_t> slotOf(cells.size(), -1); // cell -> its node while present
    for (std::size_t c = 0; c < cells.size(); ++c)
        slotOf[c] = add(cells[c]);
    std::uint64_t state = 12345;
    auto next = [&](std::uint64_t n) {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        return (state >> 33) % n;
    };
    int cutOff = 0;
    for (int step = 0; step < 300; ++step) {
        const int op = static_cast<int>(next(5));
        const std::size_t c = next(cells.size());
        if (op <= 1 && slotOf[c] >= 0) { // a brick goes
            (void)graph.remove(static_cast<std::uint32_t>(slotOf[c]));
            solver.removeNode(static_cast<std::uint32_t>(slotOf[c]));
            slotOf[c] = -1;
        } else if (op == 4 && slotOf[c] < 0) { // a brick comes back
            slotOf[c] = add(cells[c]);
        } else if ((op == 2 || op == 3) && slotOf[c] >= 0) { // one of its bonds breaks
            const auto& bonds = solver.bondsOf(static_cast<std::uint32_t>(slotOf[c]));
            if (!bonds.empty())
                solver.breakBond(bonds[next(bonds.size())]);
        }
        if (step == 100) // a held block on its own (an anchor: a floating object's kept piece)
            (void)add(boxSolid({20, 20, 20}, {21, 21, 21}), true);
        solver.solve();
        // The truth: a search from the held nodes over intact bonds.
        std::vector<char> linked(solver.nodeCount(), 0);
        std::vector<std::uint32_t> open;
        for (std::uint32_t n = 0; n < solver.nodeCount(); ++n)
            if (solver.present(n) && solver.root(n)) {
                linked[n] = 1;
                open.push_back(n);
            }
        while (!open.empty()) {
            const std::uint32_t n = open.back();
            open.pop_back();
            for (std::size_t k : solver.bondsOf(n)) {
                const std::uint32_t m = solver.bond(k).other(n);
                if (!solver.broken(k) && !linked[m]) {
                    linked[m] = 1;
                    open.push_back(m);
                }
            }
        }
        std::vector<std::uint32_t> expected;
        for (std::uint32_t n = 0; n < solver.nodeCount(); ++n)
            if (solver.present(n) && !linked[n])
                expected.push_back(n);
        ASSERT_EQ(solver.unsupported(), expected) << "step " << step;
        cutOff = std::max(cutOff, static_cast<int>(expected.size()));
    }
    EXPECT_GT(cutOff, 10) << "some bricks were cut off on the way";
}
