#pragma once
// A deterministic runtime with the stress solver on the toy engine, a ground box and static boxes: the
// structure tests' and the structure snapshot tests' scene.

#include <gtest/gtest.h>

#include "ToyPhysics.hpp"
#include "rubble/geometry/Mesh.hpp"
#include "rubble/runtime/DestructionRuntime.hpp"

namespace rubble::test {

/// The runtime over the toy engine with a 100 x 1 x 100 m ground box under y = 0.
struct StructureRig {
    explicit StructureRig(bool structure, int workers = 1, bool bondDebris = false,
                          double bearingFriction = 0, StressMethod method = StressSettings{}.method)
        : runtime(engine, config(structure, workers, bondDebris, bearingFriction, method)) {
        runtime.addGround({0, -0.5, 0}, {50, 0.5, 50});
    }
    /// Deterministic settings, seed 5, no dust limit.
    static DestructionRuntime::Config config(bool structure, int workers, bool bondDebris,
                                             double bearingFriction = 0,
                                             StressMethod method = StressSettings{}.method) {
        DestructionRuntime::Config c;
        c.world.workers = workers;
        c.world.deterministic = true;
        c.world.seed = 5;
        c.world.minPieceVolume = 0;
        c.structure.enabled = structure;
        c.structure.bondDebris = bondDebris;
        c.structure.bearingFriction = bearingFriction;
        c.structure.stress.method = method;
        return c;
    }
    /// A static box of density 500 (indestructible unless fracture is given).
    ObjectId addBox(const Vec3& lo, const Vec3& hi, const char* material = "", bool destructible = false,
                    const FractureParams& fracture = {}) {
        ObjectDesc d;
        d.fracture = fracture;
        const Vec3 half = (hi - lo) * 0.5;
        d.mesh = makeBox(-1.0 * half, half);
        d.density = 500;
        d.impulseThreshold = 1;
        d.destructible = destructible;
        d.material = material;
        Result<ObjectId> id = runtime.addObject(std::move(d), Frame{Mat3::identity(), (lo + hi) * 0.5}, true);
        EXPECT_TRUE(id) << (id ? "" : id.error().message);
        return id ? *id : 0;
    }
    /// The motion state of an object's body.
    BodyMotionState motionOf(ObjectId id) const { return runtime.bodyOf(id)->motion; }
    ToyPhysics engine;
    DestructionRuntime runtime;
};

} // namespace rubble::test
