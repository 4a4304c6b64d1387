// The world's own work per hit follows the cut, not the mesh (issue #29): a large remainder cut in place
// keeps its parent's frame and the kernel's mass properties, and its hash waits until it is read.
#include <gtest/gtest.h>

#include "TestSupport.hpp"
#include "ToyPhysics.hpp"
#include "WorldSteps.hpp"
#include "geometry/MeshTopology.hpp"
#include "rubble/core/ThreadPool.hpp"
#include "rubble/geometry/MassProperties.hpp"
#include "rubble/persist/WorldState.hpp"
#include "rubble/runtime/DestructionRuntime.hpp"
#include "rubble/runtime/DestructionWorld.hpp"

namespace rubble {
namespace {

struct Hit {
    std::size_t triangles = 0; // of the object
    std::uint64_t touched = 0; // TimingRecord::touchedTriangles
    std::size_t remainderTriangles = 0;
};

// A UV sphere of radius r with slices 160·r and stacks 80·r (the same triangle size at its equator for every
// r), hit at the equator by one cell of fixed size: the same cut on a mesh of ~25k·r² triangles.
Hit hitSphere(int r) {
    DestructionWorld::Config c;
    c.workers = 1;
    c.deterministic = true;
    c.delayFrames = 0;
    DestructionWorld w(c);
    ObjectDesc d;
    d.mesh = makeSphere({0, 0, 0}, r, 160 * r, 80 * r);
    d.convexParts = {ConvexPolytope::fromAabb(d.mesh.bounds())}; // no decomposition of the sphere
    d.fracture.sizeLaw.base = 0.4;
    d.fracture.sizeLaw.scale = 0;
    Hit h;
    h.triangles = d.mesh.triangles.size();
    const ObjectId id = w.addObject(std::move(d)).value();
    const double volume = w.object(id)->mass.volume;
    EXPECT_TRUE(w.submitImpact(id, Impact{{r - 1e-3, 0.01, 0.02}, {1, 0, 0}, 10}));
    w.beginFrame();
    const auto out = collectAndCommit(w);
    EXPECT_EQ(out.size(), 1u);
    if (out.size() != 1)
        return h;
    EXPECT_EQ(w.timings().size(), 1u);
    h.touched = w.timings().back().touchedTriangles;
    double v = out[0].droppedVolume + out[0].dustVolume();
    for (const AdoptedPiece& p : out[0].pieces) {
        const ObjectState& s = *p.state;
        v += s.mass.volume;
        if (p.cell >= 0)
            continue;
        h.remainderTriangles = s.mesh.triangles.size();
        EXPECT_GT(h.remainderTriangles, kTopologyAboveTriangles);
        // in its parent's frame, with the kernel's mass properties: those of its mesh
        EXPECT_EQ(p.frame.translation, Vec3{});
        EXPECT_LT(test::massError(s.mesh, s.mass), 1e-9);
        EXPECT_EQ(s.meshHash, 0u); // not read yet
    }
    EXPECT_NEAR(v, volume, 1e-9 * volume);
    // read: every mesh hash is computed, and a world loaded from the state has the same geometry
    const std::uint64_t geometry = w.geometryHash();
    for (ObjectId o : w.objects())
        EXPECT_EQ(w.object(o)->meshHash, w.object(o)->mesh.hash());
    DestructionWorld loaded(c);
    EXPECT_TRUE(restoreState(loaded, captureState(w)));
    EXPECT_EQ(loaded.geometryHash(), geometry);
    return h;
}

TEST(RuntimeLocality, TrianglesTouchedPerHitFollowTheCutNotTheMesh) {
    const Hit small = hitSphere(1), large = hitSphere(2);
    ASSERT_GT(small.remainderTriangles, 0u);
    ASSERT_GT(large.remainderTriangles, 0u);
    EXPECT_GT(large.triangles, 3 * small.triangles);
    // the same cut on four times the triangles: a pass over the remainder would read four times as many
    EXPECT_LT(large.touched, 2 * small.touched + 2000);
    EXPECT_LT(large.touched, large.remainderTriangles / 4);
}

// In the runtime, such a remainder stays where its parent was, and its body sits at its centre of mass: the
// offset between body and mesh is its mass properties' frame.
TEST(RuntimeLocality, ALargeRemainderStaysInPlaceWithItsBodyAtItsCentreOfMass) {
    test::ToyPhysics engine;
    DestructionRuntime::Config c;
    c.world.workers = 1;
    c.world.deterministic = true;
    DestructionRuntime runtime(engine, c);
    ObjectDesc d;
    d.mesh = makeSphere({0, 0, 0}, 1, 160, 80);
    d.convexParts = {ConvexPolytope::fromAabb(d.mesh.bounds())};
    d.fracture.sizeLaw.base = 0.4;
    d.fracture.sizeLaw.scale = 0;
    Frame placement; // a quarter turn about y, then up and aside
    placement.rotation.m[0][0] = placement.rotation.m[2][2] = 0;
    placement.rotation.m[0][2] = 1;
    placement.rotation.m[2][0] = -1;
    placement.translation = {3, 2, 1};
    const ObjectId id = runtime.addObject(std::move(d), placement, true).value();
    const BodyId body = runtime.bodyOf(id)->id;
    ASSERT_TRUE(runtime.submitImpact(body, placement.apply({1 - 1e-3, 0.01, 0.02}),
                                     placement.rotation * Vec3{1, 0, 0}, 10));
    std::vector<AdoptedPiece> pieces;
    runtime.setOnAdopted([&](const FractureOutcome& o) { pieces = o.pieces; });
    for (int i = 0; i < 10 && pieces.empty(); ++i)
        runtime.stepFrame();
    ASSERT_FALSE(pieces.empty());
    int remainders = 0;
    for (const AdoptedPiece& p : pieces) {
        if (p.cell >= 0)
            continue;
        ++remainders;
        const Vec3 com = p.state->mass.centerOfMass;
        EXPECT_GT(length(com), 1e-4); // the chip at +x moved it
        const BodyRecord* r = runtime.bodyOf(p.id);
        ASSERT_NE(r, nullptr);
        const Frame bodyFrame = runtime.motion(r->id).transform;
        EXPECT_LT(length(bodyFrame.translation - placement.apply(com)), 1e-9);
        const Frame objectToWorld = bodyFrame * r->objectToBody.inverse();
        EXPECT_LT(length(objectToWorld.translation - placement.translation), 1e-9);
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j)
                EXPECT_NEAR(objectToWorld.rotation.m[i][j], placement.rotation.m[i][j], 1e-9);
    }
    EXPECT_EQ(remainders, 1);
}

} // namespace
} // namespace rubble
