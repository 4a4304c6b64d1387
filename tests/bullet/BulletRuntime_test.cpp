// The engine-neutral runtime on the Bullet binding: piece bodies at their true centre of mass with mass =
// density · volume, the parent's velocity field, conservation at adoption, impact filtering, determinism,
// volume bookkeeping, structural collapse and the debris governor's budgets.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <future>
#include <map>
#include <optional>
#include <thread>

#include "TestSupport.hpp"

#include "rubble/bullet/BulletBinding.hpp"
#include "rubble/bullet/Convert.hpp"
#include "rubble/core/Random.hpp"
#include "rubble/geometry/MassProperties.hpp"
#include "rubble/io/SceneConfig.hpp"
#include "rubble/runtime/DestructionRuntime.hpp"
#include "rubble/runtime/SceneLoader.hpp"

using namespace rubble;
using namespace rubble::bullet;

namespace {

struct Rig {
    explicit Rig(bool gravity = true, int workers = 1, bool deterministic = true,
                 DestructionRuntime::Config rc = {}, JobSystem* jobs = nullptr) {
        rc.world.jobs = jobs;
        rc.world.workers = workers;
        rc.world.deterministic = deterministic;
        rc.world.seed = 7;
        PhysicsWorld::Config pc;
        if (!gravity)
            pc.gravity = {0, 0, 0};
        physics = std::make_unique<PhysicsWorld>(pc);
        binding = std::make_unique<BulletBinding>(*physics);
        runtime = std::make_unique<DestructionRuntime>(*binding, rc);
    }
    ~Rig() {
        runtime.reset();
        binding.reset();
        physics.reset();
    }
    const DestructionWorld& world() const { return runtime->world(); }
    ObjectId addBox(const Vec3& half, const Frame& placement, double density, bool isStatic = false,
                    const FractureParams& fracture = {}) {
        ObjectDesc d;
        d.mesh = makeBox(-half, half);
        d.density = density;
        d.impulseThreshold = 1;
        d.fracture = fracture;
        Result<ObjectId> id = runtime->addObject(std::move(d), placement, isStatic);
        EXPECT_TRUE(id) << (id ? "" : id.error().message);
        return id ? *id : 0;
    }
    const BodyRecord* bodyOf(ObjectId id) const { return runtime->bodyOf(id); }
    btRigidBody* rigidOf(ObjectId id) const {
        const BodyRecord* b = runtime->bodyOf(id);
        return b ? binding->rigid(b->id) : nullptr;
    }
    // steps until at least one fracture was adopted (or the frame limit)
    bool runUntilFracture(int maxFrames = 240) {
        const long long before = runtime->counters().fractures;
        for (int i = 0; i < maxFrames; ++i) {
            runtime->stepFrame();
            if (runtime->counters().fractures > before)
                return true;
        }
        return false;
    }
    std::unique_ptr<PhysicsWorld> physics;
    std::unique_ptr<BulletBinding> binding;
    std::unique_ptr<DestructionRuntime> runtime;
};

bool isStatic(const BodyRecord& b) {
    return b.motion == BodyMotionState::Static;
}

Frame rotatedFrame(const Vec3& t) {
    Rng rng(3);
    return Frame{rng.rotation(), t};
}

// Runs each job on a thread of its own, but only once the test releases it (it decides when a result can be
// ready). Declare it before the Rig: its destructor joins the threads.
class GatedJobs final : public JobSystem {
public:
    ~GatedJobs() override {
        for (auto& t : threads_)
            t.join();
    }
    void submit(std::function<void()> job) override { held_.push_back(std::move(job)); }
    int workerCount() const override { return 1; }
    void release() {
        for (auto& j : held_)
            threads_.emplace_back(std::move(j));
        held_.clear();
    }

private:
    std::vector<std::function<void()>> held_; // only touched by the test's thread
    std::vector<std::thread> threads_;
};

struct ParentSnapshot {
    double mass = 0;
    Vec3 com, v, w;
};

} // namespace

TEST(BulletRuntime, PieceBodiesHaveTrueMassAndCentreOfMass) {
    Rig rig(false);
    const Frame placement = rotatedFrame({3, 4, -2});
    const double density = 2.5;
    const ObjectId id = rig.addBox({1, 0.5, 0.75}, placement, density);
    int checked = 0;
    rig.runtime->setOnAdopted([&](const FractureOutcome& o) {
        for (const AdoptedPiece& piece : o.pieces) {
            const BodyRecord* b = rig.bodyOf(piece.id);
            ASSERT_NE(b, nullptr);
            const ObjectState* st = rig.world().object(piece.id);
            ASSERT_NE(st, nullptr);
            EXPECT_EQ(st, piece.state.get()) << "the outcome hands the piece's state over";
            EXPECT_NEAR(b->mass, density * st->mass.volume, 1e-9 * b->mass);
            EXPECT_NEAR(1.0 / rig.rigidOf(piece.id)->getInvMass(), density * st->mass.volume, 1e-4 * b->mass);
            // the piece mesh placed in the world through the parent's frame: its true centroid
            Mesh world = st->mesh;
            for (Vec3& p : world.positions)
                p = placement.apply(piece.frame.apply(p));
            const Vec3 truth = computeMassProperties(world).centerOfMass;
            const Vec3 com = rig.runtime->motion(b->id).transform.translation;
            EXPECT_NEAR(com.x, truth.x, 1e-4);
            EXPECT_NEAR(com.y, truth.y, 1e-4);
            EXPECT_NEAR(com.z, truth.z, 1e-4);
            ++checked;
        }
    });
    ASSERT_TRUE(rig.runtime->submitLocalImpact(id, Impact{{1, 0.1, 0.2}, {1, 0, 0}, 100}));
    ASSERT_TRUE(rig.runUntilFracture());
    EXPECT_GE(checked, 2);
}

TEST(BulletRuntime, PiecesFollowTheParentsVelocityFieldAndConserveMomentum) {
    // declared before the rig: the runtime's destructor may still call back
    std::optional<ParentSnapshot> snap;
    DestructionRuntime::Config rc;
    rc.world.minPieceVolume = 0; // keep every piece a body
    Rig rig(false, 1, true, rc);
    const ObjectId id = rig.addBox({1, 1, 1}, Frame{Mat3::identity(), {0, 10, 0}}, 3.0);
    btRigidBody* parent = rig.rigidOf(id);
    ASSERT_NE(parent, nullptr);
    parent->setLinearVelocity({1, -2, 0.5f});
    parent->setAngularVelocity({0.3f, 1.2f, -0.7f});
    rig.runtime->setOnRemoved([&snap, &rig, id](const BodyRecord& b) {
        if (b.hasObject && b.object == id) {
            const BodyMotion m = rig.runtime->motion(b.id);
            snap = ParentSnapshot{b.mass, m.transform.translation, m.linearVelocity, m.angularVelocity};
        }
    });
    bool checked = false;
    rig.runtime->setOnAdopted([&](const FractureOutcome& o) {
        ASSERT_TRUE(snap);
        double mass = 0;
        Vec3 momentum;
        for (const AdoptedPiece& piece : o.pieces) {
            const BodyRecord* b = rig.bodyOf(piece.id);
            ASSERT_NE(b, nullptr);
            const BodyMotion m = rig.runtime->motion(b->id);
            const Vec3 expected = snap->v + cross(snap->w, m.transform.translation - snap->com);
            EXPECT_NEAR(m.linearVelocity.x, expected.x, 1e-4);
            EXPECT_NEAR(m.linearVelocity.y, expected.y, 1e-4);
            EXPECT_NEAR(m.linearVelocity.z, expected.z, 1e-4);
            EXPECT_NEAR(m.angularVelocity.x, snap->w.x, 1e-5);
            EXPECT_NEAR(m.angularVelocity.y, snap->w.y, 1e-5);
            EXPECT_NEAR(m.angularVelocity.z, snap->w.z, 1e-5);
            mass += b->mass;
            momentum += m.linearVelocity * b->mass;
        }
        // conservation up to dropped slivers (none for a clean box cut)
        EXPECT_NEAR(mass, snap->mass, 1e-6 * snap->mass);
        const Vec3 p0 = snap->v * snap->mass;
        EXPECT_NEAR(momentum.x, p0.x, 1e-4 * snap->mass);
        EXPECT_NEAR(momentum.y, p0.y, 1e-4 * snap->mass);
        EXPECT_NEAR(momentum.z, p0.z, 1e-4 * snap->mass);
        checked = true;
    });
    ASSERT_TRUE(rig.runtime->submitLocalImpact(id, Impact{{1, 0, 0}, {1, 0, 0}, 100}));
    ASSERT_TRUE(rig.runUntilFracture());
    EXPECT_TRUE(checked);
    rig.runtime->setOnRemoved({});
}

TEST(BulletRuntime, RestingBoxNeverFracturesButAProjectileHitDoes) {
    DestructionRuntime::Config rc;
    rc.impacts.collisionImpulseThreshold = 1; // only the approach-speed filter protects resting contacts
    Rig rig(true, 1, true, rc);
    rig.runtime->addGround({0, -0.5, 0}, {50, 0.5, 50});
    const ObjectId id = rig.addBox({0.5, 0.5, 0.5}, Frame{Mat3::identity(), {0, 0.5, 0}}, 1000);
    for (int i = 0; i < 300; ++i)
        rig.runtime->stepFrame();
    EXPECT_EQ(rig.runtime->counters().impacts, 0);
    EXPECT_EQ(rig.runtime->counters().fractures, 0);
    ASSERT_NE(rig.bodyOf(id), nullptr);
    rig.runtime->fireProjectile({-10, 0.5, 0.1}, {100, 0, 0}, 1, 0.1);
    const bool fractured = rig.runUntilFracture(120);
    EXPECT_EQ(rig.runtime->counters().projectileHits, 1);
    EXPECT_EQ(rig.runtime->counters().impacts, 1);
    EXPECT_TRUE(fractured);
    EXPECT_EQ(rig.bodyOf(id), nullptr);
}

TEST(BulletRuntime, DebugDrawHasShapesAabbsAndImpactCrosses) {
    Rig rig(true);
    rig.runtime->addGround({0, -0.5, 0}, {50, 0.5, 50});
    rig.addBox({0.5, 0.5, 0.5}, Frame{Mat3::identity(), {0, 0.5, 0}}, 100);
    DebugDrawOptions o;
    o.aabbs = false;
    const std::size_t shapes = rig.binding->debugDraw(*rig.runtime, o).lines.size();
    EXPECT_GE(shapes, 24u); // two boxes' edges
    o.aabbs = true;
    EXPECT_EQ(rig.binding->debugDraw(*rig.runtime, o).lines.size(), shapes + 24u);
    rig.runtime->fireProjectile({-10, 0.5, 0}, {100, 0, 0}, 1, 0.1);
    for (int i = 0; i < 30 && rig.runtime->recentImpacts().empty(); ++i)
        rig.runtime->stepFrame();
    ASSERT_EQ(rig.runtime->recentImpacts().size(), 1u);
    EXPECT_NEAR(rig.runtime->recentImpacts().front().point.x, -0.5, 0.1);
    o.shapes = o.aabbs = false;
    EXPECT_EQ(rig.binding->debugDraw(*rig.runtime, o).lines.size(), 4u); // a cross and its normal
}

namespace {

// How runShootingScene adopts between frames.
struct IdleAdoption {
    bool deterministic = true; ///< the world's mode
    bool call = false;         ///< after each frame: wait for the jobs, then waitForResult + adoptReady
    long long waitedFor = 0;   ///< out: waitForResult returned true
    long long adoptedIdle = 0; ///< out: fractures adoptReady adopted
};

// A small seeded shooting scene; returns the final state hash and volume error.
std::pair<std::uint64_t, double> runShootingScene(int workers, int maxAwake = 400, int* maxSeen = nullptr,
                                                  IdleAdoption* idle = nullptr) {
    DestructionRuntime::Config rc;
    rc.debris.maxAwakeBodies = maxAwake;
    rc.debris.awakeOvershoot = 0; // the budget is hard: maxSeen never exceeds it
    Rig rig(true, workers, idle ? idle->deterministic : true, rc);
    rig.runtime->addGround({0, -0.5, 0}, {50, 0.5, 50});
    rig.addBox({1, 1, 1}, Frame{Mat3::identity(), {0, 1, 0}}, 500, true);
    rig.addBox({0.5, 1.5, 0.5}, Frame{Mat3::identity(), {4, 1.5, 0}}, 300);
    rig.addBox({1.5, 0.5, 0.5}, Frame{Mat3::identity(), {-4, 0.5, 1}}, 300);
    const double start = rig.runtime->volumes().total();
    Rng rng(11);
    int seen = 0;
    for (int f = 0; f < 180; ++f) {
        if (f % 6 == 0) {
            const Vec3 target{rng.uniform(-4.5, 4.5), rng.uniform(0.2, 1.5), rng.uniform(-0.3, 0.5)};
            rig.runtime->fireProjectile(target + Vec3{0, 3, 15}, Vec3{0, -3, -15} * 8, 2, 0.15);
        }
        rig.runtime->stepFrame();
        seen = std::max(seen, rig.runtime->awakeDebris() - rig.runtime->lightDebris());
        if (idle && idle->call) {
            rig.world().waitIdle(); // every job done: whatever can be adopted now is ready
            while (rig.world().waitForResult(std::chrono::steady_clock::now() + std::chrono::seconds(5))) {
                ++idle->waitedFor;
                idle->adoptedIdle += rig.runtime->adoptReady().fractures;
            }
            idle->adoptedIdle += rig.runtime->adoptReady().fractures; // must be a no-op when nothing is ready
        }
    }
    if (maxSeen)
        *maxSeen = seen;
    EXPECT_GT(rig.runtime->counters().fractures, 0);
    return {rig.runtime->stateHash(), std::abs(rig.runtime->volumes().total() - start) / start};
}

} // namespace

TEST(BulletRuntime, DeterministicAcrossWorkerCounts) {
    const auto one = runShootingScene(1);
    const auto two = runShootingScene(2);
    EXPECT_EQ(one.first, two.first);
}

TEST(BulletRuntime, DeterministicModeIgnoresIdleAdoption) {
    IdleAdoption idle;
    idle.call = true;
    const auto with = runShootingScene(2, 400, nullptr, &idle);
    EXPECT_EQ(idle.waitedFor, 0);
    EXPECT_EQ(idle.adoptedIdle, 0);
    EXPECT_EQ(with.first, runShootingScene(2).first);
}

TEST(BulletRuntime, IdleAdoptionKeepsVolumeAndTheAwakeBudget) {
    // Non-deterministic mode with every result adopted between frames, as soon as it is ready.
    IdleAdoption idle;
    idle.deterministic = false;
    idle.call = true;
    int seen = 0;
    const auto r = runShootingScene(2, 5, &seen, &idle);
    EXPECT_GT(idle.adoptedIdle, 0);
    EXPECT_LE(seen, 5);
    EXPECT_LT(r.second, 1e-6);
}

// Issue #5: with idle adoption, a fracture whose job finishes after stepFrame's collect is adopted before the
// next stepFrame (impact → adopted within the frame of the impact), not at the next one.
TEST(BulletRuntime, IdleAdoptionAdoptsBeforeTheNextStepFrame) {
    GatedJobs jobs;
    Rig rig(false, 1, false, {}, &jobs);
    const ObjectId id = rig.addBox({0.5, 0.5, 0.5}, Frame{Mat3::identity(), {0, 0, 0}}, 100);
    rig.runtime->fireProjectile({-10, 0, 0.1}, {100, 0, 0}, 1, 0.1);
    for (int i = 0; i < 60 && rig.runtime->counters().impacts == 0; ++i)
        rig.runtime->stepFrame();
    ASSERT_EQ(rig.runtime->counters().impacts, 1);
    ASSERT_EQ(rig.runtime->counters().fractures, 0); // the job was held through stepFrame's collect
    const std::uint64_t frame = rig.runtime->counters().frames;
    EXPECT_EQ(rig.runtime->adoptReady().fractures, 0) << "nothing ready yet";
    jobs.release(); // the job finishes in the idle time after the frame
    ASSERT_TRUE(rig.world().waitForResult(std::chrono::steady_clock::now() + std::chrono::minutes(1)));
    const FrameStats s = rig.runtime->adoptReady();
    EXPECT_EQ(s.fractures, 1);
    EXPECT_GE(s.piecesCreated + s.piecesRetired, 2);
    EXPECT_EQ(rig.runtime->counters().fractures, 1);
    EXPECT_EQ(rig.runtime->counters().frames, frame) << "no stepFrame in between";
    EXPECT_EQ(rig.bodyOf(id), nullptr);
    ASSERT_EQ(rig.world().timings().size(), 1u);
    // stepFrame submits impacts just before DestructionWorld::beginFrame: the record carries the frame before
    EXPECT_EQ(rig.world().timings()[0].frame + 1, rig.world().frame());
    EXPECT_EQ(rig.runtime->adoptReady().fractures, 0) << "nothing left to adopt";
}

// Issue #5: "impact → adopted" ends when the pieces' bodies and collision shapes exist, so the engine's part
// of the adoption is in the impact's timing record (the runtime commits the split once the bodies exist). The
// parent's removal callback runs inside the adoption; made slow, it must show in the record.
TEST(BulletRuntime, TimingRecordIncludesTheEnginesAdoption) {
    using namespace std::chrono_literals;
    Rig rig(false, 1, true);
    const ObjectId id = rig.addBox({0.5, 0.5, 0.5}, Frame{Mat3::identity(), {0, 0, 0}}, 100);
    rig.runtime->setOnRemoved([&](const BodyRecord& b) {
        if (b.hasObject && b.object == id)
            std::this_thread::sleep_for(20ms);
    });
    rig.runtime->fireProjectile({-10, 0, 0.1}, {100, 0, 0}, 1, 0.1);
    ASSERT_TRUE(rig.runUntilFracture());
    ASSERT_EQ(rig.world().timings().size(), 1u);
    const TimingRecord& r = rig.world().timings()[0];
    EXPECT_GE(r.adoptionMs, 20);
    EXPECT_GE(r.totalMs, r.queueMs + r.prepareMs + r.cellMs + r.booleanMs + r.islandsMs + r.decompositionMs +
                             r.finishMs + r.handoffMs + r.adoptionMs);
    rig.runtime->setOnRemoved({});
}

TEST(BulletRuntime, VolumeIsConservedThroughFracturesAndRetirement) {
    const auto r = runShootingScene(1);
    EXPECT_LT(r.second, 1e-6);
}

TEST(BulletRuntime, AwakeBudgetIsRespected) {
    int seen = 0;
    const auto r = runShootingScene(1, 3, &seen);
    EXPECT_LE(seen, 3);
    EXPECT_LT(r.second, 1e-6);
}

namespace {

// cube_test.cfg (the thesis's cube scene, our assets) loaded as it is, shot at by seeded projectiles in
// deterministic mode; returns the state hash, the relative volume error and the fractures adopted.
struct SceneRun {
    std::uint64_t hash = 0;
    double volumeError = 1;
    long long fractures = 0;
};

SceneRun runSceneFile(const std::filesystem::path& file, int workers) {
    SceneRun out;
    Result<SceneConfig> scene = parseSceneConfig(file);
    EXPECT_TRUE(scene) << (scene ? "" : scene.error().message);
    if (!scene)
        return out;
    Rig rig(true, workers, true);
    SceneLoadOptions lo;
    lo.loadVehicle = false;
    const LoadedScene loaded = loadScene(*scene, *rig.runtime, lo);
    EXPECT_FALSE(loaded.objects.empty());
    const double start = rig.runtime->volumes().total();
    Rng rng(3);
    for (int f = 0; f < 150; ++f) {
        if (f % 10 == 0) {
            // at the largest destructible body, from above and in front
            const BodyRecord* target = nullptr;
            for (BodyId id : rig.runtime->bodies()) {
                const BodyRecord* b = rig.runtime->body(id);
                if ((b->role == BodyRole::Object || b->role == BodyRole::Piece) &&
                    (!target || b->volume > target->volume))
                    target = b;
            }
            if (target) {
                const Vec3 c = rig.runtime->motion(target->id).transform.translation;
                const Vec3 aim = c + Vec3{rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)};
                rig.runtime->fireProjectile(aim + Vec3{0, 10, 30}, Vec3{0, -10, -30} * 4, 2, 0.25);
            }
        }
        rig.runtime->stepFrame();
    }
    out.hash = rig.runtime->stateHash();
    out.volumeError = std::abs(rig.runtime->volumes().total() - start) / start;
    out.fractures = rig.runtime->counters().fractures;
    return out;
}

} // namespace

TEST(BulletRuntime, SceneFileIsDeterministicOnOneAndTwoWorkersAndConservesVolume) {
    const auto file = test::sourceDir() / "assets" / "scenes" / "cube_test_108.cfg";
    ASSERT_TRUE(std::filesystem::exists(file));
    const SceneRun one = runSceneFile(file, 1);
    const SceneRun two = runSceneFile(file, 2);
    const SceneRun again = runSceneFile(file, 2);
    EXPECT_GE(one.fractures, 3);
    EXPECT_EQ(one.fractures, two.fractures);
    EXPECT_EQ(one.hash, two.hash);
    EXPECT_EQ(two.hash, again.hash);
    EXPECT_LT(one.volumeError, 1e-6);
    EXPECT_LT(two.volumeError, 1e-6);
}

TEST(BulletRuntime, ShutdownWithJobsInFlightNeitherHangsNorLeaks) {
    // Non-deterministic mode: impacts are submitted and the whole rig is torn down at once, with fracture
    // jobs running and queued (ASan/LSan builds check the leaks, the timeout the hang).
    auto done = std::async(std::launch::async, [] {
        long long submitted = 0;
        {
            Rig rig(false, 1, false);
            std::vector<ObjectId> ids;
            for (int i = 0; i < 6; ++i)
                ids.push_back(rig.addBox({1, 1, 1}, Frame{Mat3::identity(), {4.0 * i, 0, 0}}, 100));
            for (ObjectId id : ids)
                submitted +=
                    rig.runtime->submitLocalImpact(id, Impact{{1, 0.1, 0.2}, {1, 0, 0}, 100}) ? 1 : 0;
            rig.runtime->stepFrame();
        }
        return submitted;
    });
    ASSERT_EQ(done.wait_for(std::chrono::seconds(60)), std::future_status::ready) << "shutdown hung";
    EXPECT_EQ(done.get(), 6);
}

namespace {

// One cell, a randomly rotated cube of the given edge centred at the impact (no other Voronoi sites): it
// contains the ball of radius size/2 around the impact, so it cuts through anything narrower.
FractureParams cubeCell(double size) {
    FractureParams f;
    f.seedPoints = 0;
    f.sizeLaw.base = f.sizeLaw.minSize = f.sizeLaw.maxSize = size;
    f.sizeLaw.scale = 0;
    return f;
}

// The pieces of the first adopted outcome as the callback saw them: id, cell, static, centre height,
// volume.
struct PieceView {
    ObjectId id = 0;
    int cell = -1;
    bool isStatic = false;
    double y = 0;
    double volume = 0;
};

struct CollapseRig : Rig {
    // with a ground whose top is y = 0
    explicit CollapseRig(bool collapse = true, double debrisKick = 0.5)
        : Rig(true, 1, true, config(collapse, debrisKick)) {
        runtime->addGround({0, -0.5, 0}, {50, 0.5, 50});
    }
    // a static box of density 500 centred at `centre`, let settle for two frames
    ObjectId addStatic(const Vec3& half, const Vec3& centre, const FractureParams& fracture = {}) {
        const ObjectId id = addBox(half, Frame{Mat3::identity(), centre}, 500, true, fracture);
        step(2);
        return id;
    }
    static DestructionRuntime::Config config(bool collapse, double debrisKick) {
        DestructionRuntime::Config rc;
        rc.support.collapseUnsupported = collapse;
        rc.adoption.debrisKick = debrisKick;
        rc.world.minPieceVolume = 0;      // every piece keeps its body
        rc.debris.freezeSleeping = false; // these tests watch pieces fall and lie; none should freeze early
        rc.debris.freezeAfterFrames = 1000000;
        return rc;
    }
    // impact on `id`, steps until adopted; returns the pieces of that fracture
    std::vector<PieceView> breakAt(ObjectId id, const Impact& impact) {
        std::vector<PieceView> out;
        runtime->setOnAdopted([&](const FractureOutcome& o) {
            if (!out.empty())
                return;
            for (const AdoptedPiece& p : o.pieces) {
                const BodyRecord* b = bodyOf(p.id);
                EXPECT_NE(b, nullptr);
                if (b)
                    out.push_back({p.id, p.cell, isStatic(*b), runtime->motion(b->id).transform.translation.y,
                                   b->volume});
            }
        });
        EXPECT_TRUE(runtime->submitLocalImpact(id, impact));
        EXPECT_TRUE(runUntilFracture());
        runtime->setOnAdopted({});
        return out;
    }
    // throws the debris out at a known velocity (the runtime's own kick, AdoptionPolicy::debrisKick, depends
    // on the hit's impulse and the debris mass): a cut-out chunk left in its gap would hold up what is above
    void ejectDebris(const std::vector<PieceView>& pieces, const Vec3& velocity) {
        for (const PieceView& p : pieces)
            if (const BodyRecord* b = bodyOf(p.id); b && p.cell >= 0)
                binding->setVelocity(b->id, velocity, {});
    }
    double heightOf(ObjectId id) {
        const BodyRecord* b = bodyOf(id);
        return b ? runtime->motion(b->id).transform.translation.y : -1e9;
    }
    void step(int frames) {
        for (int i = 0; i < frames; ++i)
            runtime->stepFrame();
    }
};

// A 1 × 8 × 1 column standing on the ground (y 0..8) is cut by cubeCell(2.4) at y = 2.5: the cell spans the
// section there and reaches at most 2.08 m from the impact, so the remainder is one foot (y < 0.42 intact,
// on the ground) and one top (y > 4.58), the top being the larger.
const Impact kColumnCut{{0.5, -1.5, 0}, {1, 0, 0}, 100};
constexpr double kCutY = 2.5;

} // namespace

TEST(BulletRuntimeCollapse, ColumnCutThroughItsMiddleDropsItsTopAndKeepsItsFoot) {
    CollapseRig rig;
    const ObjectId column = rig.addStatic({0.5, 4, 0.5}, {0, 4, 0}, cubeCell(2.4));
    const double before = rig.runtime->volumes().total();
    const auto pieces = rig.breakAt(column, kColumnCut);
    int upper = 0, lower = 0, debris = 0;
    for (const PieceView& p : pieces) {
        if (p.cell >= 0) {
            ++debris;
            EXPECT_FALSE(p.isStatic) << "debris is always dynamic";
        } else if (p.y > kCutY) {
            ++upper;
            EXPECT_FALSE(p.isStatic) << "the part above the cut has nothing under it";
        } else {
            ++lower;
            EXPECT_TRUE(p.isStatic) << "the foot stands on the ground";
        }
    }
    EXPECT_GE(debris, 1);
    EXPECT_EQ(upper, 1);
    EXPECT_EQ(lower, 1);
    EXPECT_GE(rig.runtime->counters().piecesCollapsed, 1);
    rig.ejectDebris(pieces, {-10, 0, 0});
    rig.step(60);
    for (const PieceView& p : pieces) {
        if (p.cell < 0 && p.y > kCutY) { // the top fell
            EXPECT_LT(rig.heightOf(p.id), p.y - 0.5);
        }
        if (p.cell < 0 && p.y < kCutY) { // the foot did not move
            const BodyRecord* b = rig.bodyOf(p.id);
            ASSERT_NE(b, nullptr);
            EXPECT_TRUE(isStatic(*b));
            EXPECT_EQ(rig.heightOf(p.id), p.y);
        }
    }
    EXPECT_LT(std::abs(rig.runtime->volumes().total() - before) / before, 1e-9);
}

TEST(BulletRuntimeCollapse, WallHitAtItsTopCornerKeepsItsRemainderAndDropsTheDebris) {
    CollapseRig rig;
    const ObjectId wall = rig.addStatic({3, 2, 0.25}, {0, 2, 0}, cubeCell(1.5));
    const auto pieces = rig.breakAt(wall, Impact{{3, 2, 0}, {0.7071, 0.7071, 0}, 100});
    double remainder = 0;
    int debris = 0;
    for (const PieceView& p : pieces) {
        if (p.cell >= 0) {
            ++debris;
            EXPECT_FALSE(p.isStatic);
        } else if (p.volume > remainder) {
            remainder = p.volume;
            EXPECT_TRUE(p.isStatic) << "the wall still stands on the ground";
        }
    }
    EXPECT_GE(debris, 1);
    EXPECT_GT(remainder, 0.8 * 6 * 4 * 0.5);
    rig.ejectDebris(pieces, {5, 0, 0});
    rig.step(60);
    for (const PieceView& p : pieces)
        if (p.cell >= 0) {
            EXPECT_LT(rig.heightOf(p.id), p.y - 0.5) << "debris falls";
        }
}

TEST(BulletRuntimeCollapse, FloatingPlatformKeepsItsLargestRemainderPieceStatic) {
    CollapseRig rig;
    // a 6 × 1 × 1 slab 10 m up, touching nothing, cut through off its middle
    const ObjectId slab = rig.addStatic({3, 0.5, 0.5}, {0, 10, 0}, cubeCell(2.4));
    ASSERT_TRUE(rig.bodyOf(slab)->anchor) << "a static object touching nothing is an anchor";
    const auto pieces = rig.breakAt(slab, Impact{{1, 0.5, 0}, {0, 1, 0}, 100});
    double largest = 0;
    for (const PieceView& p : pieces)
        if (p.cell < 0)
            largest = std::max(largest, p.volume);
    int remainders = 0, statics = 0;
    for (const PieceView& p : pieces) {
        remainders += p.cell < 0 ? 1 : 0;
        statics += p.isStatic ? 1 : 0;
        EXPECT_EQ(p.isStatic, p.cell < 0 && p.volume == largest);
        if (p.isStatic) {
            EXPECT_TRUE(rig.bodyOf(p.id)->anchor) << "the kept piece is the new anchor";
        }
    }
    EXPECT_GE(remainders, 2);
    EXPECT_EQ(statics, 1);
    EXPECT_EQ(rig.runtime->counters().piecesCollapsed, 0);
}

TEST(BulletRuntimeCollapse, CollapsePropagatesToWhatRestedOnTheBrokenPart) {
    CollapseRig rig;
    const ObjectId lower = rig.addStatic({0.5, 4, 0.5}, {0, 4, 0}, cubeCell(2.4));
    const ObjectId upper = rig.addStatic({0.75, 0.5, 0.75}, {0, 8.5, 0});
    EXPECT_FALSE(rig.bodyOf(upper)->anchor) << "it rests on a column that stands on the ground";
    const double y0 = rig.heightOf(upper);
    rig.ejectDebris(rig.breakAt(lower, kColumnCut), {-10, 0, 0});
    const BodyRecord* b = rig.bodyOf(upper);
    ASSERT_NE(b, nullptr);
    EXPECT_FALSE(isStatic(*b)) << "the block on top lost its support with the column's top";
    rig.step(60);
    EXPECT_LT(rig.heightOf(upper), y0 - 0.5);
}

TEST(BulletRuntimeCollapse, SwitchedOffTheLargestPieceStaysStaticAsBefore) {
    CollapseRig rig(false);
    const ObjectId column = rig.addStatic({0.5, 4, 0.5}, {0, 4, 0}, cubeCell(2.4));
    const auto pieces = rig.breakAt(column, kColumnCut);
    double largest = 0;
    for (const PieceView& p : pieces)
        largest = std::max(largest, p.volume);
    int statics = 0;
    for (const PieceView& p : pieces) {
        statics += p.isStatic ? 1 : 0;
        EXPECT_EQ(p.isStatic, p.volume == largest);
        if (p.isStatic) {
            EXPECT_GT(p.y, kCutY) << "the old rule: the larger top floats";
        }
    }
    EXPECT_EQ(statics, 1);
    EXPECT_EQ(rig.runtime->counters().piecesCollapsed, 0);
}

// Debris keeps its triangles under DebrisBudget::maxTriangles: the smallest pieces become particles (their
// volume counted as retired), so the meshes the runtime keeps alive stay bounded.
TEST(BulletRuntime, DebrisTrianglesStayWithinTheBudget) {
    DestructionRuntime::Config rc;
    rc.debris.maxTriangles = 150;
    Rig rig(true, 1, true, rc);
    rig.runtime->addGround({0, -0.5, 0}, {50, 0.5, 50});
    rig.addBox({0.5, 1.5, 0.5}, Frame{Mat3::identity(), {4, 1.5, 0}}, 300);
    rig.addBox({1.5, 0.5, 0.5}, Frame{Mat3::identity(), {-4, 0.5, 1}}, 300);
    const double start = rig.runtime->volumes().total();
    Rng rng(5);
    std::size_t most = 0;
    for (int f = 0; f < 180; ++f) {
        if (f % 6 == 0) {
            const Vec3 target{rng.uniform(-4.5, 4.5), rng.uniform(0.2, 1.5), rng.uniform(-0.3, 0.5)};
            rig.runtime->fireProjectile(target + Vec3{0, 3, 15}, Vec3{0, -3, -15} * 8, 2, 0.15);
        }
        rig.runtime->stepFrame();
        ASSERT_LE(rig.runtime->debrisTriangles(), rc.debris.maxTriangles) << "frame " << f;
        most = std::max(most, rig.runtime->debrisTriangles());
    }
    EXPECT_GT(rig.runtime->counters().fractures, 2);
    EXPECT_GT(rig.runtime->counters().piecesRetired, 0);
    EXPECT_GT(most, 0u);
    EXPECT_NEAR(rig.runtime->volumes().total(), start, 1e-6 * start);
}

// The hit throws a static wall's debris outward (along the surface normal, away from the impact), at one
// speed for all debris of the hit, bounded; with the kick off the debris starts at rest like the wall.
TEST(BulletRuntimeCollapse, DebrisOfAStaticWallIsThrownOutward) {
    for (const double share : {0.5, 0.0}) {
        CollapseRig rig(true, share);
        const ObjectId wall = rig.addStatic({3, 2, 0.25}, {0, 2, 0}, cubeCell(1.0));
        std::vector<Vec3> velocities;
        rig.runtime->setOnAdopted([&](const FractureOutcome& o) {
            for (const AdoptedPiece& p : o.pieces)
                if (p.cell >= 0)
                    if (const BodyRecord* b = rig.bodyOf(p.id); b && !isStatic(*b))
                        velocities.push_back(rig.runtime->motion(b->id).linearVelocity);
        });
        ASSERT_TRUE(rig.runtime->submitLocalImpact(wall, Impact{{0, 0, 0.25}, {0, 0, 1}, 200}));
        ASSERT_TRUE(rig.runUntilFracture());
        ASSERT_FALSE(velocities.empty());
        for (const Vec3& v : velocities) {
            if (share > 0) {
                EXPECT_GT(v.z, 0.1) << "outward, along the wall's normal";
                EXPECT_LE(length(v), rig.runtime->config().adoption.maxDebrisKickSpeed + 1e-5);
                EXPECT_NEAR(length(v), length(velocities.front()), 1e-5) << "one speed per hit";
            } else {
                EXPECT_LT(length(v), 1e-9);
            }
        }
    }
}

// A light body (setCollidesWithMoving false) falls through a moving body onto the static ground; setMass
// makes it collide with every body again.
TEST(BulletBinding, ALightBodyPassesThroughMovingBodiesAndLandsOnStaticOnes) {
    auto box = [](double mass, const Vec3& at, double half) {
        BodyDesc d;
        d.shape.kind = BodyShape::Kind::Box;
        d.shape.halfExtents = {half, half, half};
        d.mass = mass;
        d.inertia = Vec3{1, 1, 1} * (mass * half * half * 2 / 3);
        d.transform.translation = at;
        return d;
    };
    for (const bool light : {false, true}) {
        PhysicsWorld physics;
        BulletBinding binding(physics);
        ASSERT_TRUE(binding.filtersMovingPairs());
        BodyDesc ground = box(0, {0, -5, 0}, 5);
        binding.createBody(1, ground);
        binding.createBody(2, box(1, {0, 0.5, 0}, 0.5)); // dynamic, resting on the ground
        binding.createBody(3, box(1, {0, 3, 0}, 0.25));  // falls onto it
        binding.setCollidesWithMoving(3, !light);
        std::vector<ContactReport> contacts;
        for (int i = 0; i < 120; ++i)
            binding.step(1.0 / 60, contacts);
        const double y = binding.motion(3).transform.translation.y;
        EXPECT_NEAR(y, light ? 0.25 : 1.25, 0.05) << (light ? "through the moving box" : "on top of it");
        EXPECT_NEAR(binding.motion(2).transform.translation.y, 0.5, 0.05);
        binding.setMass(3, 1, Vec3{1, 1, 1} * (0.25 * 0.25 * 2 / 3));
        EXPECT_EQ(binding.rigid(3)->getBroadphaseHandle()->m_collisionFilterGroup,
                  static_cast<int>(btBroadphaseProxy::DefaultFilter));
    }
}

// A frozen body (made static by setMass) stops a light body as it stops a moving one: light debris lands on
// a frozen pile instead of sinking through it and freezing inside it.
TEST(BulletBinding, ALightBodyLandsOnFrozenBodies) {
    for (const bool light : {false, true}) {
        PhysicsWorld physics;
        BulletBinding binding(physics);
        BodyDesc d;
        d.shape.kind = BodyShape::Kind::Box;
        d.shape.halfExtents = {5, 5, 5};
        d.transform.translation = {0, -5, 0};
        binding.createBody(1, d); // the ground, static from the start
        d.shape.halfExtents = {0.5, 0.5, 0.5};
        d.mass = 1;
        d.inertia = Vec3{1, 1, 1} / 6;
        d.transform.translation = {0, 0.5, 0};
        binding.createBody(2, d);
        binding.setMass(2, 0, {}); // frozen where it rests
        d.shape.halfExtents = {0.25, 0.25, 0.25};
        d.transform.translation = {0, 3, 0};
        binding.createBody(3, d);
        binding.setCollidesWithMoving(3, !light);
        std::vector<ContactReport> contacts;
        for (int i = 0; i < 120; ++i)
            binding.step(1.0 / 60, contacts);
        EXPECT_NEAR(binding.motion(3).transform.translation.y, 1.25, 0.05) << light;
    }
}

// A heavy body set down on a frozen one pushes on it with its weight every step, over the wake impulse, and
// does not wake it; dropped onto it, it does.
TEST(BulletRuntime, WeightDoesNotWakeAFrozenBodyButAFallDoes) {
    for (const double drop : {0.0, 1.0}) {
        DestructionRuntime::Config rc;
        rc.impacts.collisionImpulseThreshold = 1e12; // no fracture
        Rig rig(true, 1, true, rc);
        rig.runtime->addGround({0, -1, 0}, {10, 1, 10});
        const ObjectId below = rig.addBox({0.5, 0.5, 0.5}, Frame{Mat3::identity(), {0, 0.5, 0}}, 2000);
        for (int i = 0; i < 30; ++i)
            rig.runtime->stepFrame();
        ASSERT_EQ(rig.bodyOf(below)->motion, BodyMotionState::Frozen);
        const ObjectId above =
            rig.addBox({0.5, 0.5, 0.5}, Frame{Mat3::identity(), {0, 1.5 + drop, 0}}, 2000); // 2 t: 327 N·s
        (void)above;
        for (int i = 0; i < 60; ++i)
            rig.runtime->stepFrame();
        EXPECT_EQ(rig.runtime->counters().piecesWoken > 0, drop > 0) << "dropped from " << drop << " m";
    }
}
