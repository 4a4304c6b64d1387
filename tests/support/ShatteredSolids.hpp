#pragma once
// Solids from real fractures, for tests of what is built over pieces (bond graphs): boxes placed in the
// world, each shattered once by DestructionWorld, and their pieces' convex parts in world coordinates.

#include <gtest/gtest.h>

#include <chrono>
#include <vector>

#include "WorldSteps.hpp"
#include "rubble/geometry/ConvexPolytope.hpp"
#include "rubble/geometry/Mesh.hpp"
#include "rubble/runtime/DestructionWorld.hpp"

namespace rubble::test {

/// A box to shatter: its corners and where it is hit (world coordinates).
struct ShatterBox {
    Vec3 lo, hi;    ///< corners
    Vec3 hit;       ///< impact point
    int cells = 12; ///< shatter cells
};

/// The pieces of every box (each shattered once, deterministic in seed) as solids: each piece's convex parts
/// in world coordinates, box by box.
inline std::vector<std::vector<ConvexPolytope>> shatteredSolids(const std::vector<ShatterBox>& boxes,
                                                                std::uint64_t seed) {
    DestructionWorld::Config config;
    config.workers = 1;
    config.deterministic = true;
    config.seed = seed;
    DestructionWorld world(config);
    std::vector<std::vector<ConvexPolytope>> out;
    for (const ShatterBox& b : boxes) {
        const Vec3 centre = (b.lo + b.hi) * 0.5, half = (b.hi - b.lo) * 0.5;
        ObjectDesc d;
        d.mesh = makeBox(-1.0 * half, half);
        d.fracture.pattern = CellPattern::Shatter;
        d.fracture.cells = b.cells;
        const Result<ObjectId> id = world.addObject(std::move(d));
        EXPECT_TRUE(id);
        if (!id)
            continue;
        EXPECT_TRUE(world.submitImpact(*id, {b.hit - centre, {0, 1, 0}, 1000}));
        std::vector<FractureOutcome> done;
        for (int frame = 0; frame < 20 && done.empty(); ++frame) {
            world.beginFrame();
            (void)world.waitForResult(std::chrono::steady_clock::now() + std::chrono::seconds(10));
            done = collectAndCommit(world);
        }
        EXPECT_EQ(done.size(), 1u);
        for (const FractureOutcome& o : done)
            for (const AdoptedPiece& p : o.pieces) {
                const Frame toWorld = Frame{Mat3::identity(), centre} * p.frame;
                std::vector<ConvexPolytope> parts;
                for (const ConvexPolytope& c : p.state->convexParts)
                    parts.push_back(c.transformed(toWorld));
                out.push_back(std::move(parts));
            }
    }
    return out;
}

} // namespace rubble::test
