#include "rubble/runtime/DestructionRuntime.hpp"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <ctime>
#include <map>
#include <set>
#include <string>
#include <tuple>

#include "core/Rotation.hpp"
#include "geometry/MeshTopology.hpp"
#include "rubble/structure/Material.hpp"
#include "runtime/BodyTable.hpp"
#include "runtime/DebrisGovernor.hpp"
#include "runtime/DebrisPool.hpp"
#include "runtime/ImpactCollector.hpp"
#include "runtime/MaterialByName.hpp"
#include "runtime/PieceAdopter.hpp"
#include "runtime/StateAccess.hpp"
#include "runtime/StructureMonitor.hpp"
#include "runtime/SupportGraph.hpp"

namespace rubble {
namespace {

using Clock = std::chrono::steady_clock;

// This thread's CPU time, ms.
double threadCpuMs() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}

double msSince(Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

std::uint64_t mix(std::uint64_t h, std::uint64_t v) {
    h ^= v + 0x9E3779B97F4A7C15ull + (h << 6) + (h >> 2);
    return h * 0x100000001B3ull;
}

// Distance of the farthest mesh vertex from the body origin; above kTopologyAboveTriangles, of the farthest
// corner of the convex parts (they cover the mesh), so that adopting a large remainder reads no vertex.
double boundingRadius(const ObjectState& st, const Frame& objectToBody) {
    double r2 = 0;
    if (st.mesh.triangles.size() > kTopologyAboveTriangles && !st.convexParts.empty()) {
        for (const ConvexPolytope& part : st.convexParts)
            for (const Vec3& p : part.vertices())
                r2 = std::max(r2, lengthSquared(p - objectToBody.translation));
        return std::sqrt(r2);
    }
    for (const Vec3& p : st.mesh.positions)
        r2 = std::max(r2, lengthSquared(p - objectToBody.translation));
    return std::sqrt(r2);
}

std::vector<ConvexPolytope> worldParts(const ObjectState& st, const Frame& objectToWorld) {
    std::vector<ConvexPolytope> out;
    for (const ConvexPolytope& p : st.convexParts)
        out.push_back(p.transformed(objectToWorld));
    if (out.empty())
        out.push_back(ConvexPolytope::fromAabb(st.mesh.bounds()).transformed(objectToWorld));
    return out;
}

// The record of an object's body as its spawn describes it (role, motion and object given; no support flags).
BodyRecord objectRecord(ObjectId object, BodyRole role, BodyMotionState motion, const detail::PieceSpawn& s,
                        const ObjectState& st) {
    BodyRecord rec;
    rec.role = role;
    rec.motion = motion;
    rec.hasObject = true;
    rec.object = object;
    rec.objectToBody = s.objectToBody;
    rec.volume = s.volume;
    rec.mass = s.mass;
    rec.inertia = s.inertia;
    rec.triangles = s.triangles;
    rec.radius = boundingRadius(st, s.objectToBody);
    return rec;
}

// What the stages of one frame share.
struct FrameContext {
    double dt = 0;                        // the frame's time step (s)
    FrameStats stats;                     // what the frame did
    detail::ImpactBatch impacts;          // the impacts its contacts amount to
    std::vector<FractureOutcome> adopted; // the splits it adopted, for the callbacks
    Clock::time_point afterPhysics;       // where the runtime's own part of the frame starts
};

} // namespace

struct DestructionRuntime::Impl {
    Impl(PhysicsBinding& b, const Config& c)
        : binding(b), config(c), world(c.world), collector(config.impacts), support(config.support),
          structure(config.structure), governor(config.debris) {}

    PhysicsBinding& binding;
    Config config;
    DestructionWorld world;
    detail::BodyTable bodies;
    detail::ImpactCollector collector;
    detail::SupportGraph support;
    detail::StructureMonitor structure;
    std::vector<StructureBreak> breaks;            // the bonds this frame broke
    std::vector<StructureCollapse> collapses;      // the static bodies this frame let fall
    std::vector<PieceCreated> created;             // the piece bodies this frame made
    std::map<ObjectId, const Material*> materials; // of objects (pieces inherit their parent's)
    std::map<ObjectId, std::uint64_t> solids;      // pieces: the scene object they were cut from
    detail::DebrisGovernor governor;
    std::set<BodyId> projectiles;
    detail::DebrisPool particles;
    std::deque<ImpactMark> marks;
    RuntimeCounters counters;
    VolumeLedger ledger; // live is computed on demand
    BodyId nextId = 1;
    Vec3 focus;
    int searchesLeft = 0;
    std::vector<ContactReport> contacts;
    std::function<void(const FractureOutcome&)> onAdopted;
    std::function<void(const BodyRecord&)> onRemoved;

    bool deterministic() const { return config.world.deterministic; }

    BodyRecord& insert(BodyRecord rec, const BodyDesc& desc) {
        rec.id = nextId++;
        rec.bornFrame = counters.frames;
        binding.createBody(rec.id, desc);
        if (rec.role == BodyRole::Projectile)
            projectiles.insert(rec.id);
        return bodies.insert(rec);
    }

    // A dynamic body faster than the settling speed.
    bool moving(const BodyRecord& r) const {
        if (r.motion != BodyMotionState::Dynamic)
            return false;
        const BodyMotion m = binding.motion(r.id);
        return std::max(length(m.linearVelocity), length(m.angularVelocity)) >= config.debris.settlingSpeed;
    }

    Aabb boundsOf(const BodyRecord& r) const {
        const Vec3 c = binding.motion(r.id).transform.translation;
        const Vec3 e{r.radius, r.radius, r.radius};
        return Aabb{c - e, c + e};
    }

    // Removes a body from the engine and from every component; its object stays in the world.
    void dropBody(BodyId id) {
        const BodyRecord* r = bodies.find(id);
        if (!r)
            return;
        if (onRemoved)
            onRemoved(*r);
        support.remove(id);
        structure.remove(id);
        governor.removed(id);
        projectiles.erase(id);
        binding.removeBody(id);
        if (r->hasObject) {
            materials.erase(r->object);
            solids.erase(r->object);
        }
        bodies.erase(id);
    }

    // Removes a body and its object; what a resting body held is re-checked (support) or woken (frozen
    // debris).
    void destroy(BodyId id) {
        const BodyRecord* r = bodies.find(id);
        if (!r)
            return;
        if (r->role != BodyRole::Projectile && !moving(*r))
            governor.wakeNear(boundsOf(*r), config.support.tolerance);
        const bool hasObject = r->hasObject;
        const ObjectId object = r->object;
        dropBody(id);
        if (hasObject)
            world.removeObject(object);
    }

    void retire(BodyId id, detail::RetireReason reason, FrameStats& stats) {
        const BodyRecord* r = bodies.find(id);
        if (!r)
            return;
        const BodyMotion m = binding.motion(id);
        particles.add({m.transform.translation, m.linearVelocity, std::cbrt(r->volume), r->volume,
                       config.debris.particleLifetime});
        ledger.retired += r->volume;
        ++stats.piecesRetired;
        ++counters.piecesRetired;
        switch (reason) {
        case detail::RetireReason::Awake:
            ++counters.retired.awake;
            break;
        case detail::RetireReason::Triangles:
            ++counters.retired.triangles;
            break;
        case detail::RetireReason::Fade:
            ++counters.retired.faded;
            break;
        case detail::RetireReason::FellOut:
            ++counters.retired.fellOut;
            break;
        }
        destroy(id);
    }

    // A static or frozen body becomes dynamic (wake rules: docs/architecture.md).
    // A static body about to fall for want of support, as a collapse record.
    void recordCollapse(BodyId id, bool byStress) {
        const BodyRecord* r = bodies.find(id);
        if (!r || r->motion == BodyMotionState::Dynamic)
            return;
        StructureCollapse e;
        e.frame = counters.frames;
        e.body = id;
        e.position = binding.motion(id).transform.translation;
        e.volume = r->volume;
        e.mass = r->mass;
        e.byStress = byStress;
        if (r->hasObject)
            e.material = materialOf(r->object).name;
        collapses.push_back(std::move(e));
    }

    void makeDynamic(BodyId id) {
        BodyRecord* r = bodies.find(id);
        if (!r || r->motion == BodyMotionState::Dynamic)
            return;
        support.remove(id);
        structure.remove(id);
        governor.thawed(id);
        if (r->motion == BodyMotionState::Frozen)
            governor.woken(id, binding.motion(id).transform.translation, r->radius, config.support.tolerance);
        else
            governor.wakeNear(boundsOf(*r), config.support.tolerance);
        r->structural = false;
        r->anchor = false;
        binding.setMass(id, r->mass, r->inertia);
        bodies.setMotion(*r, BodyMotionState::Dynamic);
    }

    // A moving or frozen body given a velocity change (a blast's throw); a frozen one wakes first.
    void throwBody(BodyId id, const Vec3& dv) {
        makeDynamic(id);
        const BodyMotion m = binding.motion(id);
        binding.setVelocity(id, m.linearVelocity + dv, m.angularVelocity);
    }

    void freeze(BodyId id) {
        BodyRecord* r = bodies.find(id);
        if (!r || r->motion != BodyMotionState::Dynamic)
            return;
        binding.setMass(id, 0, {});
        bodies.setMotion(*r, BodyMotionState::Frozen);
        governor.frozen(id, binding.motion(id).transform.translation, r->radius);
    }

    const Material& materialOf(ObjectId id) const {
        const auto it = materials.find(id);
        return it != materials.end() ? *it->second : defaultMaterial();
    }

    // A node of the structure (when enabled).
    void addStructure(BodyId id, const std::vector<ConvexPolytope>& worldParts, const Material& m, bool root,
                      std::uint64_t solid, bool classify = false) {
        if (config.structure.enabled)
            structure.add(id, worldParts, m, root, solid, classify);
    }

    // The solid an object was cut from: its own id for a scene object, its ancestor's for a piece.
    std::uint64_t solidOf(ObjectId id) const {
        const auto it = solids.find(id);
        return it != solids.end() ? it->second : id;
    }

    // Submits an impact; false when the world's filter refuses it.
    bool submit(const detail::PendingImpact& p, FrameStats& stats) {
        if (config.structure.enabled)
            structure.damage(p.worldPoint, p.impact.impulse);
        if (!world.submitImpact(p.object, p.impact))
            return false;
        ++stats.impactsSubmitted;
        ++counters.impacts;
        marks.push_back({p.worldPoint, p.worldNormal, p.impact.impulse});
        while (static_cast<int>(marks.size()) > config.impacts.maxImpactMarks)
            marks.pop_front();
        return true;
    }

    // Adopts a split: the parent's body goes, the pieces' bodies are made, then the world commits the split.
    // False when no body carries the parent.
    bool adopt(const FractureOutcome& outcome, FrameStats& stats) {
        ledger.dropped += outcome.droppedVolume;
        ledger.dust += outcome.dustVolume();
        const BodyRecord* parentPtr = bodies.findObject(outcome.parent);
        if (!parentPtr) { // no body carries the parent: its pieces go at once, their volume retired
            ++counters.staleOutcomes;
            world.commit(outcome); // as a journal replay commits it, so the journal's removals replay
            for (const AdoptedPiece& p : outcome.pieces) {
                ledger.retired += std::abs(p.state->mass.volume);
                world.removeObject(p.id);
            }
            return false;
        }
        const BodyRecord parent = *parentPtr;
        const Material& material = materialOf(outcome.parent);
        const BodyMotion parentMotion = binding.motion(parent.id);
        const bool collapse = config.support.collapseUnsupported;
        detail::AdoptionPlan plan = detail::planAdoption(
            outcome, parent, parentMotion, config.adoption, collapse, config.debris.particleLifetime,
            config.structure.enabled && config.structure.bondDebris);
        const bool parentResting = !moving(parent);
        const std::uint64_t parentSolid = solidOf(parent.object);
        const bool parentAnchored = structure.anchored(parent.id); // its pieces may float as it did
        // The parent object goes when the split is committed; what it held wakes near its flying debris.
        dropBody(parent.id);
        ++stats.fractures;
        ++counters.fractures;
        const double impulse = outcome.impulse();
        for (std::size_t i = 0; i < plan.spawns.size(); ++i) {
            const detail::PieceSpawn& s = plan.spawns[i];
            const ObjectState& st = *outcome.pieces[i].state;
            BodyRecord rec =
                objectRecord(s.object, BodyRole::Piece,
                             s.isStatic ? BodyMotionState::Static : BodyMotionState::Dynamic, s, st);
            rec.anchor = s.anchor;
            rec.structural = s.structural;
            const BodyRecord& made = insert(rec, s.desc);
            if (&material != &defaultMaterial())
                materials[s.object] = &material;
            if (parentSolid != s.object)
                solids[s.object] = parentSolid;
            if (s.structural) {
                const auto parts = worldParts(st, s.desc.transform * s.objectToBody.inverse());
                addStructure(made.id, parts, material, s.anchor, parentSolid, parentAnchored);
                support.add(made.id, parts, s.anchor);
                support.queue(made.id);
            }
            if (parentResting && !s.isStatic)
                governor.wakeNear(boundsOf(made), config.support.tolerance);
            created.push_back({counters.frames, made.id, s.object, outcome.parent,
                               s.desc.transform.translation, s.desc.linearVelocity, s.volume, s.mass,
                               std::cbrt(s.volume), impulse, s.isStatic, material.name});
            ++stats.piecesCreated;
            ++counters.piecesCreated;
        }
        stats.piecesRetired += static_cast<int>(plan.particles.size());
        counters.piecesRetired += static_cast<long long>(plan.particles.size());
        counters.retired.dust += static_cast<long long>(plan.particles.size());
        particles.add(plan.particles);
        world.commit(outcome); // the pieces' bodies exist
        return true;
    }

    void settleSupport(FrameStats& stats) {
        if (!config.support.collapseUnsupported) {
            int none = 0;
            (void)support.settle(none);
            return;
        }
        const auto t0 = Clock::now();
        for (;;) {
            const int before = searchesLeft;
            const std::vector<BodyId> fallen = support.settle(searchesLeft);
            stats.supportSearches += before - searchesLeft;
            for (BodyId id : fallen) {
                recordCollapse(id, false);
                makeDynamic(id);
                ++stats.piecesCollapsed;
                ++counters.piecesCollapsed;
            }
            if (fallen.empty() || searchesLeft <= 0)
                break;
        }
        stats.supportMs += msSince(t0);
    }

    // Contact forces of moving bodies on structure nodes (impulse over the frame).
    void feedContactLoads(double dt) {
        if (!config.structure.enabled || dt <= 0)
            return;
        for (const ContactReport& c : contacts) {
            const Vec3 onA = c.normalOnB * (c.impulse / dt); // b pushes a away from b
            for (const auto& [self, other, force, point] :
                 {std::tuple{c.a, c.b, onA, c.pointOnA}, std::tuple{c.b, c.a, -onA, c.pointOnB}}) {
                const BodyRecord* o = bodies.find(other);
                if (o && o->motion == BodyMotionState::Dynamic && structure.contains(self))
                    structure.addLoad(self, force, point);
            }
        }
    }

    // Solves the structure; what lost its bonded support falls, and what rested on that is re-checked.
    void settleStructure(FrameStats& stats) {
        if (!config.structure.enabled)
            return;
        const auto t0 = Clock::now();
        const double cpu0 = threadCpuMs();
        int broken = 0;
        const std::vector<BodyId> fallen = structure.step(binding.gravity(), broken);
        stats.structureResidual = structure.residual();
        stats.bondsBroken += broken;
        for (StructureBreak e : structure.breaks()) {
            e.frame = counters.frames;
            breaks.push_back(std::move(e));
        }
        counters.bondsBroken += broken;
        for (BodyId id : fallen) {
            recordCollapse(id, true);
            makeDynamic(id);
            ++stats.piecesCollapsed;
            ++counters.piecesCollapsed;
        }
        stats.structureMs += msSince(t0); // what rested on the fallen is checked at the next support stage
        stats.structureCpuMs += threadCpuMs() - cpu0;
    }

    // A restored static object joins the structure: as saved, or (nothing saved) as a scene object at load.
    void restoreNode(BodyId body, ObjectId object, const std::vector<ConvexPolytope>& parts, bool saved,
                     const detail::StructureMonitor::SavedNode* node) {
        if (!saved) {
            addStructure(body, parts, defaultMaterial(), false, object, true);
            return;
        }
        if (!node)
            return;
        const detail::StructureMonitor::SavedNode& n = *node;
        const Material& m = *n.material;
        if (&m != &defaultMaterial())
            materials[object] = &m;
        if (n.solid != object)
            solids[object] = n.solid;
        addStructure(body, parts, m, n.root, n.solid, n.pending);
        if (n.anchor && config.structure.enabled)
            structure.markAnchor(body);
    }

    // The stages of a frame (stepFrame) and of an adoption between frames (adoptReady), over a FrameContext.
    void stepPhysics(FrameContext& f) {
        const auto t0 = Clock::now();
        contacts.clear();
        breaks.clear();
        collapses.clear();
        created.clear();
        f.stats.substeps = binding.step(f.dt, contacts);
        f.stats.physicsMs = msSince(t0);
        f.afterPhysics = Clock::now();
        ++counters.frames;
        searchesLeft = config.support.maxSearchesPerFrame;
    }
    void submitImpacts(FrameContext& f) {
        collector.gather(contacts, bodies, world, binding, counters.frames, config.debris.freezeSpeed,
                         governor.light());
        f.impacts = collector.take(f.dt);
        f.stats.projectileHits = f.impacts.projectileHits;
        counters.projectileHits += f.impacts.projectileHits;
        counters.collisionsOverBudget += f.impacts.collisionsOverBudget;
        for (const detail::PendingImpact& p : f.impacts.impacts)
            submit(p, f.stats);
        world.beginFrame();
    }
    void classifyAnchors(FrameContext& f) {
        const auto t0 = Clock::now();
        for (BodyId a : support.classify())
            if (BodyRecord* r = bodies.find(a))
                r->anchor = true;
        f.stats.supportMs += msSince(t0);
    }
    void adoptSplits(FrameContext& f) {
        for (FractureOutcome& o : world.collect())
            if (adopt(o, f.stats))
                f.adopted.push_back(std::move(o));
    }
    void settleSupportStage(FrameContext& f) { settleSupport(f.stats); }
    void reportAdopted(FrameContext& f) { // after the support stage: the pieces' motion is final
        if (onAdopted)
            for (const FractureOutcome& o : f.adopted)
                onAdopted(o);
    }
    void governDebris(FrameContext& f) { govern(f.impacts.frozenHits, f.dt, f.stats); }
    void settleStructureStage(FrameContext& f) {
        feedContactLoads(f.dt);
        settleStructure(f.stats);
    }
    void advanceStage(FrameContext& f) { advance(f.dt); }

    struct Stage {
        const char* name;
        void (Impl::*run)(FrameContext&);
    };
    // One frame, in order; support settles once, after the adoption.
    static constexpr Stage kFrame[] = {{"physics", &Impl::stepPhysics},
                                       {"impacts", &Impl::submitImpacts},
                                       {"anchors", &Impl::classifyAnchors},
                                       {"adopt", &Impl::adoptSplits},
                                       {"support", &Impl::settleSupportStage},
                                       {"adopted callbacks", &Impl::reportAdopted},
                                       {"debris", &Impl::governDebris},
                                       {"structure", &Impl::settleStructureStage},
                                       {"particles and projectiles", &Impl::advanceStage}};
    // The adoption of results ready between frames.
    static constexpr Stage kBetweenFrames[] = {{"adopt", &Impl::adoptSplits},
                                               {"support", &Impl::settleSupportStage},
                                               {"adopted callbacks", &Impl::reportAdopted}};

    template <std::size_t N>
    void run(const Stage (&stages)[N], FrameContext& f) {
        for (const Stage& stage : stages)
            (this->*stage.run)(f);
    }

    void govern(const std::map<BodyId, double>& frozenHits, double dt, FrameStats& stats) {
        const detail::GovernorActions a =
            governor.update(bodies, binding, frozenHits, stats.physicsMs, deterministic(), focus, dt);
        for (BodyId id : a.wake) {
            makeDynamic(id);
            ++stats.piecesWoken;
            ++counters.piecesWoken;
        }
        for (BodyId id : a.freeze) {
            freeze(id);
            ++stats.piecesFrozen;
            ++counters.piecesFrozen;
        }
        for (BodyId id : a.lighten) {
            binding.setCollidesWithMoving(id, false);
            ++counters.piecesLight;
        }
        for (const auto& [id, reason] : a.retire)
            retire(id, reason, stats);
    }

    void advance(double dt) {
        particles.advance(dt, binding.gravity());
        std::vector<BodyId> expired;
        for (BodyId id : projectiles) {
            BodyRecord& b = *bodies.find(id);
            b.age += dt;
            if (b.spent)
                b.spentAge += dt;
            if (b.age > config.projectileLifetime || b.spentAge > config.spentProjectileLifetime ||
                binding.motion(id).transform.translation.y < config.debris.killBelowY)
                expired.push_back(id);
        }
        for (BodyId id : expired)
            destroy(id);
    }
};

DestructionRuntime::DestructionRuntime(PhysicsBinding& binding, Config config)
    : impl_(std::make_unique<Impl>(binding, config)) {}

DestructionRuntime::~DestructionRuntime() {
    for (const auto& [id, r] : impl_->bodies.all())
        impl_->binding.removeBody(id);
}

const DestructionWorld& DestructionRuntime::world() const {
    return impl_->world;
}

PhysicsBinding& DestructionRuntime::binding() {
    return impl_->binding;
}

const DestructionRuntime::Config& DestructionRuntime::config() const {
    return impl_->config;
}

void DestructionRuntime::setImpactPolicy(const ImpactPolicy& policy) {
    impl_->config.impacts = policy;
}

void DestructionRuntime::setAdoptionPolicy(const AdoptionPolicy& policy) {
    impl_->config.adoption = policy;
}

void DestructionRuntime::setSupportPolicy(const SupportPolicy& policy) {
    impl_->config.support = policy;
}

void DestructionRuntime::setDebrisBudget(const DebrisBudget& budget) {
    impl_->config.debris = budget;
}

BodyId DestructionRuntime::addGround(const Vec3& center, const Vec3& halfExtents) {
    BodyDesc desc;
    desc.shape.kind = BodyShape::Kind::Box;
    desc.shape.halfExtents = halfExtents;
    desc.transform.translation = center;
    desc.friction = 0.8;
    BodyRecord rec;
    rec.role = BodyRole::Ground;
    rec.motion = BodyMotionState::Static;
    rec.structural = true;
    rec.radius = length(halfExtents);
    const BodyId id = impl_->insert(rec, desc).id;
    const std::vector<ConvexPolytope> parts{
        ConvexPolytope::fromAabb(Aabb{center - halfExtents, center + halfExtents})};
    impl_->addStructure(id, parts, defaultMaterial(), true, kSceneryNodeKey | id);
    impl_->support.add(id, parts, true);
    return id;
}

Result<ObjectId> DestructionRuntime::addObject(ObjectDesc desc, const Frame& placement, bool isStatic) {
    Impl& im = *impl_;
    if (!detail::isRotation(placement.rotation) || !isFinite(placement.translation))
        return Error{ErrorCode::InvalidInput,
                     "addObject: the placement is not a rigid motion (its rotation must "
                     "be orthonormal with determinant 1: Mat3{} is zero, "
                     "Mat3::identity() is no rotation)"};
    const Result<const Material*> named = detail::materialByName(desc.material);
    if (!named)
        return named.error();
    const Material* material = named.value();
    Result<ObjectId> id = im.world.addObject(std::move(desc));
    if (!id)
        return id;
    if (material != &defaultMaterial())
        im.materials[*id] = material;
    const ObjectState& st = *im.world.object(*id);
    detail::PieceSpawn s = detail::describeObjectBody(st, isStatic, 0);
    s.desc.transform = placement * s.objectToBody;
    BodyRecord rec = objectRecord(*id, BodyRole::Object,
                                  isStatic ? BodyMotionState::Static : BodyMotionState::Dynamic, s, st);
    rec.structural = isStatic;
    const BodyId body = im.insert(rec, s.desc).id;
    if (isStatic) {
        const auto parts = worldParts(st, placement);
        im.addStructure(body, parts, *material, false, *id, true);
        im.support.add(body, parts, false, true);
    }
    return id;
}

Result<BodyId> DestructionRuntime::addConvexBody(const std::vector<Vec3>& points, const Frame& placement,
                                                 double mass, bool neverSleeps) {
    if (points.size() < 4)
        return Error{ErrorCode::InvalidInput, "a convex body needs at least 4 points"};
    Aabb box;
    for (const Vec3& p : points)
        box.extend(p);
    const Vec3 s = box.size();
    if (!(s.x > 0 && s.y > 0 && s.z > 0))
        return Error{ErrorCode::InvalidInput, "points span no volume"};
    const Vec3 centre = box.center();
    BodyDesc desc;
    double r2 = 0;
    for (const Vec3& p : points) {
        desc.shape.points.push_back(p - centre);
        r2 = std::max(r2, lengthSquared(p - centre));
    }
    desc.transform = placement * Frame{Mat3::identity(), centre};
    desc.mass = std::max(mass, 0.0);
    desc.inertia =
        Vec3{s.y * s.y + s.z * s.z, s.x * s.x + s.z * s.z, s.x * s.x + s.y * s.y} * (desc.mass / 12);
    desc.neverSleeps = neverSleeps;
    BodyRecord rec;
    rec.role = BodyRole::Scenery;
    rec.motion = mass > 0 ? BodyMotionState::Dynamic : BodyMotionState::Static;
    rec.objectToBody = Frame{Mat3::identity(), centre};
    rec.volume = s.x * s.y * s.z;
    rec.mass = desc.mass;
    rec.inertia = desc.inertia;
    rec.radius = std::sqrt(r2);
    rec.structural = mass <= 0;
    const BodyId id = impl_->insert(rec, desc).id;
    if (mass <= 0) {
        const std::vector<ConvexPolytope> parts{ConvexPolytope::fromAabb(box).transformed(placement)};
        impl_->addStructure(id, parts, defaultMaterial(), true, kSceneryNodeKey | id);
        impl_->support.add(id, parts, true);
    }
    return id;
}

BodyId DestructionRuntime::fireProjectile(const Vec3& from, const Vec3& velocity, double mass,
                                          double radius) {
    BodyDesc desc;
    desc.shape.kind = BodyShape::Kind::Sphere;
    desc.shape.radius = radius;
    desc.transform.translation = from;
    desc.mass = mass;
    const double moment = 0.4 * mass * radius * radius;
    desc.inertia = Vec3{moment, moment, moment};
    desc.linearVelocity = velocity;
    desc.continuous = true;
    desc.neverSleeps = true;
    BodyRecord rec;
    rec.role = BodyRole::Projectile;
    rec.motion = BodyMotionState::Dynamic;
    rec.mass = mass;
    rec.inertia = desc.inertia;
    rec.volume = 4.0 / 3.0 * 3.14159265358979 * radius * radius * radius;
    rec.radius = radius;
    return impl_->insert(rec, desc).id;
}

void DestructionRuntime::removeBody(BodyId id) {
    impl_->destroy(id);
}

bool DestructionRuntime::submitImpact(BodyId id, const Vec3& worldPoint, const Vec3& worldNormal,
                                      double impulse) {
    Impl& im = *impl_;
    const BodyRecord* r = im.bodies.find(id);
    if (!r || !r->hasObject)
        return false;
    const Frame f = im.binding.motion(id).transform * r->objectToBody.inverse();
    detail::PendingImpact p;
    p.body = id;
    p.object = r->object;
    p.impact.point = f.applyInverse(worldPoint);
    p.impact.normal = f.rotation.transposed() * worldNormal;
    p.impact.impulse = impulse;
    p.worldPoint = worldPoint;
    p.worldNormal = worldNormal;
    FrameStats ignored;
    return im.submit(p, ignored);
}

bool DestructionRuntime::submitLocalImpact(ObjectId object, const Impact& impact) {
    Impl& im = *impl_;
    const BodyRecord* r = im.bodies.findObject(object);
    if (!r)
        return false;
    const Frame f = im.binding.motion(r->id).transform * r->objectToBody.inverse();
    detail::PendingImpact p;
    p.body = r->id;
    p.object = object;
    p.impact = impact;
    p.worldPoint = f.apply(impact.point);
    p.worldNormal = f.rotation * impact.normal;
    FrameStats ignored;
    return im.submit(p, ignored);
}

void DestructionRuntime::setJournalSink(std::function<void(const JournalEvent&)> sink) {
    impl_->world.setJournalSink(std::move(sink));
}

BlastOutcome DestructionRuntime::blast(const Vec3& center, double radius, double impulse, double edgeShare) {
    BlastOutcome out;
    if (!(radius > 0) || !(impulse > 0))
        return out;
    const ImpactPolicy& policy = impl_->config.impacts;
    struct InRange { // a body the blast reaches, its distance from the centre and its own centre
        double dist;
        BodyId id;
        Vec3 c;
    };
    std::vector<InRange> inRange;
    for (const auto& [id, b] : impl_->bodies.all()) {
        if (!b.hasObject)
            continue;
        const Vec3 c = motion(id).transform.translation;
        if (const double dist = length(center - c); dist <= radius + b.radius)
            inRange.push_back({dist, id, c});
    }
    // nearest first, so that the nearest cuts are queued first
    std::sort(inRange.begin(), inRange.end(), [](const InRange& x, const InRange& y) {
        return std::tie(x.dist, x.id) < std::tie(y.dist, y.id);
    });
    int movingCuts = 0;
    for (const auto& [dist, id, c] : inRange) {
        const BodyRecord& b = *body(id);
        const Vec3 n = dist > 1e-9 ? (center - c) * (1.0 / dist) : Vec3{0, 1, 0};
        const double share = 1.0 - (1.0 - edgeShare) * std::clamp((dist - b.radius) / radius, 0.0, 1.0);
        const bool moving = b.motion != BodyMotionState::Static;
        if (moving && (b.volume < policy.blastCutVolume ||
                       (policy.blastMaxCuts > 0 && movingCuts >= policy.blastMaxCuts))) {
            if (b.mass > 0)
                impl_->throwBody(id, n * -std::min(impulse * share / b.mass, policy.blastThrowSpeed * share));
            ++out.thrown;
            continue;
        }
        if (b.volume < policy.minFractureVolume)
            continue;
        const Vec3 at = c + n * std::min(dist, 0.7 * b.radius); // a cell centred here cuts the object
        if (submitImpact(id, at, n, impulse * share)) {
            ++out.impacts;
            movingCuts += moving ? 1 : 0;
        }
    }
    return out;
}

FrameStats DestructionRuntime::stepFrame(double dt) {
    FrameContext f;
    f.dt = dt;
    impl_->run(Impl::kFrame, f);
    f.stats.adoptMs = msSince(f.afterPhysics);
    return f.stats;
}

FrameStats DestructionRuntime::adoptReady() {
    FrameContext f;
    const auto t0 = Clock::now();
    if (!impl_->world.waitForResult(t0)) // nothing ready, or deterministic: adoption is frame-bound
        return f.stats;
    impl_->run(Impl::kBetweenFrames, f);
    f.stats.adoptMs = msSince(t0);
    return f.stats;
}

const BodyRecord* DestructionRuntime::body(BodyId id) const {
    return impl_->bodies.find(id);
}

const BodyRecord* DestructionRuntime::bodyOf(ObjectId id) const {
    return impl_->bodies.findObject(id);
}

std::vector<BodyId> DestructionRuntime::bodies() const {
    std::vector<BodyId> out;
    out.reserve(impl_->bodies.all().size());
    for (const auto& [id, r] : impl_->bodies.all())
        out.push_back(id);
    return out;
}

BodyMotion DestructionRuntime::motion(BodyId id) const {
    return impl_->binding.motion(id);
}

std::size_t DestructionRuntime::bodyCount() const {
    return impl_->bodies.all().size();
}

int DestructionRuntime::livePieces() const {
    return impl_->bodies.pieces();
}

int DestructionRuntime::awakeDebris() const {
    return impl_->bodies.awake();
}

int DestructionRuntime::lightDebris() const {
    return static_cast<int>(impl_->governor.light().size());
}

int DestructionRuntime::frozenDebris() const {
    return impl_->bodies.frozen();
}

std::size_t DestructionRuntime::debrisTriangles() const {
    return impl_->bodies.debrisTriangles();
}

int DestructionRuntime::awakeBudget() const {
    return impl_->governor.awakeBudget();
}

const std::vector<DebrisParticle>& DestructionRuntime::particles() const {
    return impl_->particles.particles();
}

const std::deque<ImpactMark>& DestructionRuntime::recentImpacts() const {
    return impl_->marks;
}

const RuntimeCounters& DestructionRuntime::counters() const {
    return impl_->counters;
}

VolumeLedger DestructionRuntime::volumes() const {
    VolumeLedger v = impl_->ledger;
    v.live = 0;
    for (const auto& [id, r] : impl_->bodies.all())
        if (r.hasObject)
            v.live += r.volume;
    return v;
}

std::vector<StructureBond> DestructionRuntime::structureBonds() const {
    return impl_->structure.bonds();
}

const std::vector<StructureBreak>& DestructionRuntime::structureBreaks() const {
    return impl_->breaks;
}

const std::vector<StructureCollapse>& DestructionRuntime::structureCollapses() const {
    return impl_->collapses;
}

const std::vector<PieceCreated>& DestructionRuntime::createdPieces() const {
    return impl_->created;
}

std::vector<BodyId> DestructionRuntime::supportNeighbours(BodyId id) const {
    return impl_->support.neighbours(id);
}

void DestructionRuntime::setFocus(const Vec3& point) {
    impl_->focus = point;
}

std::vector<ObjectPlacement> DestructionRuntime::placements() const {
    std::vector<ObjectPlacement> out;
    for (const auto& [id, r] : impl_->bodies.all()) {
        if (!r.hasObject)
            continue;
        const BodyMotion m = impl_->binding.motion(id);
        out.push_back({r.object, r.role, r.motion, m.transform * r.objectToBody.inverse(), m.linearVelocity,
                       m.angularVelocity});
    }
    return out;
}

namespace detail {

const DestructionRuntime::Config& StateAccess::config(const DestructionRuntime& runtime) {
    return runtime.impl_->config;
}

DestructionWorld& StateAccess::world(DestructionRuntime& runtime) {
    return runtime.impl_->world;
}

const BodyTable& StateAccess::bodies(const DestructionRuntime& runtime) {
    return runtime.impl_->bodies;
}

const StructureMonitor& StateAccess::structure(const DestructionRuntime& runtime) {
    return runtime.impl_->structure;
}

StructureMonitor& StateAccess::structure(DestructionRuntime& runtime) {
    return runtime.impl_->structure;
}

void StateAccess::dropBody(DestructionRuntime& runtime, BodyId id) {
    runtime.impl_->dropBody(id);
}

void StateAccess::continueLedger(DestructionRuntime& runtime, const VolumeLedger& volumes) {
    runtime.impl_->ledger = VolumeLedger{0, volumes.retired, volumes.dust, volumes.dropped};
}

void StateAccess::placeObject(DestructionRuntime& runtime, ObjectId id, const ObjectPlacement& p,
                              bool savedStructure, const StructureMonitor::SavedNode* node) {
    DestructionRuntime::Impl& im = *runtime.impl_;
    const ObjectState& st = *im.world.object(id);
    const bool isStatic = p.motion != BodyMotionState::Dynamic;
    PieceSpawn s =
        describeObjectBody(st, isStatic, p.role == BodyRole::Piece ? im.config.adoption.singleHullVolume : 0);
    s.desc.transform = p.objectToWorld * s.objectToBody;
    s.desc.linearVelocity = p.linearVelocity;
    s.desc.angularVelocity = p.angularVelocity;
    if (p.role == BodyRole::Piece) {
        s.desc.friction = im.config.adoption.friction;
        s.desc.restitution = im.config.adoption.restitution;
    }
    BodyRecord rec = objectRecord(id, p.role, p.motion, s, st);
    rec.structural = p.motion == BodyMotionState::Static;
    const BodyId body = im.insert(rec, s.desc).id;
    if (p.motion == BodyMotionState::Static) {
        const auto parts = worldParts(st, p.objectToWorld);
        im.restoreNode(body, id, parts, savedStructure, node);
        im.support.add(body, parts, false, true);
    } else if (p.motion == BodyMotionState::Frozen) {
        im.governor.frozen(body, s.desc.transform.translation, rec.radius);
    }
}

} // namespace detail

std::uint64_t DestructionRuntime::stateHash() const {
    std::uint64_t h = 0xCBF29CE484222325ull;
    for (const auto& [id, r] : impl_->bodies.all()) {
        if (!r.hasObject)
            continue;
        h = mix(h, id);
        h = mix(h, r.object);
        h = mix(h, static_cast<std::uint64_t>(r.motion));
        if (const ObjectState* st = impl_->world.object(r.object)) {
            h = mix(h, st->version);
            h = mix(h, st->mesh.hash());
        }
        const Frame t = impl_->binding.motion(id).transform;
        for (int i = 0; i < 3; ++i) {
            h = mix(h, std::bit_cast<std::uint64_t>(t.translation[i]));
            for (int j = 0; j < 3; ++j)
                h = mix(h, std::bit_cast<std::uint64_t>(t.rotation.m[i][j]));
        }
    }
    const VolumeLedger& v = impl_->ledger;
    for (double x : {v.retired, v.dust, v.dropped})
        h = mix(h, std::bit_cast<std::uint64_t>(x));
    return h;
}

void DestructionRuntime::setOnAdopted(std::function<void(const FractureOutcome&)> callback) {
    impl_->onAdopted = std::move(callback);
}

void DestructionRuntime::setOnRemoved(std::function<void(const BodyRecord&)> callback) {
    impl_->onRemoved = std::move(callback);
}

} // namespace rubble
