#pragma once
// A small destructible scene shared by the journal, snapshot and netplay tests: a wall, a column and a slab
// on the ground of the toy engine, shot at by projectiles, with a small awake budget so that debris retires
// (journaled removals) as well as breaks.

#include <vector>

#include "ToyPhysics.hpp"
#include "rubble/geometry/Mesh.hpp"
#include "rubble/runtime/DestructionRuntime.hpp"

namespace rubble::test {

/// One object of the scene.
struct SceneObject {
    ObjectDesc desc; ///< mesh, density, fracture parameters
    Frame placement; ///< world ← object
    bool isStatic{}; ///< static (structural) or dynamic
};

/// Deterministic runtime settings with the given worker count.
inline DestructionRuntime::Config journalConfig(int workers) {
    DestructionRuntime::Config c;
    c.world.workers = workers;
    c.world.deterministic = true;
    c.world.seed = 11;
    c.world.minPieceVolume = 1e-3;
    c.debris.maxAwakeBodies = 8;
    return c;
}

/// The scene's objects, in the order they are added.
inline std::vector<SceneObject> journalScene() {
    auto object = [](const Vec3& half, const Vec3& centre, bool isStatic, CellPattern pattern, int cells,
                     double size) {
        SceneObject o;
        o.desc.mesh = makeBox(-1.0 * half, half);
        o.desc.density = 500;
        o.desc.impulseThreshold = 1;
        o.desc.fracture.pattern = pattern;
        o.desc.fracture.cells = cells;
        o.desc.fracture.seedPoints = 6;
        o.desc.fracture.sizeLaw.base = o.desc.fracture.sizeLaw.minSize = o.desc.fracture.sizeLaw.maxSize =
            size;
        o.desc.fracture.sizeLaw.scale = 0;
        o.placement = Frame{Mat3::identity(), centre};
        o.isStatic = isStatic;
        return o;
    };
    return {object({0.25, 1.5, 2}, {0, 1.5, 0}, true, CellPattern::Shatter, 5, 1.2),
            object({0.4, 2, 0.4}, {0, 2, 4}, true, CellPattern::SingleCell, 6, 0.9),
            object({1, 0.2, 1}, {3, 3.2, -3}, false, CellPattern::Shatter, 4, 1.0)};
}

/// A runtime over the toy engine with the scene loaded.
struct JournalRig {
    explicit JournalRig(int workers) : runtime(engine, journalConfig(workers)) {
        runtime.addGround({0, -0.5, 0}, {50, 0.5, 50});
        for (SceneObject& o : journalScene())
            EXPECT_TRUE(runtime.addObject(std::move(o.desc), o.placement, o.isStatic));
    }
    /// Steps `frames` frames firing a projectile every `every` frames (counted across calls) at the wall and
    /// the column.
    void play(int frames, int every = 7) {
        for (int i = 0; i < frames; ++i) {
            const int f = played++;
            if (f % every == 0) {
                const double y = 0.4 + 0.37 * (f % 11);
                const double z = (f / every) % 2 == 0 ? -1.5 + 0.29 * (f % 13) : 4.0;
                runtime.fireProjectile({-12, y, z}, {120, 0, 0}, 5, 0.1);
            }
            runtime.stepFrame();
        }
    }
    /// Steps until no fracture job is in flight.
    void settle() {
        for (int i = 0; i < 600 && runtime.world().jobsInFlight() > 0; ++i)
            runtime.stepFrame();
    }
    ToyPhysics engine;
    DestructionRuntime runtime;
    int played = 0; ///< frames played
};

/// A bare world (no engine) with the scene's objects: what a replay or a client starts from.
inline std::unique_ptr<DestructionWorld> journalWorld(int workers) {
    auto world = std::make_unique<DestructionWorld>(journalConfig(workers).world);
    for (SceneObject& o : journalScene())
        EXPECT_TRUE(world->addObject(std::move(o.desc)));
    return world;
}

/// The live object of the largest volume (the first of equals; 0 in an empty world).
inline ObjectId largestObject(const DestructionWorld& world) {
    ObjectId largest = 0;
    double volume = 0;
    for (ObjectId id : world.objects())
        if (world.object(id)->mass.volume > volume) {
            volume = world.object(id)->mass.volume;
            largest = id;
        }
    return largest;
}

} // namespace rubble::test
