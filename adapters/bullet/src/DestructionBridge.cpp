#include "rubble/bullet/DestructionBridge.hpp"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstring>

#include "rubble/bullet/Convert.hpp"

namespace rubble::bullet {
namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

std::uint64_t mix(std::uint64_t h, std::uint64_t v) {
    h ^= v + 0x9E3779B97F4A7C15ull + (h << 6) + (h >> 2);
    return h * 0x100000001B3ull;
}

std::uint64_t floatBits(btScalar f) {
    std::uint64_t out = 0;
    std::memcpy(&out, &f, sizeof f);
    return out;
}

std::uint32_t kindColor(BodyKind k) {
    switch (k) {
    case BodyKind::Ground:
        return 0x808080FFu;
    case BodyKind::Scenery:
        return 0x40A0FFFFu;
    case BodyKind::Object:
        return 0x40FF40FFu;
    case BodyKind::Piece:
        return 0xFFD040FFu;
    case BodyKind::Projectile:
        return 0xFF4040FFu;
    }
    return 0xFFFFFFFFu;
}

Frame principalFrame(const MassProperties& m) {
    return Frame{m.principalAxes, m.centerOfMass};
}

// Principal moments of a solid of the object's shape and density (floored so that slivers stay stable).
btVector3 principalInertia(const ObjectState& st, double volume) {
    const double floorMoment = 1e-9 * std::max(volume, 1e-12);
    return toBt(Vec3{std::max(st.mass.principalMoments.x, floorMoment),
                     std::max(st.mass.principalMoments.y, floorMoment),
                     std::max(st.mass.principalMoments.z, floorMoment)} *
                st.density);
}

// Static collision objects whose broadphase bounds overlap a box.
struct StaticOverlaps : btBroadphaseAabbCallback {
    const btCollisionObject* self = nullptr;
    std::vector<btCollisionObject*> found;
    bool process(const btBroadphaseProxy* proxy) override {
        auto* o = static_cast<btCollisionObject*>(proxy->m_clientObject);
        if (o != self && o->isStaticObject())
            found.push_back(o);
        return true;
    }
};

// Whether a contact pair test found the two bodies within the callback's distance threshold.
struct Touching : btCollisionWorld::ContactResultCallback {
    bool touching = false;
    btScalar addSingleResult(btManifoldPoint& cp, const btCollisionObjectWrapper*, int, int,
                             const btCollisionObjectWrapper*, int, int) override {
        if (cp.getDistance() <= m_closestDistanceThreshold)
            touching = true;
        return 0;
    }
};

// Collapsible: a static destructible body that holds itself up only through what it touches.
bool collapsible(const Body& b) {
    return b.isStatic && !b.anchor && b.hasObject &&
           (b.kind == BodyKind::Object || b.kind == BodyKind::Piece);
}

// A root of support: the ground, static scenery, an anchor.
bool supportRoot(const Body& b) {
    return b.isStatic && (b.kind == BodyKind::Ground || b.kind == BodyKind::Scenery || b.anchor);
}

} // namespace

DestructionBridge::DestructionBridge(PhysicsWorld& physics, DestructionWorld& destruction, Config config)
    : physics_(physics), destruction_(destruction), config_(config) {
    physics_.setPreTickCallback([this](double) { preTick(); });
    physics_.setPostTickCallback([this](double) { postTick(); });
}

DestructionBridge::~DestructionBridge() {
    physics_.setPreTickCallback({});
    physics_.setPostTickCallback({});
    while (!bodies_.empty())
        destroy(bodies_.begin()->first, false);
}

Body& DestructionBridge::insert(std::unique_ptr<Body> body) {
    const std::uint64_t handle = nextHandle_++;
    body->bornFrame = counters_.frames;
    body->rigid->setUserPointer(body.get());
    body->rigid->setUserIndex(static_cast<int>(handle & 0x7FFFFFFF));
    body->rigid->setSleepingThresholds(static_cast<btScalar>(config_.linearSleep),
                                       static_cast<btScalar>(config_.angularSleep));
    physics_.world().addRigidBody(body->rigid.get());
    if (body->hasObject)
        byObject_[body->object] = handle;
    if (body->kind == BodyKind::Piece)
        ++livePieces_;
    Body& ref = *body;
    bodies_.emplace(handle, std::move(body));
    return ref;
}

std::uint64_t DestructionBridge::handleOf(const Body& body) const {
    if (body.hasObject) {
        auto it = byObject_.find(body.object);
        if (it != byObject_.end())
            return it->second;
    }
    for (const auto& [h, b] : bodies_)
        if (b.get() == &body)
            return h;
    return 0;
}

void DestructionBridge::destroy(std::uint64_t handle, bool removeObject) {
    auto it = bodies_.find(handle);
    if (it == bodies_.end())
        return;
    Body& b = *it->second;
    if (onRemoved_)
        onRemoved_(b);
    physics_.world().removeRigidBody(b.rigid.get());
    if (b.hasObject) {
        byObject_.erase(b.object);
        if (removeObject)
            destruction_.removeObject(b.object);
    }
    if (b.kind == BodyKind::Piece)
        --livePieces_;
    bodies_.erase(it);
}

Body& DestructionBridge::addGround(const Vec3& center, const Vec3& halfExtents) {
    auto b = std::make_unique<Body>();
    b->kind = BodyKind::Ground;
    b->isStatic = true;
    b->shape = CollisionShape::box(halfExtents);
    btTransform t;
    t.setIdentity();
    t.setOrigin(toBt(center));
    btRigidBody::btRigidBodyConstructionInfo info(0, nullptr, b->shape->shape());
    info.m_startWorldTransform = t;
    info.m_friction = 0.8f;
    b->rigid = std::make_unique<btRigidBody>(info);
    return insert(std::move(b));
}

Body* DestructionBridge::makeObjectBody(ObjectId id, const btTransform& bodyWorld, bool isStatic,
                                        BodyKind kind) {
    const ObjectState* st = destruction_.object(id);
    if (!st)
        return nullptr;
    auto b = std::make_unique<Body>();
    b->kind = kind;
    b->hasObject = true;
    b->object = id;
    b->isStatic = isStatic;
    b->objectToBody = principalFrame(st->mass);
    b->volume = std::abs(st->mass.volume);
    if (kind == BodyKind::Piece && st->convexParts.size() > 1 && b->volume < config_.singleHullVolume) {
        std::vector<Vec3> points;
        for (const ConvexPolytope& part : st->convexParts)
            for (const Vec3& p : part.vertices())
                points.push_back(p);
        b->shape = CollisionShape::fromParts({}, points, b->objectToBody, config_.collisionMargin);
    }
    if (!b->shape)
        b->shape = CollisionShape::fromParts(st->convexParts, st->mesh.positions, b->objectToBody,
                                             config_.collisionMargin);
    if (!b->shape) {
        const Aabb box = st->mesh.bounds();
        b->shape = CollisionShape::box(box.empty() ? Vec3{0.1, 0.1, 0.1} : box.size() * 0.5);
    }
    b->mass = isStatic ? 0.0 : st->density * b->volume;
    const btVector3 inertia = isStatic ? btVector3(0, 0, 0) : principalInertia(*st, b->volume);
    btRigidBody::btRigidBodyConstructionInfo info(static_cast<btScalar>(b->mass), nullptr, b->shape->shape(),
                                                  inertia);
    info.m_startWorldTransform = bodyWorld;
    info.m_friction = 0.7f;
    info.m_restitution = 0.1f;
    b->rigid = std::make_unique<btRigidBody>(info);
    b->supportKnown = kind == BodyKind::Piece;
    Body& ref = insert(std::move(b));
    if (isStatic && kind == BodyKind::Object)
        unclassified_.push_back(handleOf(ref));
    return &ref;
}

Result<ObjectId> DestructionBridge::addObject(ObjectDesc desc, const Frame& placement, bool isStatic) {
    Result<ObjectId> id = destruction_.addObject(std::move(desc));
    if (!id)
        return id;
    const ObjectState* st = destruction_.object(*id);
    const btTransform bodyWorld = toBt(placement) * toBt(principalFrame(st->mass));
    if (!makeObjectBody(*id, bodyWorld, isStatic, BodyKind::Object)) {
        destruction_.removeObject(*id);
        return Error{ErrorCode::InvalidInput, "object has no usable collision shape"};
    }
    return id;
}

Result<Body*> DestructionBridge::addConvexBody(const std::vector<Vec3>& points, const Frame& placement,
                                               double mass) {
    if (points.size() < 4)
        return Error{ErrorCode::InvalidInput, "a convex body needs at least 4 points"};
    Aabb box;
    for (const Vec3& p : points)
        box.extend(p);
    const Vec3 centre = box.center();
    auto b = std::make_unique<Body>();
    b->kind = BodyKind::Scenery;
    b->isStatic = mass <= 0;
    b->objectToBody = Frame{Mat3::identity(), centre};
    b->shape = CollisionShape::fromParts({}, points, b->objectToBody, config_.collisionMargin);
    if (!b->shape)
        return Error{ErrorCode::InvalidInput, "points span no volume"};
    const Vec3 s = box.size();
    b->volume = s.x * s.y * s.z;
    b->mass = std::max(mass, 0.0);
    btVector3 inertia(0, 0, 0);
    if (b->mass > 0)
        b->shape->shape()->calculateLocalInertia(static_cast<btScalar>(b->mass), inertia);
    btRigidBody::btRigidBodyConstructionInfo info(static_cast<btScalar>(b->mass), nullptr, b->shape->shape(),
                                                  inertia);
    info.m_startWorldTransform = toBt(placement) * toBt(b->objectToBody);
    b->rigid = std::make_unique<btRigidBody>(info);
    return &insert(std::move(b));
}

Body& DestructionBridge::fireProjectile(const Vec3& from, const Vec3& velocity, double mass, double radius) {
    auto b = std::make_unique<Body>();
    b->kind = BodyKind::Projectile;
    b->mass = mass;
    b->volume = 4.0 / 3.0 * 3.14159265358979 * radius * radius * radius;
    b->shape = CollisionShape::sphere(radius);
    btVector3 inertia;
    b->shape->shape()->calculateLocalInertia(static_cast<btScalar>(mass), inertia);
    btRigidBody::btRigidBodyConstructionInfo info(static_cast<btScalar>(mass), nullptr, b->shape->shape(),
                                                  inertia);
    info.m_startWorldTransform.setIdentity();
    info.m_startWorldTransform.setOrigin(toBt(from));
    b->rigid = std::make_unique<btRigidBody>(info);
    b->rigid->setLinearVelocity(toBt(velocity));
    b->rigid->setCcdMotionThreshold(static_cast<btScalar>(radius * 0.5));
    b->rigid->setCcdSweptSphereRadius(static_cast<btScalar>(radius * 0.9));
    b->rigid->setActivationState(DISABLE_DEACTIVATION);
    return insert(std::move(b));
}

void DestructionBridge::removeBody(Body& body) {
    if (body.isStatic && config_.collapseUnsupported) {
        FrameStats ignored;
        queueNeighbours(body, ignored);
    }
    destroy(handleOf(body), true);
}

Body* DestructionBridge::bodyOf(ObjectId id) {
    auto it = byObject_.find(id);
    if (it == byObject_.end())
        return nullptr;
    return bodies_.at(it->second).get();
}

std::vector<Body*> DestructionBridge::bodies() const {
    std::vector<Body*> out;
    out.reserve(bodies_.size());
    for (const auto& [h, b] : bodies_)
        out.push_back(b.get());
    return out;
}

void DestructionBridge::preTick() {
    for (auto& [h, b] : bodies_) {
        if (b->isStatic)
            continue;
        b->preLinearVelocity = b->rigid->getLinearVelocity();
        b->preAngularVelocity = b->rigid->getAngularVelocity();
    }
}

void DestructionBridge::postTick() {
    btCollisionDispatcher& dispatcher = physics_.dispatcher();
    const int manifolds = dispatcher.getNumManifolds();
    for (int i = 0; i < manifolds; ++i) {
        btPersistentManifold* m = dispatcher.getManifoldByIndexInternal(i);
        const int n = m->getNumContacts();
        if (n == 0)
            continue;
        auto* a = static_cast<Body*>(m->getBody0()->getUserPointer());
        auto* b = static_cast<Body*>(m->getBody1()->getUserPointer());
        if (!a || !b)
            continue;
        // the deepest contact and the total impulse of the pair
        int best = 0;
        double total = 0;
        for (int c = 0; c < n; ++c) {
            const btManifoldPoint& cp = m->getContactPoint(c);
            total += cp.getAppliedImpulse();
            if (cp.getDistance() < m->getContactPoint(best).getDistance())
                best = c;
        }
        const btManifoldPoint& cp = m->getContactPoint(best);
        if (cp.getDistance() > 0.05f)
            continue;
        const bool aProj = a->kind == BodyKind::Projectile, bProj = b->kind == BodyKind::Projectile;
        // velocity of a body at a world point before this step
        auto preVelocity = [](const Body& body, const btVector3& p) {
            if (body.isStatic)
                return btVector3(0, 0, 0);
            return body.preLinearVelocity +
                   body.preAngularVelocity.cross(p - body.rigid->getCenterOfMassPosition());
        };
        auto makeImpact = [&](const Body& target, bool targetIsA, double impulse) {
            const btVector3 pw = targetIsA ? cp.getPositionWorldOnA() : cp.getPositionWorldOnB();
            const btVector3 nw = targetIsA ? -cp.m_normalWorldOnB : cp.m_normalWorldOnB;
            const btTransform inv = target.objectTransform().inverse();
            PendingImpact pi;
            pi.object = target.object;
            pi.impact.point = fromBt(inv * pw);
            pi.impact.normal = fromBt(inv.getBasis() * nw);
            pi.impact.impulse = impulse;
            pi.worldPoint = fromBt(pw);
            pi.worldNormal = fromBt(nw);
            return pi;
        };
        if (aProj || bProj) {
            if (aProj && bProj)
                continue;
            Body& proj = aProj ? *a : *b;
            Body& other = aProj ? *b : *a;
            if (proj.spent)
                continue;
            proj.spent = true;
            ++counters_.projectileHits;
            if (!other.hasObject || (other.kind != BodyKind::Object && other.kind != BodyKind::Piece))
                continue;
            const ObjectState* st = destruction_.object(other.object);
            if (!st || !st->destructible || other.volume < config_.minFractureVolume)
                continue;
            const btVector3 pw = aProj ? cp.getPositionWorldOnB() : cp.getPositionWorldOnA();
            const btVector3 rel = preVelocity(proj, pw) - preVelocity(other, pw);
            const double impulse = std::max({proj.mass * static_cast<double>(rel.length()),
                                             static_cast<double>(total), st->impulseThreshold});
            projectileImpacts_.push_back(makeImpact(other, !aProj, impulse));
            continue;
        }
        const btVector3 pw = cp.getPositionWorldOnB();
        const btVector3 rel = preVelocity(*a, pw) - preVelocity(*b, pw);
        const double approach = -static_cast<double>(rel.dot(cp.m_normalWorldOnB));
        if (approach < config_.minApproachSpeed || total < config_.collisionImpulseThreshold)
            continue;
        for (Body* target : {a, b}) {
            if (!target->hasObject || (target->kind != BodyKind::Object && target->kind != BodyKind::Piece))
                continue;
            if (counters_.frames < target->bornFrame + static_cast<std::uint64_t>(config_.graceFrames) &&
                target->kind == BodyKind::Piece)
                continue;
            if (target->volume < config_.minFractureVolume)
                continue;
            const ObjectState* st = destruction_.object(target->object);
            if (!st || !st->destructible || total < st->impulseThreshold)
                continue;
            auto it = collisionImpacts_.find(target->object);
            if (it != collisionImpacts_.end() && it->second.impact.impulse >= total)
                continue;
            collisionImpacts_[target->object] = makeImpact(*target, target == a, total);
        }
    }
}

void DestructionBridge::submitImpacts(FrameStats& stats) {
    auto submit = [&](const PendingImpact& pi) {
        if (!destruction_.submitImpact(pi.object, pi.impact))
            return;
        ++stats.impactsSubmitted;
        ++counters_.impacts;
        marks_.push_back({pi.worldPoint, pi.worldNormal, pi.impact.impulse});
        while (static_cast<int>(marks_.size()) > config_.maxImpactMarks)
            marks_.pop_front();
    };
    for (const PendingImpact& pi : projectileImpacts_)
        submit(pi);
    for (const auto& [id, pi] : collisionImpacts_)
        submit(pi);
    projectileImpacts_.clear();
    collisionImpacts_.clear();
}

void DestructionBridge::adopt(const FractureOutcome& outcome, FrameStats& stats) {
    droppedVolume_ += outcome.droppedVolume;
    auto pit = byObject_.find(outcome.parent);
    if (pit == byObject_.end()) {
        // No body to replace: the pieces cannot be placed; drop them (their volume counts as retired).
        ++counters_.staleOutcomes;
        for (ObjectId pid : outcome.pieces) {
            if (const ObjectState* st = destruction_.object(pid))
                retiredVolume_ += std::abs(st->mass.volume);
            destruction_.removeObject(pid);
        }
        return;
    }
    const std::uint64_t parentHandle = pit->second;
    Body& parent = *bodies_.at(parentHandle);
    const btTransform parentObject = parent.objectTransform();
    const btVector3 v = parent.rigid->getLinearVelocity();
    const btVector3 w = parent.rigid->getAngularVelocity();
    const btVector3 c = parent.rigid->getCenterOfMassPosition();
    const bool parentStatic = parent.isStatic;
    auto isRemainder = [&](std::size_t i) {
        return i >= outcome.pieceCells.size() || outcome.pieceCells[i] < 0;
    };
    // Static parent, collapse on: remainder pieces start static and are checked for support after
    // creation; a floating parent (an anchor) keeps its largest remainder piece as the new anchor.
    // Collapse off: the largest piece stays static.
    const bool collapse = parentStatic && config_.keepStaticRemainder && config_.collapseUnsupported;
    const bool floating = collapse && parent.anchor;
    std::size_t keep = outcome.pieces.size();
    if (parentStatic && config_.keepStaticRemainder && (!collapse || floating)) {
        double best = -1;
        for (std::size_t i = 0; i < outcome.pieces.size(); ++i) {
            const ObjectState* st = destruction_.object(outcome.pieces[i]);
            if (st && st->mass.volume > best && (!floating || isRemainder(i))) {
                best = st->mass.volume;
                keep = i;
            }
        }
    }
    if (collapse) {
        const auto t0 = Clock::now();
        queueNeighbours(parent, stats); // what rested on the parent is re-checked
        stats.supportMs += msSince(t0);
    }
    destroy(parentHandle, false); // the DestructionWorld already removed the parent object
    ++stats.fractures;
    ++counters_.fractures;
    // Debris of a static object is thrown outward by the hit: a share of the impulse, split by mass (so all
    // debris of one hit gets the same speed), along the surface normal and away from the impact point. A
    // dynamic parent's pieces keep its velocity field only: the physics engine applied the impulse already.
    double debrisMass = 0;
    if (parentStatic && config_.debrisKick > 0 && !outcome.impacts.empty())
        for (std::size_t i = 0; i < outcome.pieces.size(); ++i)
            if (!isRemainder(i))
                if (const ObjectState* st = destruction_.object(outcome.pieces[i]))
                    debrisMass += st->density * std::abs(st->mass.volume);
    auto kick = [&](std::size_t i) {
        if (debrisMass <= 0 || isRemainder(i) || i >= outcome.pieceFrames.size())
            return btVector3(0, 0, 0);
        const Vec3 at = outcome.pieceFrames[i].translation; // the piece's centre, parent coordinates
        const Impact* hit = &outcome.impacts.front();
        for (const Impact& m : outcome.impacts)
            if (lengthSquared(m.point - at) < lengthSquared(hit->point - at))
                hit = &m;
        Vec3 dir = normalized(hit->normal);
        if (const Vec3 away = at - hit->point; lengthSquared(away) > 0)
            dir = normalized(dir + 0.5 * normalized(away));
        const double speed =
            std::min(config_.debrisKick * hit->impulse / debrisMass, config_.maxDebrisKickSpeed);
        return parentObject.getBasis() * toBt(dir * speed);
    };
    for (std::size_t i = 0; i < outcome.pieces.size(); ++i) {
        const ObjectId pid = outcome.pieces[i];
        const ObjectState* st = destruction_.object(pid);
        if (!st)
            continue;
        const Frame pieceFrame = i < outcome.pieceFrames.size() ? outcome.pieceFrames[i] : Frame{};
        const btTransform pieceObject = parentObject * toBt(pieceFrame);
        const btTransform bodyWorld = pieceObject * toBt(principalFrame(st->mass));
        const bool checked = collapse && !floating && isRemainder(i); // static until its support check
        const bool isStatic = (parentStatic && i == keep) || checked;
        const double volume = std::abs(st->mass.volume);
        const btVector3 pv =
            v + w.cross(bodyWorld.getOrigin() - c) + (isStatic ? btVector3(0, 0, 0) : kick(i));
        if (!isStatic && volume < config_.minPieceVolume) {
            particles_.push_back({fromBt(bodyWorld.getOrigin()), fromBt(pv), std::cbrt(volume), volume,
                                  config_.debrisLifetime});
            retiredVolume_ += volume;
            destruction_.removeObject(pid);
            ++stats.piecesRetired;
            ++counters_.piecesRetired;
            continue;
        }
        Body* body = makeObjectBody(pid, bodyWorld, isStatic, BodyKind::Piece);
        if (!body)
            continue;
        if (!isStatic) {
            body->rigid->setLinearVelocity(pv);
            body->rigid->setAngularVelocity(w);
            body->preLinearVelocity = pv;
            body->preAngularVelocity = w;
        }
        body->anchor = floating && i == keep;
        if (checked)
            supportQueue_.push_front(byObject_.at(pid));
        ++stats.piecesCreated;
        ++counters_.piecesCreated;
    }
    if (collapse) {
        const auto t0 = Clock::now();
        settleSupport(stats); // before the callback, so that it sees the pieces' final static state
        stats.supportMs += msSince(t0);
    }
    destruction_.finishAdoption(outcome); // the pieces' bodies and collision shapes exist: the impact's
                                          // timing record ends here (not the renderer's upload below)
    if (onAdopted_)
        onAdopted_(outcome);
}

std::vector<std::uint64_t> DestructionBridge::staticNeighbours(const Body& body, FrameStats& stats) {
    const auto tol = static_cast<btScalar>(config_.supportTolerance);
    btVector3 lo, hi;
    body.rigid->getCollisionShape()->getAabb(body.rigid->getWorldTransform(), lo, hi);
    StaticOverlaps overlaps;
    overlaps.self = body.rigid.get();
    physics_.world().getBroadphase()->aabbTest(lo - btVector3(tol, tol, tol), hi + btVector3(tol, tol, tol),
                                               overlaps);
    std::vector<std::uint64_t> out;
    for (btCollisionObject* o : overlaps.found) {
        auto* other = static_cast<Body*>(o->getUserPointer());
        if (!other)
            continue;
        Touching touching;
        touching.m_closestDistanceThreshold = tol;
        physics_.world().contactPairTest(body.rigid.get(), o, touching);
        ++stats.supportQueries;
        ++counters_.supportQueries;
        if (touching.touching)
            out.push_back(static_cast<std::uint64_t>(o->getUserIndex())); // the body's handle (see insert)
    }
    std::sort(out.begin(), out.end()); // broadphase order is not part of the result
    return out;
}

void DestructionBridge::queueNeighbours(const Body& body, FrameStats& stats) {
    for (std::uint64_t h : staticNeighbours(body, stats))
        if (collapsible(*bodies_.at(h)))
            supportQueue_.push_back(h);
}

DestructionBridge::Support DestructionBridge::searchSupport(std::uint64_t start,
                                                            std::vector<std::uint64_t>& component,
                                                            FrameStats& stats) {
    // breadth first over touching static bodies until a root turns up
    component.assign(1, start);
    for (std::size_t next = 0; next < component.size(); ++next) {
        if (static_cast<int>(next) >= config_.maxSupportVisits)
            return Support::Unknown;
        for (std::uint64_t h : staticNeighbours(*bodies_.at(component[next]), stats)) {
            const Body& b = *bodies_.at(h);
            if (supportRoot(b))
                return Support::Supported;
            if (collapsible(b) && std::find(component.begin(), component.end(), h) == component.end())
                component.push_back(h);
        }
    }
    return Support::Unsupported;
}

void DestructionBridge::classifyStaticObjects(FrameStats& stats) {
    // A static object whose static neighbourhood reaches no root was placed floating: it (and everything
    // static in that neighbourhood) becomes an anchor.
    std::vector<std::uint64_t> pending;
    pending.swap(unclassified_);
    std::vector<std::uint64_t> component;
    for (std::uint64_t h : pending) {
        auto it = bodies_.find(h);
        if (it == bodies_.end() || it->second->supportKnown || !it->second->isStatic)
            continue;
        const Support s = searchSupport(h, component, stats);
        for (std::uint64_t m : component) {
            Body& b = *bodies_.at(m);
            if (b.kind != BodyKind::Object || b.supportKnown)
                continue;
            b.supportKnown = true;
            b.anchor = s == Support::Unsupported;
        }
        it->second->supportKnown = true;
    }
}

void DestructionBridge::settleSupport(FrameStats& stats) {
    std::vector<std::uint64_t> component;
    while (!supportQueue_.empty() && supportSearchesLeft_ > 0) {
        const std::uint64_t h = supportQueue_.front();
        supportQueue_.pop_front();
        auto it = bodies_.find(h);
        if (it == bodies_.end() || !collapsible(*it->second))
            continue;
        --supportSearchesLeft_;
        if (searchSupport(h, component, stats) != Support::Unsupported)
            continue;
        // nothing static below: the whole component falls
        for (std::uint64_t m : component)
            makeDynamic(m, stats);
    }
}

void DestructionBridge::makeDynamic(std::uint64_t handle, FrameStats& stats) {
    Body& b = *bodies_.at(handle);
    const ObjectState* st = destruction_.object(b.object);
    if (!b.isStatic || !st)
        return;
    btDiscreteDynamicsWorld& world = physics_.world();
    world.removeRigidBody(b.rigid.get()); // re-added below so that it joins the dynamic broadphase set
    b.isStatic = false;
    b.anchor = false;
    b.mass = st->density * b.volume;
    b.rigid->setMassProps(static_cast<btScalar>(b.mass), principalInertia(*st, b.volume));
    b.rigid->updateInertiaTensor();
    b.rigid->setLinearVelocity(btVector3(0, 0, 0));
    b.rigid->setAngularVelocity(btVector3(0, 0, 0));
    b.preLinearVelocity = b.preAngularVelocity = btVector3(0, 0, 0);
    b.rigid->forceActivationState(ACTIVE_TAG);
    b.rigid->setDeactivationTime(0);
    world.addRigidBody(b.rigid.get());
    ++stats.piecesCollapsed;
    ++counters_.piecesCollapsed;
    if (b.kind == BodyKind::Piece && b.volume < config_.minPieceVolume)
        retire(handle, stats);
}

void DestructionBridge::retire(std::uint64_t handle, FrameStats& stats) {
    auto it = bodies_.find(handle);
    if (it == bodies_.end())
        return;
    Body& b = *it->second;
    if (b.isStatic && config_.collapseUnsupported)
        queueNeighbours(b, stats); // what this static piece held up is re-checked
    const btVector3 p = b.rigid->getCenterOfMassPosition();
    particles_.push_back({fromBt(p), fromBt(b.rigid->getLinearVelocity()), std::cbrt(b.volume), b.volume,
                          config_.debrisLifetime});
    retiredVolume_ += b.volume;
    ++stats.piecesRetired;
    ++counters_.piecesRetired;
    destroy(handle, true);
}

void DestructionBridge::retireExcess(FrameStats& stats) {
    std::vector<std::uint64_t> fallen;
    std::vector<std::pair<double, std::uint64_t>> pieces;
    for (const auto& [h, b] : bodies_) {
        if (b->kind != BodyKind::Piece && b->kind != BodyKind::Object)
            continue;
        if (!b->isStatic && b->rigid->getCenterOfMassPosition().y() < config_.killBelowY)
            fallen.push_back(h);
        else if (b->kind == BodyKind::Piece && !b->isStatic)
            pieces.push_back({b->volume, h});
    }
    for (std::uint64_t h : fallen)
        retire(h, stats);
    std::sort(pieces.begin(), pieces.end());
    // The triangle budget of dynamic pieces: the smallest go first.
    std::size_t i = 0;
    for (std::size_t triangles = livePieceTriangles();
         triangles > config_.maxLivePieceTriangles && i < pieces.size(); ++i) {
        const Body& b = *bodies_.at(pieces[i].second);
        if (const ObjectState* st = destruction_.object(b.object))
            triangles -= std::min(triangles, st->mesh.triangleCount());
        retire(pieces[i].second, stats);
    }
    const int excess = livePieces_ - config_.maxLivePieces;
    if (excess <= 0)
        return;
    for (int n = 0; n < excess && i < pieces.size(); ++n, ++i)
        retire(pieces[i].second, stats);
    // static pieces count too; when they alone exceed the cap, retire the smallest of them
    if (livePieces_ > config_.maxLivePieces) {
        std::vector<std::pair<double, std::uint64_t>> rest;
        for (const auto& [h, b] : bodies_)
            if (b->kind == BodyKind::Piece)
                rest.push_back({b->volume, h});
        std::sort(rest.begin(), rest.end());
        for (std::size_t j = 0; livePieces_ > config_.maxLivePieces && j < rest.size(); ++j)
            retire(rest[j].second, stats);
    }
}

void DestructionBridge::advanceParticlesAndProjectiles(double dt) {
    const Vec3 g = physics_.config().gravity;
    for (DebrisParticle& p : particles_) {
        p.velocity += g * dt;
        p.position += p.velocity * dt;
        p.lifetime -= dt;
    }
    std::erase_if(particles_, [](const DebrisParticle& p) { return p.lifetime <= 0; });
    std::vector<std::uint64_t> expired;
    for (auto& [h, b] : bodies_) {
        b->age += dt;
        if (b->kind != BodyKind::Projectile)
            continue;
        if (b->spent)
            b->spentAge += dt;
        if (b->age > config_.projectileLifetime || b->spentAge > config_.spentProjectileLifetime ||
            b->rigid->getCenterOfMassPosition().y() < config_.killBelowY)
            expired.push_back(h);
    }
    for (std::uint64_t h : expired)
        destroy(h, false);
}

FrameStats DestructionBridge::stepFrame(double dt) {
    FrameStats stats;
    const auto t0 = Clock::now();
    stats.substeps = physics_.step(dt);
    stats.physicsMs = msSince(t0);
    const auto t1 = Clock::now();
    ++counters_.frames;
    supportSearchesLeft_ = config_.maxSupportSearches;
    submitImpacts(stats);
    destruction_.beginFrame();
    const auto t2 = Clock::now();
    if (config_.collapseUnsupported)
        classifyStaticObjects(stats);
    stats.supportMs += msSince(t2);
    adoptResults(stats);
    advanceParticlesAndProjectiles(dt);
    stats.adoptMs = msSince(t1);
    return stats;
}

void DestructionBridge::adoptResults(FrameStats& stats) {
    for (const FractureOutcome& o : destruction_.collect())
        adopt(o, stats);
    retireExcess(stats);
    const auto t0 = Clock::now();
    if (config_.collapseUnsupported)
        settleSupport(stats); // what retirement left unsupported, and what earlier frames left queued
    else
        supportQueue_.clear();
    stats.supportMs += msSince(t0);
}

FrameStats DestructionBridge::adoptReady() {
    FrameStats stats;
    const auto t0 = Clock::now();
    if (!destruction_.waitForResult(t0)) // nothing ready, or deterministic: adoption is frame-bound
        return stats;
    adoptResults(stats);
    stats.adoptMs = msSince(t0);
    return stats;
}

std::size_t DestructionBridge::livePieceTriangles() const {
    std::size_t n = 0;
    for (const auto& [h, b] : bodies_)
        if (b->kind == BodyKind::Piece && !b->isStatic && b->hasObject)
            if (const ObjectState* st = destruction_.object(b->object))
                n += st->mesh.triangleCount();
    return n;
}

double DestructionBridge::liveVolume() const {
    double v = 0;
    for (const auto& [h, b] : bodies_)
        if (b->hasObject)
            v += b->volume;
    return v;
}

Vec3 DestructionBridge::objectMomentum() const {
    Vec3 p;
    for (const auto& [h, b] : bodies_)
        if (b->hasObject && !b->isStatic)
            p += fromBt(b->rigid->getLinearVelocity()) * b->mass;
    return p;
}

double DestructionBridge::objectMass() const {
    double m = 0;
    for (const auto& [h, b] : bodies_)
        if (b->hasObject)
            m += b->mass;
    return m;
}

std::uint64_t DestructionBridge::stateHash() const {
    std::uint64_t h = 0xCBF29CE484222325ull;
    for (const auto& [id, handle] : byObject_) {
        const Body& b = *bodies_.at(handle);
        h = mix(h, id);
        if (const ObjectState* st = destruction_.object(id)) {
            h = mix(h, st->version);
            h = mix(h, st->mesh.hash());
        }
        const btTransform& t = b.rigid->getWorldTransform();
        for (int i = 0; i < 3; ++i) {
            h = mix(h, floatBits(t.getOrigin()[i]));
            for (int j = 0; j < 3; ++j)
                h = mix(h, floatBits(t.getBasis()[i][j]));
        }
    }
    h = mix(h, std::bit_cast<std::uint64_t>(retiredVolume_));
    h = mix(h, std::bit_cast<std::uint64_t>(droppedVolume_));
    return h;
}

DebugDraw DestructionBridge::debugDraw(const DebugDrawOptions& options) const {
    DebugDraw out;
    for (const auto& [h, b] : bodies_) {
        const btTransform& t = b->rigid->getWorldTransform();
        const std::uint32_t color = kindColor(b->kind);
        if (options.shapes && b->shape)
            for (const auto& e : b->shape->edges())
                out.lines.push_back({fromBt(t * toBt(e[0])), fromBt(t * toBt(e[1])), color});
        if (options.aabbs) {
            btVector3 lo, hi;
            b->rigid->getAabb(lo, hi);
            const Vec3 l = fromBt(lo), u = fromBt(hi);
            for (int axis = 0; axis < 3; ++axis)
                for (int k = 0; k < 4; ++k) {
                    Vec3 p = l, q;
                    p[(axis + 1) % 3] = (k & 1) ? u[(axis + 1) % 3] : l[(axis + 1) % 3];
                    p[(axis + 2) % 3] = (k & 2) ? u[(axis + 2) % 3] : l[(axis + 2) % 3];
                    q = p;
                    q[axis] = u[axis];
                    out.lines.push_back({p, q, 0xFF80FFFFu});
                }
        }
    }
    if (options.impacts)
        for (const ImpactMark& m : marks_) {
            const double s = options.impactCrossSize;
            for (int axis = 0; axis < 3; ++axis) {
                Vec3 d;
                d[axis] = s;
                out.lines.push_back({m.point - d, m.point + d, 0xFF2020FFu});
            }
            out.lines.push_back({m.point, m.point + m.normal * (2 * s), 0xFFFF20FFu});
        }
    return out;
}

} // namespace rubble::bullet
