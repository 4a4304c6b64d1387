// The engine-neutral runtime on a second binding, the toy engine of tests/support (no Bullet): support and
// collapse, freezing and waking, the debris governor's budgets and exact volume accounting with particles.
#include "rubble/runtime/DestructionRuntime.hpp"
#include "rubble/runtime/JournalPlayer.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>

#include "TestSupport.hpp"
#include "ToyPhysics.hpp"

namespace rubble {
namespace {

// One cell, a randomly rotated cube of the given edge centred at the impact: it cuts through anything
// narrower than size / 2 around the impact.
FractureParams cubeCell(double size) {
    FractureParams f;
    f.seedPoints = 0;
    f.sizeLaw.base = f.sizeLaw.minSize = f.sizeLaw.maxSize = size;
    f.sizeLaw.scale = 0;
    return f;
}

FractureParams shatter(int cells, double size) {
    FractureParams f = cubeCell(size);
    f.pattern = CellPattern::Shatter;
    f.cells = cells;
    return f;
}

struct ToyRig {
    explicit ToyRig(DestructionRuntime::Config config = defaults(), test::ToyPhysics::Config physics = {})
        : engine(physics), runtime(engine, config) {
        runtime.addGround({0, -0.5, 0}, {50, 0.5, 50});
    }
    static DestructionRuntime::Config defaults() {
        DestructionRuntime::Config c;
        c.world.workers = 1;
        c.world.deterministic = true;
        c.world.seed = 5;
        c.world.minPieceVolume = 0;
        return c;
    }
    ObjectId addBox(const Vec3& half, const Vec3& centre, bool isStatic, const FractureParams& fracture = {},
                    bool destructible = true) {
        ObjectDesc d;
        d.destructible = destructible;
        d.mesh = makeBox(-1.0 * half, half);
        d.density = 500;
        d.impulseThreshold = 1;
        d.fracture = fracture;
        Result<ObjectId> id = runtime.addObject(std::move(d), Frame{Mat3::identity(), centre}, isStatic);
        EXPECT_TRUE(id) << (id ? "" : id.error().message);
        return id ? *id : 0;
    }
    double heightOf(ObjectId id) const {
        const BodyRecord* b = runtime.bodyOf(id);
        return b ? runtime.motion(b->id).transform.translation.y : -1e9;
    }
    BodyMotionState motionOf(ObjectId id) const { return runtime.bodyOf(id)->motion; }
    void step(int frames) {
        for (int i = 0; i < frames; ++i)
            runtime.stepFrame();
    }
    // steps until a fracture of `object` was adopted; returns its outcome's pieces
    std::vector<AdoptedPiece> breakAndWait(ObjectId object, int maxFrames = 60) {
        std::vector<AdoptedPiece> out;
        runtime.setOnAdopted([&](const FractureOutcome& o) {
            if (o.parent == object)
                out = o.pieces;
        });
        for (int i = 0; i < maxFrames && out.empty(); ++i)
            runtime.stepFrame();
        runtime.setOnAdopted({});
        return out;
    }
    test::ToyPhysics engine;
    DestructionRuntime runtime;
};

} // namespace

// A placement that is no rigid motion (Mat3{} is the zero matrix) is refused: its impacts had no normal.
TEST(DestructionRuntime, APlacementThatIsNoRigidMotionIsRefused) {
    ToyRig rig;
    const std::size_t bodies = rig.runtime.bodyCount();
    Mat3 stretched = Mat3::identity();
    stretched.m[0][0] = 2;
    Mat3 mirrored = Mat3::identity();
    mirrored.m[2][2] = -1;
    for (const Frame& f : {Frame{Mat3{}, {0, 1, 0}}, Frame{stretched, {0, 1, 0}}, Frame{mirrored, {0, 1, 0}},
                           Frame{Mat3::identity(), {0, std::nan(""), 0}}}) {
        ObjectDesc d;
        d.mesh = makeBox({-1, -1, -1}, {1, 1, 1});
        const Result<ObjectId> id = rig.runtime.addObject(std::move(d), f, true);
        ASSERT_FALSE(id);
        EXPECT_EQ(id.error().code, ErrorCode::InvalidInput);
        EXPECT_NE(id.error().message.find("not a rigid motion"), std::string::npos) << id.error().message;
    }
    EXPECT_EQ(rig.runtime.bodyCount(), bodies);
    EXPECT_TRUE(rig.runtime.world().objects().empty());
}

// A split whose parent no body carries makes no body; its journal replays to the same world.
TEST(DestructionRuntime, ASplitWhoseParentHasNoBodyMakesNoPieceAndItsJournalReplays) {
    ToyRig rig;
    std::vector<JournalEvent> events;
    rig.runtime.setJournalSink([&](const JournalEvent& e) { events.push_back(e); });
    ObjectDesc d;
    d.mesh = makeBox({-1, -1, -1}, {1, 1, 1});
    d.fracture = cubeCell(1.2);
    // No public call makes an object without a body: the test writes to the runtime's own world.
    DestructionWorld& world = const_cast<DestructionWorld&>(rig.runtime.world());
    const ObjectId orphan = *world.addObject(ObjectDesc(d));
    int adopted = 0;
    rig.runtime.setOnAdopted([&](const FractureOutcome&) { ++adopted; });
    EXPECT_FALSE(rig.runtime.submitLocalImpact(orphan, Impact{{1, 0, 0}, {1, 0, 0}, 100})) << "no body";
    ASSERT_TRUE(world.submitImpact(orphan, Impact{{1, 0, 0}, {1, 0, 0}, 100}));
    rig.step(10);
    EXPECT_EQ(rig.runtime.counters().staleOutcomes, 1);
    EXPECT_EQ(adopted, 0);
    EXPECT_TRUE(rig.runtime.world().objects().empty());
    ASSERT_GE(events.size(), 3u); // the impact, then one removal per piece
    EXPECT_NEAR(rig.runtime.volumes().total(), 8.0, 1e-6);
    EXPECT_GT(rig.runtime.volumes().retired, 7.0);

    DestructionWorld replayed(ToyRig::defaults().world);
    ASSERT_EQ(*replayed.addObject(std::move(d)), orphan);
    JournalPlayer player(replayed);
    for (const JournalEvent& e : events)
        ASSERT_TRUE(player.receive(e));
    const Status done = player.advanceTo(rig.runtime.world().frame());
    ASSERT_TRUE(done) << done.message();
    EXPECT_TRUE(replayed.objects().empty());
    EXPECT_EQ(replayed.journalPosition(), events.size());
}

TEST(DestructionRuntime, ColumnCutOnTheToyEngineKeepsItsFootAndDropsWhatItHeld) {
    ToyRig rig;
    const ObjectId column = rig.addBox({0.5, 4, 0.5}, {0, 4, 0}, true, cubeCell(2.4));
    const ObjectId slab = rig.addBox({1.5, 0.25, 1.5}, {0, 8.25, 0}, true);
    rig.step(1);
    ASSERT_FALSE(rig.runtime.bodyOf(slab)->anchor) << "the slab rests on a column that stands on the ground";
    const BodyId columnBody = rig.runtime.bodyOf(column)->id;
    const BodyId slabBody = rig.runtime.bodyOf(slab)->id;
    EXPECT_EQ(rig.runtime.supportNeighbours(slabBody), std::vector<BodyId>{columnBody});

    ASSERT_TRUE(rig.runtime.submitLocalImpact(column, Impact{{0.5, -1.5, 0}, {1, 0, 0}, 100}));
    const std::vector<AdoptedPiece> pieces = rig.breakAndWait(column);
    ASSERT_GE(pieces.size(), 3u);
    EXPECT_EQ(rig.motionOf(slab), BodyMotionState::Dynamic) << "what the column held falls";
    int feet = 0, tops = 0;
    for (const AdoptedPiece& p : pieces) {
        const BodyRecord* b = rig.runtime.bodyOf(p.id);
        ASSERT_NE(b, nullptr);
        const double y = rig.runtime.motion(b->id).transform.translation.y;
        if (p.cell >= 0)
            EXPECT_EQ(b->motion, BodyMotionState::Dynamic) << "debris flies";
        else if (y < 2.5)
            feet += b->motion == BodyMotionState::Static ? 1 : 0;
        else
            tops += b->motion == BodyMotionState::Dynamic ? 1 : 0;
    }
    EXPECT_EQ(feet, 1);
    EXPECT_EQ(tops, 1);
    const double slabBefore = rig.heightOf(slab);
    rig.step(240);
    EXPECT_LT(rig.heightOf(slab), slabBefore - 2) << "the slab fell";
    EXPECT_GT(rig.runtime.counters().piecesCollapsed, 0);
    EXPECT_GT(rig.runtime.counters().piecesFrozen, 0) << "fallen parts came to rest and were frozen";
}

TEST(DestructionRuntime, FrozenPiecesWakeAndBreakWhenHit) {
    ToyRig rig;
    const ObjectId box = rig.addBox({1, 1, 1}, {0, 1, 0}, false, shatter(6, 3));
    ASSERT_TRUE(rig.runtime.submitLocalImpact(box, Impact{{0, 1, 0}, {0, 1, 0}, 50}));
    const std::vector<AdoptedPiece> pieces = rig.breakAndWait(box);
    ASSERT_GE(pieces.size(), 2u);
    rig.step(120);
    // the largest piece has come to rest on the ground and was frozen
    const AdoptedPiece* target = &pieces.front();
    for (const AdoptedPiece& p : pieces)
        if (p.state->mass.volume > target->state->mass.volume)
            target = &p;
    const BodyRecord* b = rig.runtime.bodyOf(target->id);
    ASSERT_NE(b, nullptr);
    ASSERT_EQ(b->motion, BodyMotionState::Frozen);
    EXPECT_EQ(rig.runtime.frozenDebris(), static_cast<int>(rig.runtime.livePieces()));
    const Vec3 at = rig.runtime.motion(b->id).transform.translation;
    rig.runtime.fireProjectile(at + Vec3{-20, 0, 0}, {200, 0, 0}, 5, 0.1);
    const std::vector<AdoptedPiece> again = rig.breakAndWait(target->id, 120);
    EXPECT_GE(rig.runtime.counters().piecesWoken, 1);
    EXPECT_FALSE(again.empty()) << "the frozen piece broke";
    EXPECT_EQ(rig.runtime.bodyOf(target->id), nullptr);
}

TEST(DestructionRuntime, FrozenDebrisWakesWhenWhatItRestsOnFalls) {
    ToyRig rig;
    const ObjectId column = rig.addBox({0.5, 4, 0.5}, {0, 4, 0}, true, cubeCell(2.4));
    const ObjectId slab = rig.addBox({1.5, 0.25, 1.5}, {0, 8.25, 0}, true);
    const ObjectId brick = rig.addBox({0.2, 0.2, 0.2}, {1, 9.0, 1}, false); // dropped onto the slab
    rig.step(90);
    ASSERT_EQ(rig.motionOf(brick), BodyMotionState::Frozen) << "the brick came to rest on the slab";
    ASSERT_NEAR(rig.heightOf(brick), 8.7, 1e-6);
    ASSERT_TRUE(rig.runtime.submitLocalImpact(column, Impact{{0.5, -1.5, 0}, {1, 0, 0}, 100}));
    ASSERT_FALSE(rig.breakAndWait(column).empty());
    ASSERT_NE(rig.motionOf(slab), BodyMotionState::Static);
    rig.step(2);
    EXPECT_GE(rig.runtime.counters().piecesWoken, 1);
    rig.step(240);
    EXPECT_LT(rig.heightOf(brick), 8) << "the brick fell with the slab instead of hanging in the air";
}

// Waking a frozen body does not wake what rests against it while it stays in place (a hit that does not move
// it), only once it leaves its place: otherwise one hit on a pile wakes the whole pile, frame after frame.
TEST(DestructionRuntime, AWokenFrozenBodyWakesItsNeighboursOnlyOnceItLeavesItsPlace) {
    ToyRig rig;
    const ObjectId a = rig.addBox({0.2, 0.2, 0.2}, {0, 0.5, 0}, false, {}, false);
    const ObjectId b = rig.addBox({0.2, 0.2, 0.2}, {0.41, 0.5, 0}, false, {}, false); // 1 cm beside a
    rig.step(90);
    ASSERT_EQ(rig.motionOf(a), BodyMotionState::Frozen);
    ASSERT_EQ(rig.motionOf(b), BodyMotionState::Frozen);
    const BodyId aBody = rig.runtime.bodyOf(a)->id;
    rig.runtime.fireProjectile({-5, 0.2, 0}, {100, 0, 0}, 1, 0.05); // hits a, which cannot break
    for (int i = 0; i < 10 && rig.motionOf(a) == BodyMotionState::Frozen; ++i)
        rig.step(1);
    ASSERT_EQ(rig.motionOf(a), BodyMotionState::Dynamic) << "the hit woke a";
    rig.step(2);
    EXPECT_EQ(rig.motionOf(b), BodyMotionState::Frozen) << "a has not moved: b still rests where it did";
    rig.engine.setVelocity(aBody, {0, 0, 3}, {}); // a slides away
    rig.step(3);
    EXPECT_EQ(rig.motionOf(b), BodyMotionState::Dynamic) << "a left its place: b is woken";
}

// Breaking a static object wakes the frozen debris near the pieces that fly off, not everything inside the
// object's bounds: the remainder still holds what rests on it.
TEST(DestructionRuntime, BreakingAStaticObjectWakesOnlyTheDebrisNearWhatLeaves) {
    ToyRig rig;
    const ObjectId wall = rig.addBox({4, 2, 0.25}, {0, 2, 0}, true, cubeCell(1.0));
    const ObjectId near = rig.addBox({0.2, 0.2, 0.2}, {3.5, 0.2, 0.5}, false, {}, false);
    const ObjectId far = rig.addBox({0.2, 0.2, 0.2}, {-3.5, 0.2, 0.5}, false, {}, false);
    rig.step(90);
    ASSERT_EQ(rig.motionOf(near), BodyMotionState::Frozen);
    ASSERT_EQ(rig.motionOf(far), BodyMotionState::Frozen);
    ASSERT_TRUE(rig.runtime.submitLocalImpact(wall, Impact{{3.6, -1.7, 0.25}, {0, 0, 1}, 100})); // local
    ASSERT_FALSE(rig.breakAndWait(wall).empty());
    rig.step(2);
    EXPECT_EQ(rig.motionOf(near), BodyMotionState::Dynamic) << "debris left beside it";
    EXPECT_EQ(rig.motionOf(far), BodyMotionState::Frozen) << "7 m away, within the wall's bounds";
}

TEST(DestructionRuntime, AwakeBudgetRetiresTheSmallestPiecesButNeverTheGamesObjects) {
    DestructionRuntime::Config c = ToyRig::defaults();
    c.debris.maxAwakeBodies = 5;
    ToyRig rig(c);
    for (int i = 0; i < 3; ++i) // three falling objects of the game: never retired
        rig.addBox({0.5, 0.5, 0.5}, {-10.0 - 3 * i, 40, 0}, false);
    const ObjectId box = rig.addBox({1, 1, 1}, {0, 30, 0}, false, shatter(12, 3));
    ASSERT_TRUE(rig.runtime.submitLocalImpact(box, Impact{{0, 1, 0}, {0, 1, 0}, 50}));
    const double start = rig.runtime.volumes().total();
    const std::vector<AdoptedPiece> pieces = rig.breakAndWait(box);
    ASSERT_GE(pieces.size(), 4u);
    rig.step(1);
    EXPECT_EQ(rig.runtime.counters().piecesRetired, 0) << "new pieces get 10 frames to settle";
    rig.step(11); // falling, so none settled: the smallest retire
    EXPECT_EQ(rig.runtime.awakeDebris(), 5);
    EXPECT_EQ(rig.runtime.livePieces(), 2) << "the three objects take three of the five";
    EXPECT_EQ(rig.runtime.counters().piecesRetired, static_cast<long long>(pieces.size()) - 2);
    EXPECT_EQ(rig.runtime.counters().retired.awake, static_cast<long long>(pieces.size()) - 2);
    std::vector<double> kept, all;
    for (const AdoptedPiece& p : pieces) {
        all.push_back(p.state->mass.volume);
        if (rig.runtime.bodyOf(p.id))
            kept.push_back(p.state->mass.volume);
    }
    std::sort(all.rbegin(), all.rend());
    std::sort(kept.rbegin(), kept.rend());
    EXPECT_EQ(kept, std::vector<double>(all.begin(), all.begin() + 2)) << "the two largest pieces stay";
    const VolumeLedger v = rig.runtime.volumes();
    EXPECT_GT(v.retired, 0);
    EXPECT_NEAR(v.total(), start, 1e-12 * start);
}

TEST(DestructionRuntime, AwakeBudgetFreezesSettledPiecesBeforeRetiringAny) {
    DestructionRuntime::Config c = ToyRig::defaults();
    c.debris.maxAwakeBodies = 2;
    c.debris.freezeSleeping = false;
    c.debris.freezeAfterFrames = 100000; // only the budget freezes here
    ToyRig rig(c);
    const ObjectId box = rig.addBox({1, 0.05, 1}, {0, 0.05, 0}, false, shatter(8, 3)); // a tile on the ground
    ASSERT_TRUE(rig.runtime.submitLocalImpact(box, Impact{{0, 0.1, 0}, {0, 1, 0}, 50}));
    const std::vector<AdoptedPiece> pieces = rig.breakAndWait(box);
    ASSERT_GE(pieces.size(), 4u);
    const int live = rig.runtime.livePieces();
    rig.step(30);
    EXPECT_EQ(rig.runtime.counters().piecesRetired, 0) << "settled pieces freeze instead of retiring";
    EXPECT_EQ(rig.runtime.livePieces(), live);
    EXPECT_LE(rig.runtime.awakeDebris(), 2);
    EXPECT_GE(rig.runtime.frozenDebris(), live - 2);
}

TEST(DestructionRuntime, TriangleBudgetAndFadingRetireDebris) {
    DestructionRuntime::Config c = ToyRig::defaults();
    ToyRig rig(c);
    const ObjectId box = rig.addBox({1, 1, 1}, {0, 1, 0}, false, shatter(8, 3));
    ASSERT_TRUE(rig.runtime.submitLocalImpact(box, Impact{{0, 1, 0}, {0, 1, 0}, 50}));
    ASSERT_GE(rig.breakAndWait(box).size(), 4u);
    const std::size_t before = rig.runtime.debrisTriangles();
    DebrisBudget budget = rig.runtime.config().debris;
    budget.maxTriangles = before / 2;
    rig.runtime.setDebrisBudget(budget);
    rig.step(1);
    EXPECT_LE(rig.runtime.debrisTriangles(), before / 2);
    EXPECT_GT(rig.runtime.debrisTriangles(), 0u);
    EXPECT_GT(rig.runtime.counters().piecesRetired, 0);
    EXPECT_EQ(rig.runtime.counters().retired.triangles, rig.runtime.counters().piecesRetired);

    DestructionRuntime::Config f = ToyRig::defaults();
    f.debris.fadeVolume = 0.05;
    f.debris.fadeDistance = 10;
    ToyRig far(f);
    far.runtime.setFocus({0, 0, 0});
    const ObjectId nearBox = far.addBox({1, 1, 1}, {0, 1, 0}, false, shatter(8, 3));
    const ObjectId farBox = far.addBox({1, 1, 1}, {30, 1, 0}, false, shatter(8, 3));
    const ObjectId farObject = far.addBox({0.1, 0.1, 0.1}, {30, 0.1, 5}, false);
    ASSERT_TRUE(far.runtime.submitLocalImpact(nearBox, Impact{{0, 1, 0}, {0, 1, 0}, 50}));
    ASSERT_TRUE(far.runtime.submitLocalImpact(farBox, Impact{{0, 1, 0}, {0, 1, 0}, 50}));
    far.step(3); // adopted, then governed
    int nearSmall = 0, farSmall = 0;
    for (BodyId id : far.runtime.bodies())
        if (const BodyRecord* b = far.runtime.body(id); b->role == BodyRole::Piece && b->volume < 0.05)
            (far.runtime.motion(id).transform.translation.x > 15 ? farSmall : nearSmall) += 1;
    EXPECT_GT(nearSmall, 0);
    EXPECT_EQ(farSmall, 0) << "tiny pieces far from the focus faded";
    EXPECT_NE(far.runtime.bodyOf(farObject), nullptr) << "the game's own objects never fade";
    EXPECT_GT(far.runtime.counters().retired.faded, 0);
    EXPECT_EQ(far.runtime.counters().retired.faded, far.runtime.counters().piecesRetired);
}

// Policies set between frames govern what follows: impact marks kept, and a static object's remainder.
TEST(DestructionRuntime, PoliciesSetBetweenFramesGovernWhatFollows) {
    ToyRig rig;
    const ObjectId box = rig.addBox({1, 1, 1}, {0, 1, 0}, true, cubeCell(1.2));
    const ObjectId other = rig.addBox({1, 1, 1}, {5, 1, 0}, true, cubeCell(1.2));
    rig.step(1);
    ImpactPolicy impacts = rig.runtime.config().impacts;
    impacts.maxImpactMarks = 1;
    rig.runtime.setImpactPolicy(impacts);
    AdoptionPolicy adoption = rig.runtime.config().adoption;
    adoption.keepStaticRemainder = false;
    rig.runtime.setAdoptionPolicy(adoption);
    EXPECT_EQ(rig.runtime.config().impacts.maxImpactMarks, 1);
    ASSERT_TRUE(rig.runtime.submitLocalImpact(other, Impact{{1, 0, 0}, {1, 0, 0}, 50}));
    ASSERT_TRUE(rig.runtime.submitLocalImpact(box, Impact{{1, 0, 0}, {1, 0, 0}, 50}));
    EXPECT_EQ(rig.runtime.recentImpacts().size(), 1u);
    const std::vector<AdoptedPiece> pieces = rig.breakAndWait(box);
    ASSERT_GE(pieces.size(), 2u);
    for (const AdoptedPiece& p : pieces)
        EXPECT_EQ(rig.motionOf(p.id), BodyMotionState::Dynamic) << "piece " << p.id << " of cell " << p.cell;
}

TEST(DestructionRuntime, VolumeAccountingIsExactWithDustParticlesAndRetirement) {
    DestructionRuntime::Config c = ToyRig::defaults();
    c.world.minPieceVolume = 0.05; // the smaller shatter pieces become dust
    c.debris.maxAwakeBodies = 4;
    ToyRig rig(c);
    const ObjectId a = rig.addBox({1, 1, 1}, {0, 1, 0}, true, shatter(12, 1.5));
    const ObjectId b = rig.addBox({0.5, 2, 0.5}, {5, 2, 0}, false, shatter(8, 1.2));
    for (int i = 0; i < 4; ++i) // falling while the shatters land: more awake debris than the budget
        rig.addBox({0.3, 0.3, 0.3}, {-5.0 - i, 30, 0}, false);
    const double start = rig.runtime.volumes().total();
    ASSERT_TRUE(rig.runtime.submitLocalImpact(a, Impact{{1, 0.5, 0}, {1, 0, 0}, 80}));
    ASSERT_TRUE(rig.runtime.submitLocalImpact(b, Impact{{0.5, 1, 0}, {1, 0, 0}, 80}));
    rig.step(200);
    const VolumeLedger v = rig.runtime.volumes();
    EXPECT_GT(rig.runtime.counters().fractures, 1);
    EXPECT_GT(v.dust, 0) << "some pieces were below the minimum volume";
    EXPECT_GT(v.retired, 0) << "the awake budget retired some pieces";
    const RuntimeCounters& n = rig.runtime.counters();
    EXPECT_GT(n.retired.dust, 0);
    EXPECT_GT(n.retired.awake, 0);
    EXPECT_EQ(n.retired.total(), n.piecesRetired) << "every retirement has one reason";
    EXPECT_LT(std::abs(v.total() - start) / start, 1e-9);
}

// Each piece body a split makes is one record, with its body's place, motion, volume and mass and the impulse
// that broke its parent; the pieces' and the dust's volumes add up to the parent's; records last one frame.
TEST(DestructionRuntime, EachPieceMadeIsARecordOfItsBodyAndTheImpulseThatBrokeIt) {
    DestructionRuntime::Config c = ToyRig::defaults();
    c.world.minPieceVolume = 0.01;
    ToyRig rig(c);
    const ObjectId box = rig.addBox({1, 1, 1}, {0, 1, 0}, true, shatter(12, 1.5));
    ASSERT_TRUE(rig.runtime.submitLocalImpact(box, Impact{{1, 0.5, 0}, {1, 0, 0}, 80}));
    FrameStats stats;
    for (int i = 0; i < 10 && rig.runtime.createdPieces().empty(); ++i)
        stats = rig.runtime.stepFrame();
    const std::vector<PieceCreated> made = rig.runtime.createdPieces();
    ASSERT_GT(made.size(), 2u);
    EXPECT_EQ(made.size(), static_cast<std::size_t>(stats.piecesCreated));
    double volume = 0;
    int statics = 0;
    for (const PieceCreated& p : made) {
        const BodyRecord* r = rig.runtime.body(p.body);
        ASSERT_NE(r, nullptr);
        EXPECT_EQ(r->role, BodyRole::Piece);
        EXPECT_EQ(r->object, p.object);
        EXPECT_EQ(p.parent, box);
        EXPECT_EQ(p.frame, rig.runtime.counters().frames);
        const BodyMotion m = rig.runtime.motion(p.body);
        EXPECT_LT(length(m.transform.translation - p.position), 1e-9);
        EXPECT_LT(length(m.linearVelocity - p.velocity), 1e-9);
        EXPECT_DOUBLE_EQ(p.volume, r->volume);
        EXPECT_NEAR(p.mass, 500 * p.volume, 1e-9);
        EXPECT_NEAR(p.size * p.size * p.size, p.volume, 1e-12);
        EXPECT_NEAR(p.impulse, 80, 1e-4);
        EXPECT_EQ(p.material, "concrete");
        statics += p.isStatic;
        volume += p.volume;
    }
    EXPECT_GE(statics, 1) << "the kept part of the static box";
    EXPECT_LT(statics, static_cast<int>(made.size())) << "and the thrown debris";
    const VolumeLedger v = rig.runtime.volumes();
    EXPECT_NEAR(volume + v.dust + v.dropped, 8, 1e-9);
    rig.runtime.stepFrame();
    EXPECT_TRUE(rig.runtime.createdPieces().empty());
}

TEST(DestructionRuntime, BlastHitsEveryObjectInRangeWithAnImpulseFallingOffToItsEdge) {
    ToyRig rig;
    std::vector<ObjectId> boxes;
    for (int i = 4; i >= 0; --i) // centres 12, 9, 6, 3, 0 m from the blast; bounding radius sqrt(0.75)
        boxes.push_back(rig.addBox({0.5, 0.5, 0.5}, {3.0 * i, 0.5, 0}, true));
    std::reverse(boxes.begin(), boxes.end()); // boxes[i] at 3 i m, the nearest made last
    const ObjectId sturdy = rig.addBox({0.5, 0.5, 0.5}, {0, 0.5, 3}, true, {}, false); // not destructible
    std::vector<JournalEvent> hits;
    rig.runtime.setJournalSink([&](const JournalEvent& e) { hits.push_back(e); });
    const double radius = 7, impulse = 1000;
    EXPECT_EQ(rig.runtime.blast({0, 0.5, 0}, radius, impulse).impacts, 3)
        << "the boxes within 7 m plus their radius";
    ASSERT_EQ(hits.size(), 3u);
    double last = 2 * impulse;
    for (std::size_t i = 0; i < hits.size(); ++i) {
        EXPECT_EQ(hits[i].object, boxes[i]) << "nearest first";
        const double dist = 3.0 * static_cast<double>(i), r = std::sqrt(0.75);
        const double share = 1 - 0.6 * std::clamp((dist - r) / radius, 0.0, 1.0);
        EXPECT_NEAR(hits[i].impulse, impulse * share, 1e-6 * impulse); // the journal keeps floats
        EXPECT_LE(hits[i].impulse, last) << "farther is weaker";
        EXPECT_GE(hits[i].impulse, 0.4 * impulse);
        last = hits[i].impulse;
        if (i > 0) { // the hit is on the side facing the blast, inside the bounding sphere
            EXPECT_NEAR(hits[i].point[0], -0.7 * r, 1e-6);
            EXPECT_NEAR(hits[i].normal[0], -1, 1e-6);
        }
    }
    EXPECT_EQ(rig.runtime.blast({0, 0.5, 0}, 0, impulse).impacts, 0) << "no radius, no blast";
    ImpactPolicy capped = rig.runtime.config().impacts;
    capped.blastMaxCuts = 1;
    rig.runtime.setImpactPolicy(capped);
    hits.clear();
    EXPECT_EQ(rig.runtime.blast({0, 0.5, 0}, radius, impulse).impacts, 3)
        << "static bodies are cut past the cap";
    EXPECT_NE(rig.runtime.bodyOf(sturdy), nullptr);
}

TEST(DestructionRuntime, BlastSkipsBodiesBelowTheMinimumFractureVolume) {
    ToyRig rig;
    const ObjectId small = rig.addBox({0.5, 0.5, 0.5}, {2, 0.5, 0}, true); // 1 m³
    const ObjectId large = rig.addBox({1, 1, 1}, {-3, 1, 0}, true);        // 8 m³
    ImpactPolicy policy = rig.runtime.config().impacts;
    policy.minFractureVolume = 2;
    rig.runtime.setImpactPolicy(policy);
    std::vector<JournalEvent> hits;
    rig.runtime.setJournalSink([&](const JournalEvent& e) { hits.push_back(e); });
    EXPECT_EQ(rig.runtime.blast({0, 0.5, 0}, 8, 1000).impacts, 1) << "only the large box is hit";
    ASSERT_EQ(hits.size(), 1u);
    EXPECT_EQ(hits[0].object, large);
    policy.minFractureVolume = 0;
    rig.runtime.setImpactPolicy(policy);
    EXPECT_EQ(rig.runtime.blast({0, 0.5, 0}, 8, 1000).impacts, 2) << "without the minimum both are";
    ASSERT_EQ(hits.size(), 3u);
    EXPECT_TRUE(hits[1].object == small || hits[2].object == small);
}

TEST(DestructionRuntime, BlastThrowsSmallMovingBodiesAndCutsTheRest) {
    ToyRig rig;
    // 0.001 m³ each: a moving box 2 m from the centre, one 4 m away that comes to rest and is frozen, and a
    // static one; a moving 1 m³ box; blastCutVolume 0.25 m³.
    const ObjectId moving = rig.addBox({0.05, 0.05, 0.05}, {2, 3, 0}, false);
    const ObjectId resting = rig.addBox({0.05, 0.05, 0.05}, {-4, 0.05, 0}, false);
    const ObjectId fixed = rig.addBox({0.05, 0.05, 0.05}, {0, 0.05, 2}, true);
    const ObjectId large = rig.addBox({0.5, 0.5, 0.5}, {0, 3, -3}, false);
    for (int i = 0; i < 240 && rig.motionOf(resting) != BodyMotionState::Frozen; ++i)
        rig.runtime.stepFrame();
    ASSERT_EQ(rig.motionOf(resting), BodyMotionState::Frozen);
    ASSERT_EQ(rig.motionOf(moving), BodyMotionState::Dynamic);
    std::vector<JournalEvent> hits;
    rig.runtime.setJournalSink([&](const JournalEvent& e) { hits.push_back(e); });
    const BodyId movingBody = rig.runtime.bodyOf(moving)->id, restingBody = rig.runtime.bodyOf(resting)->id;
    const Vec3 center = rig.runtime.motion(movingBody).transform.translation - Vec3{2, 0, 0};
    const Vec3 before = rig.runtime.motion(movingBody).linearVelocity;
    const double impulse = 1000, mass = 500 * 0.001;
    const BlastOutcome out = rig.runtime.blast(center, 8, impulse);
    EXPECT_EQ(out.thrown, 2) << "the moving and the frozen small boxes";
    EXPECT_EQ(out.impacts, 2) << "the static small box and the large one";
    ASSERT_EQ(hits.size(), 2u);
    EXPECT_TRUE((hits[0].object == fixed && hits[1].object == large) ||
                (hits[0].object == large && hits[1].object == fixed));
    EXPECT_EQ(rig.motionOf(resting), BodyMotionState::Dynamic) << "woken to be thrown";
    const ImpactPolicy policy = rig.runtime.config().impacts;
    for (const BodyId id : {movingBody, restingBody}) {
        const BodyMotion m = rig.runtime.motion(id);
        const Vec3 dv = m.linearVelocity - (id == movingBody ? before : Vec3{});
        const Vec3 away = m.transform.translation - center;
        const double dist = length(away), r = rig.runtime.body(id)->radius;
        const double share = 1 - 0.6 * std::clamp((dist - r) / 8, 0.0, 1.0);
        EXPECT_NEAR(length(dv), std::min(impulse * share / mass, policy.blastThrowSpeed * share), 1e-9);
        EXPECT_GT(dot(dv, away), 0.999 * length(dv) * dist) << "away from the centre";
    }
    // With blastMaxCuts 1 it cuts the nearest moving body and throws the others.
    ImpactPolicy oneCut = policy;
    oneCut.blastMaxCuts = 1;
    oneCut.blastCutVolume = 0;
    rig.runtime.setImpactPolicy(oneCut);
    hits.clear();
    const BlastOutcome capped = rig.runtime.blast(center, 8, impulse);
    EXPECT_EQ(capped.thrown, 2) << "the farther moving boxes";
    ASSERT_EQ(hits.size(), 2u) << "the nearest moving box and the static one";
    const double toMoving = length(rig.runtime.motion(movingBody).transform.translation - center);
    const double toLarge =
        length(rig.runtime.motion(rig.runtime.bodyOf(large)->id).transform.translation - center);
    const double toResting = length(rig.runtime.motion(restingBody).transform.translation - center);
    const ObjectId nearest = toMoving < std::min(toLarge, toResting) ? moving
                             : toLarge < toResting                   ? large
                                                                     : resting;
    EXPECT_TRUE(hits[0].object == nearest || hits[1].object == nearest);
    EXPECT_TRUE(hits[0].object == fixed || hits[1].object == fixed);
    // With blastCutVolume 0 the same blast cuts every destructible body in range.
    ImpactPolicy cutAll = policy;
    cutAll.blastCutVolume = 0;
    rig.runtime.setImpactPolicy(cutAll);
    hits.clear();
    EXPECT_EQ(rig.runtime.blast(center, 8, impulse).thrown, 0);
    EXPECT_EQ(hits.size(), 4u);
}

TEST(DestructionRuntime, PhysicsTimeBudgetShrinksTheAwakeBudgetOutsideDeterministicMode) {
    for (const bool deterministic : {false, true}) {
        DestructionRuntime::Config c = ToyRig::defaults();
        c.world.deterministic = deterministic;
        c.debris.maxAwakeBodies = 50;
        c.debris.physicsBudgetMs = 0.5;
        test::ToyPhysics::Config slow;
        slow.stepDelayMs = 2; // an engine that takes longer than the budget
        ToyRig rig(c, slow);
        for (int i = 0; i < 40; ++i)
            rig.addBox({0.2, 0.2, 0.2}, {1.0 * i, 50, 0}, false);
        rig.step(20);
        if (deterministic) {
            EXPECT_EQ(rig.runtime.awakeBudget(), 50) << "time must not change a deterministic run";
            EXPECT_EQ(rig.runtime.awakeDebris(), 40);
        } else {
            EXPECT_LT(rig.runtime.awakeBudget(), 40);
            EXPECT_EQ(rig.runtime.awakeDebris(), 40)
                << "over budget, but the game's objects are never retired";
        }
    }
}

TEST(DestructionRuntime, SameStateOnOneAndTwoWorkers) {
    auto run = [](int workers) {
        DestructionRuntime::Config c = ToyRig::defaults();
        c.world.workers = workers;
        c.debris.maxAwakeBodies = 6;
        ToyRig rig(c);
        const ObjectId column = rig.addBox({0.5, 4, 0.5}, {0, 4, 0}, true, shatter(5, 2.4));
        rig.addBox({1.5, 0.25, 1.5}, {0, 8.25, 0}, true, shatter(5, 1.5));
        EXPECT_TRUE(rig.runtime.submitLocalImpact(column, Impact{{0.5, -1.5, 0}, {1, 0, 0}, 100}));
        for (int f = 0; f < 120; ++f) {
            if (f % 20 == 10)
                rig.runtime.fireProjectile({-15, 1.0 + 0.05 * f, 0.1}, {150, 0, 0}, 5, 0.1);
            rig.runtime.stepFrame();
        }
        EXPECT_GT(rig.runtime.counters().fractures, 1);
        return rig.runtime.stateHash();
    };
    EXPECT_EQ(run(1), run(2));
}

} // namespace rubble
