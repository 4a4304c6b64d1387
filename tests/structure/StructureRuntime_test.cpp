// The stress solver in the engine-neutral runtime, on the toy engine of tests/support: overstressed bonds
// break and what they held falls through the runtime's collapse path; hits weaken bonds near them.
#include <gtest/gtest.h>

#include "StructureRig.hpp"
#include "TestSupport.hpp"
#include "rubble/io/SceneConfig.hpp"
#include "rubble/runtime/DestructionRuntime.hpp"
#include "rubble/runtime/SceneLoader.hpp"

namespace rubble {
namespace {

using Rig = test::StructureRig;

} // namespace

TEST(StructureRuntime, AnOverhangThatConnectivityWouldHoldBreaksUnderItsWeight) {
    for (const bool structure : {false, true}) {
        Rig rig(structure);
        rig.addBox({-0.2, 0, -0.2}, {0.2, 3, 0.2});
        // A 6 m slab on the column's 0.4 x 0.4 m top, 5.6 m of it to one side.
        const ObjectId slab = rig.addBox({-0.2, 3, -0.75}, {5.8, 3.2, 0.75});
        // A slab centred on a second column stays.
        const ObjectId column = rig.addBox({9.8, 0, -0.2}, {10.2, 3, 0.2});
        const ObjectId centred = rig.addBox({9.5, 3, -0.5}, {10.5, 3.2, 0.5});
        rig.runtime.stepFrame();
        EXPECT_EQ(rig.motionOf(slab), structure ? BodyMotionState::Dynamic : BodyMotionState::Static);
        EXPECT_EQ(rig.motionOf(centred), BodyMotionState::Static);
        EXPECT_EQ(rig.motionOf(column), BodyMotionState::Static);
        // The overhang's column carries the slab's moment down to its foot, the same 0.4 x 0.4 m section: the
        // first (converged) solve breaks its top and its foot.
        EXPECT_EQ(rig.runtime.counters().bondsBroken, structure ? 2 : 0);
        EXPECT_EQ(rig.runtime.structureBonds().size(), structure ? 2u : 0u) << "ground-column, column-slab";
        // Both broken bonds let go: the overhang's column and the slab fall, a collapse record each, in this
        // frame, the slab's at the slab.
        const std::vector<StructureCollapse>& fell = rig.runtime.structureCollapses();
        ASSERT_EQ(fell.size(), structure ? 2u : 0u);
        if (structure) {
            const BodyRecord& body = *rig.runtime.bodyOf(slab);
            const auto it = std::find_if(fell.begin(), fell.end(),
                                         [&](const StructureCollapse& e) { return e.body == body.id; });
            ASSERT_NE(it, fell.end());
            for (const StructureCollapse& e : fell) {
                EXPECT_EQ(e.frame, rig.runtime.counters().frames);
                EXPECT_TRUE(e.byStress);
                EXPECT_EQ(e.material, "concrete");
            }
            EXPECT_NEAR(it->position.x, 2.8, 1e-6);
            EXPECT_NEAR(it->position.y, 3.1, 1e-6);
            EXPECT_NEAR(it->position.z, 0, 1e-6);
            EXPECT_NEAR(it->volume, 6 * 0.2 * 1.5, 1e-9);
            EXPECT_EQ(it->mass, body.mass);
            EXPECT_GT(it->mass, 0);
        }
    }
}

// Objects resting on each other as bearings: a slab across two columns stands (a weld check of its bending
// over a column top would break it), an overhang tips once its centre of mass is past its column, and a
// block that only touches a column's side is not held by it.
TEST(StructureRuntime, BearingsHoldWhatRestsOnThemAndLetGoOfWhatTipsOrHangs) {
    Rig rig(true, 1, false, 0.6);
    rig.addBox({-0.2, 0, -0.2}, {0.2, 3, 0.2});
    rig.addBox({5.8, 0, -0.2}, {6.2, 3, 0.2});
    const ObjectId bridge = rig.addBox({-0.2, 3, -0.75}, {6.2, 3.2, 0.75}, "concrete");
    rig.addBox({9.8, 0, -0.2}, {10.2, 3, 0.2});
    const ObjectId overhang = rig.addBox({9.8, 3, -0.5}, {12.8, 3.2, 0.5}, "concrete");
    rig.addBox({19.8, 0, -0.2}, {20.2, 3, 0.2});
    const ObjectId side = rig.addBox({20.2, 2, -0.2}, {20.6, 2.4, 0.2}, "concrete");
    for (int i = 0; i < 45; ++i)
        rig.runtime.stepFrame();
    auto height = [&](ObjectId id) {
        return rig.runtime.motion(rig.runtime.bodyOf(id)->id).transform.translation.y;
    };
    EXPECT_EQ(rig.motionOf(bridge), BodyMotionState::Static);
    EXPECT_NE(rig.motionOf(overhang), BodyMotionState::Static) << "centre of mass 1.3 m past the column";
    EXPECT_NE(rig.motionOf(side), BodyMotionState::Static) << "held only by friction with no compression";
    EXPECT_LT(height(side), 2) << "it fell";
    EXPECT_EQ(rig.runtime.counters().bondsBroken, 0) << "bearings fail by letting go, not by breaking";
}

TEST(StructureRuntime, HitsNearACantileversRootWeakenItUntilItFalls) {
    Rig rig(true);
    ASSERT_TRUE(rig.runtime.addConvexBody(makeBox({-1, 0, -2}, {0, 4, 2}).positions, Frame{}, 0));
    // Concrete, h = 0.2, b = 1.5, L = 2: sigma = 3 rho g L^2 / h = 1.41 MPa < f_t = 2.9 MPa: it holds until
    // its root's health drops below 1.41 / 2.9 = 0.49.
    const ObjectId slab = rig.addBox({0, 2, -0.75}, {2, 2.2, 0.75}, "concrete");
    rig.runtime.stepFrame();
    ASSERT_EQ(rig.motionOf(slab), BodyMotionState::Static);
    const BodyId body = rig.runtime.bodyOf(slab)->id;
    auto root = [&] {
        for (const StructureBond& b : rig.runtime.structureBonds())
            if (b.b == body)
                return b;
        ADD_FAILURE() << "no bond at the slab's root";
        return StructureBond{};
    };
    ASSERT_EQ(rig.runtime.structureBonds().size(), 2u) << "wall-ground, wall-slab";
    EXPECT_NEAR(root().area, 0.3, 1e-9);
    EXPECT_NEAR(root().utilisation, 1.41e6 / 2.9e6, 0.01);
    // Each hit 5 cm from the root takes 0.19 of its health (2000 N s * 1e-4 * (1 - 0.05 / 1)).
    std::vector<StructureBreak> events;
    auto step = [&] {
        rig.runtime.stepFrame();
        for (const StructureBreak& e : rig.runtime.structureBreaks())
            events.push_back(e);
    };
    int hits = 0;
    while (rig.motionOf(slab) == BodyMotionState::Static && hits < 6) {
        rig.runtime.submitImpact(body, {0.05, 2.1, 0}, {0, 1, 0}, 2000);
        step();
        ++hits;
        if (hits == 1) // a new static body rebuilds the bond graph: health carries over by body pair
            rig.addBox({20, 0, 20}, {21, 1, 21});
        step();
        if (rig.motionOf(slab) == BodyMotionState::Static) {
            EXPECT_NEAR(root().health, 1 - 0.19 * hits, 1e-9);
        }
    }
    EXPECT_EQ(hits, 3) << "health 0.43 < 0.49";
    EXPECT_EQ(rig.runtime.counters().bondsBroken, 1);
    ASSERT_EQ(events.size(), 1u) << "one break event for the one bond";
    EXPECT_EQ(events[0].b, body);
    EXPECT_NEAR(length(events[0].position - Vec3{0, 2.1, 0}), 0, 1e-9) << "the root's section centroid";
    EXPECT_FALSE(events[0].damaged) << "a weakened root breaks under its load";
    EXPECT_GT(events[0].utilisation, 1);
}

TEST(StructureRuntime, ABoxDroppedOnACantileversTipBreaksItWhenHeavyEnough) {
    // The cantilever above (utilisation 0.49) and a box dropped 1 m on its tip: landing at v = 4.4 m/s, the
    // toy engine reports the impulse m v over the frame, a force of m v / dt at 1.9 m from the root.
    for (const double mass : {10.0, 200.0}) {
        Rig rig(true);
        ASSERT_TRUE(rig.runtime.addConvexBody(makeBox({-1, 0, -2}, {0, 4, 2}).positions, Frame{}, 0));
        const ObjectId slab = rig.addBox({0, 2, -0.75}, {2, 2.2, 0.75}, "concrete");
        ASSERT_TRUE(
            rig.runtime.addConvexBody(makeBox({1.8, 3.2, -0.1}, {2.0, 3.4, 0.1}).positions, Frame{}, mass));
        for (int i = 0; i < 40; ++i)
            rig.runtime.stepFrame();
        // 10 kg: M = 2.6 kN * 1.9 m = 5 kN m adds 0.5 MPa (1.9 < 2.9 MPa); 200 kg: 100 kN m, 10 MPa.
        EXPECT_EQ(rig.motionOf(slab), mass > 100 ? BodyMotionState::Dynamic : BodyMotionState::Static)
            << mass;
    }
}

// The break the dropped box causes, as the record an effect reads: the root's section, the two bodies, the
// frame it broke in and the load it carried (at least the slab's weight, 1440 kg).
TEST(StructureRuntime, ALoadedBeamBreakingReportsItsBreakEventAtItsRoot) {
    Rig rig(true);
    ASSERT_TRUE(rig.runtime.addConvexBody(makeBox({-1, 0, -2}, {0, 4, 2}).positions, Frame{}, 0));
    const ObjectId slab = rig.addBox({0, 2, -0.75}, {2, 2.2, 0.75}, "concrete");
    ASSERT_TRUE(
        rig.runtime.addConvexBody(makeBox({1.8, 3.2, -0.1}, {2.0, 3.4, 0.1}).positions, Frame{}, 200));
    const BodyId body = rig.runtime.bodyOf(slab)->id;
    std::vector<StructureBreak> events;
    std::uint64_t brokeIn = 0;
    for (int i = 0; i < 40; ++i) {
        const FrameStats stats = rig.runtime.stepFrame();
        EXPECT_EQ(rig.runtime.structureBreaks().size(), static_cast<std::size_t>(stats.bondsBroken));
        for (const StructureBreak& e : rig.runtime.structureBreaks()) {
            events.push_back(e);
            brokeIn = rig.runtime.counters().frames;
        }
    }
    ASSERT_EQ(rig.motionOf(slab), BodyMotionState::Dynamic);
    ASSERT_EQ(events.size(), 1u);
    const StructureBreak& e = events[0];
    EXPECT_EQ(e.frame, brokeIn);
    EXPECT_GT(e.frame, 1u) << "the box landed first";
    EXPECT_EQ(e.b, body);
    EXPECT_LT(e.a, e.b);
    EXPECT_NEAR(length(e.position - Vec3{0, 2.1, 0}), 0, 1e-9) << "the root's section centroid";
    EXPECT_NEAR(e.normal.x, 1, 1e-9) << "from the wall to the slab";
    EXPECT_NEAR(e.area, 0.3, 1e-9);
    EXPECT_GT(std::abs(e.force.y), 1440 * 9.81) << "the slab's weight and the box's landing";
    EXPECT_GT(e.utilisation, 1);
    EXPECT_FALSE(e.damaged);
    EXPECT_EQ(e.materialB, "concrete");
}

TEST(StructureRuntime, TheMaterialFieldOfWorldCfgReachesTheStructure) {
    // A wall on the ground and a 2 m cantilever slab (h = 0.2 m) off it, stand-in boxes. Brick (f_t 0.4 MPa):
    // 3 rho g L^2 / h = 1.12 MPa breaks it; wood on the (default concrete) wall: 0.25 MPa < 2.9 MPa holds.
    for (const char* material : {"brick", "wood"}) {
        const std::string text = std::string("a;b;c;d;e;f\n;;0;-15;0;100;10;100;0\n;;0;20;0;1;1;1;1\n") +
                                 "wall.obj;;-0.5;-8;0;1;4;4;0\n" + "slab.obj;;1;-7.9;0;2;0.2;1.5;0;" +
                                 material + "\n";
        const Result<SceneConfig> scene = parseSceneConfigText(text, "world.cfg", "/nonexistent");
        ASSERT_TRUE(scene) << scene.error().message;
        test::ToyPhysics engine;
        DestructionRuntime runtime(engine, Rig::config(true, 1, false));
        SceneLoadOptions options;
        options.loadVehicle = false;
        const LoadedScene loaded = loadScene(*scene, runtime, options);
        ASSERT_EQ(loaded.objects.size(), 2u);
        runtime.stepFrame();
        EXPECT_EQ(runtime.bodyOf(loaded.objects[0])->motion, BodyMotionState::Static);
        EXPECT_EQ(runtime.bodyOf(loaded.objects[1])->motion,
                  std::string(material) == "brick" ? BodyMotionState::Dynamic : BodyMotionState::Static)
            << material;
    }
}

TEST(StructureRuntime, UnknownMaterialIsRefused) {
    Rig rig(true);
    ObjectDesc d;
    d.mesh = makeBox({-1, -1, -1}, {1, 1, 1});
    d.material = "cheese";
    const Result<ObjectId> id = rig.runtime.addObject(std::move(d), Frame{}, true);
    ASSERT_FALSE(id);
    EXPECT_EQ(id.error().message,
              "unknown material 'cheese'; expected one of concrete, brick, stone, wood, glass, steel");
    EXPECT_EQ(rig.runtime.bodyCount(), 1u);
}

// The cut-face area of an object's mesh (triangles of the interior material).
double cutArea(const Mesh& m) {
    double area = 0;
    for (std::size_t t = 0; t < m.triangles.size(); ++t)
        if (m.material(t) == kInteriorMaterial) {
            const auto& tri = m.triangles[t];
            area += length(cross(m.positions[tri[1]] - m.positions[tri[0]],
                                 m.positions[tri[2]] - m.positions[tri[0]])) /
                    2;
        }
    return area;
}

TEST(StructureRuntime, ChipsStayBondedAcrossTheirCutFacesByPolicyAndTheStructureIsTheSameOnOneAndTwoWorkers) {
    auto run = [](int workers, bool bondDebris, std::vector<StructureBond>& bonds) {
        Rig rig(true, workers, bondDebris);
        FractureParams f;
        f.seedPoints = 0;
        f.sizeLaw.base = f.sizeLaw.minSize = f.sizeLaw.maxSize = 2.4;
        f.sizeLaw.scale = 0;
        const ObjectId column = rig.addBox({-0.5, 0, -0.5}, {0.5, 8, 0.5}, "concrete", true);
        rig.addBox({-1.5, 8, -1.5}, {1.5, 8.5, 1.5}, "concrete");
        rig.runtime.stepFrame();
        EXPECT_EQ(rig.runtime.structureBonds().size(), 2u);
        // A hit chips the column: the remainder and one chip (the cell's piece).
        EXPECT_TRUE(rig.runtime.submitLocalImpact(column, Impact{{0.5, 0, 0}, {1, 0, 0}, 100}));
        for (int i = 0; i < 30; ++i)
            rig.runtime.stepFrame();
        EXPECT_EQ(rig.runtime.counters().fractures, 1);
        EXPECT_EQ(rig.runtime.livePieces(), 2);
        bonds = rig.runtime.structureBonds();
        // The chip: the smaller piece. Bonded, its bond is exactly its cut faces (each shared with the
        // remainder).
        const BodyRecord* chip = nullptr;
        for (BodyId b : rig.runtime.bodies())
            if (const BodyRecord* r = rig.runtime.body(b);
                r->role == BodyRole::Piece && (!chip || r->volume < chip->volume))
                chip = r;
        EXPECT_NE(chip, nullptr);
        if (chip) {
            EXPECT_EQ(chip->motion, bondDebris ? BodyMotionState::Static : BodyMotionState::Dynamic);
            const double cut = cutArea(rig.runtime.world().object(chip->object)->mesh);
            EXPECT_GT(cut, 0.01);
            if (bondDebris) {
                EXPECT_EQ(bonds.size(), 3u);
                EXPECT_TRUE(bonds.back().b == chip->id || bonds.back().a == chip->id);
                EXPECT_NEAR(bonds.back().area, cut, 1e-6 * cut) << "every cut face, around the chip's corner";
            } else {
                EXPECT_EQ(bonds.size(), 2u) << "thrown debris has no bonds";
            }
        }
        return rig.runtime.stateHash();
    };
    std::vector<StructureBond> one, two, thrown;
    EXPECT_EQ(run(1, true, one), run(2, true, two));
    ASSERT_EQ(one.size(), two.size());
    for (std::size_t i = 0; i < one.size(); ++i) {
        EXPECT_EQ(one[i].area, two[i].area);
        EXPECT_EQ(one[i].utilisation, two[i].utilisation);
    }
    run(1, false, thrown);
}

} // namespace rubble

namespace rubble {

// The demolition case in small: a slab on two columns, each column shot through at mid-height (one cell, a
// 1 m cube around the hit, takes a band out of it; the stump and the upper part stay static). Connectivity
// keeps the slab up on the other column (the upper part hangs from the slab); the solver lets it tip off the
// remaining column, and the upper part, held by nothing, falls. Shooting the second column out brings it down
// either way.
TEST(StructureRuntime, ShootingAColumnOutFromUnderASlabBringsTheSlabDown) {
    for (const bool structure : {false, true}) {
        SCOPED_TRACE(structure ? "stress solver, bearings" : "connectivity");
        Rig rig(structure, 1, false, 0.6);
        FractureParams cut;
        cut.seedPoints = 0;
        cut.sizeLaw.base = cut.sizeLaw.minSize = cut.sizeLaw.maxSize = 1;
        cut.sizeLaw.scale = 0;
        const ObjectId left = rig.addBox({-0.2, 0, -0.2}, {0.2, 3, 0.2}, "concrete", true, cut);
        const ObjectId right = rig.addBox({5.8, 0, -0.2}, {6.2, 3, 0.2}, "concrete", true, cut);
        const ObjectId slab = rig.addBox({-0.2, 3, -0.75}, {6.2, 3.2, 0.75}, "concrete");
        for (int i = 0; i < 40; ++i)
            rig.runtime.stepFrame();
        ASSERT_EQ(rig.motionOf(slab), BodyMotionState::Static) << "it stands on both";
        auto shoot = [&](ObjectId column, double x) {
            const BodyRecord* r = rig.runtime.bodyOf(column);
            ASSERT_NE(r, nullptr) << "not broken yet";
            ASSERT_TRUE(rig.runtime.submitImpact(r->id, {x, 1.5, 0}, {1, 0, 0}, 100));
            for (int i = 0; i < 60; ++i)
                rig.runtime.stepFrame();
        };
        // Made dynamic (the toy engine then rests it on the highest static top below, and may freeze it).
        auto fell = [&] { return rig.motionOf(slab) != BodyMotionState::Static; };
        shoot(left, 0.2);
        EXPECT_EQ(rig.runtime.counters().fractures, 1);
        EXPECT_EQ(fell(), structure) << "it tips off the remaining column";
        shoot(right, 6.2);
        EXPECT_TRUE(fell());
        if (structure) {
            EXPECT_EQ(rig.runtime.counters().bondsBroken, 0) << "bearings let go; nothing broke";
        }
    }
}

} // namespace rubble

namespace rubble {

// No false collapse: a two-storey building of columns, slabs, a brick wall and a balcony slab, on bearings,
// stands unshot for a simulated minute: no bond breaks, nothing becomes dynamic, and every frame's solve is
// converged. (With the old sweep budget at 1 sweep a frame, 10 at first, it falls; at 2 to 8 it stands on
// solves whose residual reaches 0.02 to 0.4.)
// assets/scenes/tower.cfg: six storeys, each a slab on four pillars (bearings). It stands unshot; without
// the two ground-floor pillars of one side, the first slab rests on one edge, tips, and the storeys above go
// with it: the load brings the tower down, where connectivity alone (the slab still touches two pillars)
// leaves it standing.
TEST(StructureRuntime, ATowerStandsUnshotAndFallsWhenOneSideOfItsBaseIsRemoved) {
    const Result<SceneConfig> scene = parseSceneConfig(test::sourceDir() / "assets/scenes/tower.cfg");
    ASSERT_TRUE(scene) << scene.error().message;
    for (const int mode : {0, 1, 2}) { // Gauss-Seidel, direct, connectivity
        const bool structure = mode < 2;
        SCOPED_TRACE(mode == 0 ? "gauss-seidel" : mode == 1 ? "direct" : "connectivity");
        test::ToyPhysics engine;
        DestructionRuntime runtime(engine,
                                   Rig::config(structure, 1, false, 0.6,
                                               mode == 1 ? StressMethod::Direct : StressMethod::GaussSeidel));
        SceneLoadOptions options;
        options.loadVehicle = false;
        const LoadedScene loaded = loadScene(*scene, runtime, options);
        ASSERT_EQ(loaded.objects.size(), 30u);
        auto standing = [&] {
            int n = 0;
            for (ObjectId id : loaded.objects) {
                const BodyRecord* r = runtime.bodyOf(id); // none once removed
                n += r && r->motion == BodyMotionState::Static;
            }
            return n;
        };
        for (int i = 0; i < 30; ++i)
            runtime.stepFrame();
        EXPECT_EQ(standing(), 30) << "unshot";
        EXPECT_EQ(runtime.counters().piecesCollapsed, 0);
        for (std::size_t k : {0u, 1u}) // the ground floor's pillars at x = -2.7
            runtime.removeBody(runtime.bodyOf(loaded.objects[k])->id);
        for (int i = 0; i < 40; ++i) // unbalanced for 30 solves, then falling
            runtime.stepFrame();
        if (structure) {
            EXPECT_EQ(standing(), 2) << "only the two pillars left at its foot";
        } else {
            EXPECT_EQ(standing(), 28);
        }
    }
}

TEST(StructureRuntime, AnUnshotBuildingStandsForASimulatedMinute) {
    ASSERT_EQ(StructurePolicy{}.stress.method, StressMethod::Auto) << "the runtime's default";
    for (const StressMethod method : {StressMethod::GaussSeidel, StressMethod::Direct, StressMethod::Auto}) {
        SCOPED_TRACE(static_cast<int>(method));
        Rig rig(true, 1, false, 0.6, method);
        std::vector<ObjectId> parts;
        for (int storey = 0; storey < 2; ++storey) {
            const double y = storey * 3.3;
            for (const double x : {0.0, 4.6})
                for (const double z : {0.0, 4.6})
                    parts.push_back(rig.addBox({x, y, z}, {x + 0.4, y + 3, z + 0.4}, "concrete"));
            parts.push_back(rig.addBox({0, y + 3, 0}, {5, y + 3.3, 5}, "concrete"));
        }
        parts.push_back(rig.addBox({0.4, 0, 0.1}, {4.6, 3, 0.3}, "brick")); // a wall under the first slab
        parts.push_back(rig.addBox({1.5, 6.6, 1.5}, {3.5, 7.6, 3.5}, "concrete")); // a tank on the roof
        const int frames = 3600;
        double worst = 0;
        for (int i = 0; i < frames; ++i) {
            const FrameStats fs = rig.runtime.stepFrame();
            worst = std::max(worst, fs.structureResidual);
        }
        EXPECT_EQ(rig.runtime.counters().bondsBroken, 0);
        EXPECT_EQ(rig.runtime.counters().piecesCollapsed, 0);
        for (ObjectId id : parts)
            EXPECT_EQ(rig.motionOf(id), BodyMotionState::Static) << "object " << id;
        EXPECT_LE(worst, 1e-3) << "every frame acted on a converged solve";
    }
}

} // namespace rubble
