#include "rubble/bullet/BulletBinding.hpp"

#include <algorithm>

#include "rubble/bullet/Convert.hpp"

namespace rubble::bullet {
namespace {

constexpr int kFrozenFilter = 64; // collision filter group of bodies made static by setMass

std::uint32_t roleColor(BodyRole role, BodyMotionState motion) {
    if (motion == BodyMotionState::Frozen)
        return 0x8080C0FFu;
    switch (role) {
    case BodyRole::Ground:
        return 0x808080FFu;
    case BodyRole::Scenery:
        return 0x40A0FFFFu;
    case BodyRole::Object:
        return 0x40FF40FFu;
    case BodyRole::Piece:
        return 0xFFD040FFu;
    case BodyRole::Projectile:
        return 0xFF4040FFu;
    }
    return 0xFFFFFFFFu;
}

} // namespace

BulletBinding::BulletBinding(PhysicsWorld& physics, Config config) : physics_(physics), config_(config) {
    physics_.setPreTickCallback([this](double) { preTick(); });
    physics_.setPostTickCallback([this](double) { postTick(); });
}

BulletBinding::BulletBinding(PhysicsWorld& physics) : BulletBinding(physics, Config{}) {}

BulletBinding::~BulletBinding() {
    physics_.setPreTickCallback({});
    physics_.setPostTickCallback({});
    for (auto& [id, e] : bodies_)
        physics_.world().removeRigidBody(e->rigid.get());
}

BulletBinding::Entry& BulletBinding::entry(BodyId id) const {
    return *bodies_.at(id);
}

void BulletBinding::createBody(BodyId id, const BodyDesc& desc) {
    auto e = std::make_unique<Entry>();
    e->id = id;
    switch (desc.shape.kind) {
    case BodyShape::Kind::Box:
        e->shape = CollisionShape::box(desc.shape.halfExtents);
        break;
    case BodyShape::Kind::Sphere:
        e->shape = CollisionShape::sphere(desc.shape.radius);
        break;
    case BodyShape::Kind::Convex:
        e->shape = CollisionShape::fromParts(desc.shape.parts, desc.shape.points, Frame{},
                                             config_.collisionMargin, config_.maxHullPoints);
        break;
    }
    if (!e->shape) // nothing usable: a small box keeps the body in the world
        e->shape = CollisionShape::box(Vec3{0.1, 0.1, 0.1});
    const bool dynamic = desc.mass > 0;
    btRigidBody::btRigidBodyConstructionInfo info(static_cast<btScalar>(dynamic ? desc.mass : 0.0), nullptr,
                                                  e->shape->shape(),
                                                  dynamic ? toBt(desc.inertia) : btVector3(0, 0, 0));
    info.m_startWorldTransform = toBt(desc.transform);
    info.m_friction = static_cast<btScalar>(desc.friction);
    info.m_restitution = static_cast<btScalar>(desc.restitution);
    e->rigid = std::make_unique<btRigidBody>(info);
    btRigidBody& rb = *e->rigid;
    rb.setUserPointer(e.get());
    rb.setUserIndex(static_cast<int>(id));
    rb.setSleepingThresholds(static_cast<btScalar>(config_.linearSleep),
                             static_cast<btScalar>(config_.angularSleep));
    if (dynamic) {
        rb.setLinearVelocity(toBt(desc.linearVelocity));
        rb.setAngularVelocity(toBt(desc.angularVelocity));
        e->preLinear = rb.getLinearVelocity();
        e->preAngular = rb.getAngularVelocity();
    }
    if (desc.continuous) {
        const double r = desc.shape.kind == BodyShape::Kind::Sphere ? desc.shape.radius : 0.1;
        rb.setCcdMotionThreshold(static_cast<btScalar>(r * 0.5));
        rb.setCcdSweptSphereRadius(static_cast<btScalar>(r * 0.9));
    }
    if (desc.neverSleeps)
        rb.setActivationState(DISABLE_DEACTIVATION);
    physics_.world().addRigidBody(&rb);
    bodies_[id] = std::move(e);
}

void BulletBinding::removeBody(BodyId id) {
    auto it = bodies_.find(id);
    if (it == bodies_.end())
        return;
    physics_.world().removeRigidBody(it->second->rigid.get());
    bodies_.erase(it);
}

void BulletBinding::setMass(BodyId id, double mass, const Vec3& inertia) {
    Entry& e = entry(id);
    btRigidBody& rb = *e.rigid;
    btDiscreteDynamicsWorld& world = physics_.world();
    world.removeRigidBody(&rb); // re-added below, so that it joins the static or dynamic broadphase set
    const bool dynamic = mass > 0;
    rb.setMassProps(static_cast<btScalar>(dynamic ? mass : 0.0),
                    dynamic ? toBt(inertia) : btVector3(0, 0, 0));
    rb.updateInertiaTensor();
    rb.setLinearVelocity(btVector3(0, 0, 0));
    rb.setAngularVelocity(btVector3(0, 0, 0));
    e.preLinear = e.preAngular = btVector3(0, 0, 0);
    if (dynamic) {
        rb.forceActivationState(ACTIVE_TAG);
        rb.setDeactivationTime(0);
        world.addRigidBody(&rb);
        return;
    }
    // Frozen: light bodies land on it as on static ones; static and frozen ones never pair with it.
    world.addRigidBody(&rb, kFrozenFilter,
                       btBroadphaseProxy::AllFilter ^ (btBroadphaseProxy::StaticFilter | kFrozenFilter));
}

void BulletBinding::setVelocity(BodyId id, const Vec3& linear, const Vec3& angular) {
    Entry& e = entry(id);
    e.rigid->setLinearVelocity(toBt(linear));
    e.rigid->setAngularVelocity(toBt(angular));
    e.preLinear = e.rigid->getLinearVelocity();
    e.preAngular = e.rigid->getAngularVelocity();
    e.rigid->activate(true);
}

void BulletBinding::setCollidesWithMoving(BodyId id, bool collides) {
    btRigidBody& rb = *entry(id).rigid;
    if (rb.isStaticOrKinematicObject())
        return;
    btDiscreteDynamicsWorld& world = physics_.world();
    world.removeRigidBody(&rb); // re-added with the new filter; its pairs go with it
    if (collides)
        world.addRigidBody(&rb);
    else
        world.addRigidBody(&rb, btBroadphaseProxy::DebrisFilter,
                           btBroadphaseProxy::StaticFilter | kFrozenFilter);
}

BodyMotion BulletBinding::motion(BodyId id) const {
    const btRigidBody& rb = *entry(id).rigid;
    BodyMotion m;
    m.transform = fromBt(rb.getWorldTransform());
    m.linearVelocity = fromBt(rb.getLinearVelocity());
    m.angularVelocity = fromBt(rb.getAngularVelocity());
    m.sleeping = rb.isStaticObject() || !rb.isActive();
    return m;
}

int BulletBinding::step(double dt, std::vector<ContactReport>& contacts) {
    sink_ = &contacts;
    const int n = physics_.step(dt);
    sink_ = nullptr;
    return n;
}

Vec3 BulletBinding::gravity() const {
    return physics_.config().gravity;
}

btRigidBody* BulletBinding::rigid(BodyId id) const {
    auto it = bodies_.find(id);
    return it == bodies_.end() ? nullptr : it->second->rigid.get();
}

const CollisionShape* BulletBinding::shape(BodyId id) const {
    auto it = bodies_.find(id);
    return it == bodies_.end() ? nullptr : it->second->shape.get();
}

void BulletBinding::preTick() {
    btAlignedObjectArray<btRigidBody*>& moving = physics_.world().getNonStaticRigidBodies();
    for (int i = 0; i < moving.size(); ++i)
        if (auto* e = static_cast<Entry*>(moving[i]->getUserPointer())) {
            e->preLinear = moving[i]->getLinearVelocity();
            e->preAngular = moving[i]->getAngularVelocity();
        }
}

void BulletBinding::postTick() {
    if (!sink_)
        return;
    btCollisionDispatcher& dispatcher = physics_.dispatcher();
    const int manifolds = dispatcher.getNumManifolds();
    for (int i = 0; i < manifolds; ++i) {
        btPersistentManifold* m = dispatcher.getManifoldByIndexInternal(i);
        const int n = m->getNumContacts();
        if (n == 0)
            continue;
        auto* a = static_cast<Entry*>(m->getBody0()->getUserPointer());
        auto* b = static_cast<Entry*>(m->getBody1()->getUserPointer());
        if (!a || !b || (!a->rigid->isActive() && !b->rigid->isActive()))
            continue;
        int best = 0; // the deepest contact, and the total impulse of the pair
        double total = 0;
        for (int c = 0; c < n; ++c) {
            const btManifoldPoint& cp = m->getContactPoint(c);
            total += cp.getAppliedImpulse();
            if (cp.getDistance() < m->getContactPoint(best).getDistance())
                best = c;
        }
        const btManifoldPoint& cp = m->getContactPoint(best);
        auto preVelocity = [](const Entry& e, const btVector3& p) { // before this step
            if (e.rigid->isStaticObject())
                return btVector3(0, 0, 0);
            return e.preLinear + e.preAngular.cross(p - e.rigid->getCenterOfMassPosition());
        };
        ContactReport r;
        r.a = a->id;
        r.b = b->id;
        r.pointOnA = fromBt(cp.getPositionWorldOnA());
        r.pointOnB = fromBt(cp.getPositionWorldOnB());
        r.normalOnB = fromBt(cp.m_normalWorldOnB);
        r.impulse = total;
        const btVector3 p = cp.getPositionWorldOnB();
        r.relativeVelocity = fromBt(preVelocity(*a, p) - preVelocity(*b, p));
        r.distance = cp.getDistance();
        sink_->push_back(r);
    }
}

DebugDraw BulletBinding::debugDraw(const DestructionRuntime& runtime, const DebugDrawOptions& options) const {
    DebugDraw out;
    for (BodyId id : runtime.bodies()) {
        const BodyRecord* rec = runtime.body(id);
        auto it = bodies_.find(id);
        if (!rec || it == bodies_.end())
            continue;
        const Entry& e = *it->second;
        const btTransform& t = e.rigid->getWorldTransform();
        const std::uint32_t color = roleColor(rec->role, rec->motion);
        if (options.shapes && e.shape)
            for (const auto& edge : e.shape->edges())
                out.lines.push_back({fromBt(t * toBt(edge[0])), fromBt(t * toBt(edge[1])), color});
        if (options.aabbs) {
            btVector3 lo, hi;
            e.rigid->getAabb(lo, hi);
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
        for (const ImpactMark& m : runtime.recentImpacts()) {
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
