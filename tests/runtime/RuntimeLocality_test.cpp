// The world's own work per hit follows the cut, not the mesh (issue #29): a large remainder cut in place
// keeps its parent's frame and the kernel's mass properties, and its hash waits until it is read.
#include <gtest/gtest.h>

#include "TestSupport.hpp"
#include "rubble/DestructionWorld.hpp"
#include "rubble/MassProperties.hpp"
#include "rubble/MeshTopology.hpp"
#include "rubble/ThreadPool.hpp"

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
    const auto out = w.collect();
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
    EXPECT_TRUE(loaded.loadState(w.saveState()));
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

} // namespace
} // namespace rubble
