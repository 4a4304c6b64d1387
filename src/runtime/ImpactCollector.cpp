#include "runtime/ImpactCollector.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace rubble::detail {
namespace {

bool breakable(const BodyRecord& b) {
    return b.hasObject && (b.role == BodyRole::Object || b.role == BodyRole::Piece);
}

// world ← object coordinates of a body
Frame objectFrame(const BodyRecord& b, const PhysicsBinding& binding) {
    return binding.motion(b.id).transform * b.objectToBody.inverse();
}

PendingImpact makeImpact(const BodyRecord& target, const Vec3& worldPoint, const Vec3& worldNormal,
                         double impulse, const PhysicsBinding& binding) {
    const Frame f = objectFrame(target, binding);
    PendingImpact p;
    p.body = target.id;
    p.object = target.object;
    p.impact.point = f.applyInverse(worldPoint);
    p.impact.normal = f.rotation.transposed() * worldNormal;
    p.impact.impulse = impulse;
    p.worldPoint = worldPoint;
    p.worldNormal = worldNormal;
    return p;
}

} // namespace

void ImpactCollector::gather(const std::vector<ContactReport>& contacts, BodyTable& bodies,
                             const DestructionWorld& world, const PhysicsBinding& binding,
                             std::uint64_t frame, double wakeSpeed, const std::set<BodyId>& light) {
    for (const ContactReport& c : contacts) {
        BodyRecord* a = bodies.find(c.a);
        BodyRecord* b = bodies.find(c.b);
        if (!a || !b || c.distance > policy_.maxContactDistance)
            continue;
        const bool aProj = a->role == BodyRole::Projectile, bProj = b->role == BodyRole::Projectile;
        if (aProj || bProj) {
            if (aProj && bProj)
                continue;
            BodyRecord& proj = aProj ? *a : *b;
            BodyRecord& other = aProj ? *b : *a;
            if (proj.spent)
                continue;
            proj.spent = true;
            ++projectileHits_;
            if (other.motion == BodyMotionState::Frozen)
                frozenHits_[other.id] = std::numeric_limits<double>::infinity();
            if (!breakable(other))
                continue;
            const ObjectState* st = world.object(other.object);
            if (!st || other.volume < policy_.minFractureVolume)
                continue;
            const double speed = length(c.relativeVelocity);
            const double impulse = std::max({proj.mass * speed, c.impulse, st->impulseThreshold});
            const Vec3 point = aProj ? c.pointOnB : c.pointOnA;
            const Vec3 normal = aProj ? c.normalOnB : -c.normalOnB; // out of the object hit
            PendingImpact p = makeImpact(other, point, normal, impulse, binding);
            if (world.accepts(p.object, p.impact))
                projectileImpacts_.push_back(std::move(p));
            continue;
        }
        if (light.count(a->id) || light.count(b->id)) // over the awake budget: it only lands
            continue;
        const double approach = -dot(c.relativeVelocity, c.normalOnB);
        for (BodyRecord* frozen : {a, b})
            if (frozen->motion == BodyMotionState::Frozen && approach >= wakeSpeed) {
                double& best = frozenHits_[frozen->id];
                best = std::max(best, c.impulse);
            }
        if (approach < policy_.minApproachSpeed || c.impulse < policy_.collisionImpulseThreshold)
            continue;
        for (BodyRecord* target : {a, b}) {
            if (!breakable(*target))
                continue;
            if (target->role == BodyRole::Piece &&
                frame < target->bornFrame + static_cast<std::uint64_t>(std::max(0, policy_.graceFrames)))
                continue;
            if (target->volume < policy_.minFractureVolume)
                continue;
            auto it = collisionImpacts_.find(target->object);
            if (it != collisionImpacts_.end() && it->second.impact.impulse >= c.impulse)
                continue;
            const bool isA = target == a;
            PendingImpact p = makeImpact(*target, isA ? c.pointOnA : c.pointOnB,
                                         isA ? -c.normalOnB : c.normalOnB, c.impulse, binding);
            if (world.accepts(p.object, p.impact))
                collisionImpacts_[target->object] = std::move(p);
        }
    }
}

ImpactBatch ImpactCollector::take(double dt) {
    ImpactBatch out;
    out.impacts = std::move(projectileImpacts_);
    std::vector<const PendingImpact*> collisions;
    for (const auto& [id, p] : collisionImpacts_)
        collisions.push_back(&p);
    if (const double rate = policy_.collisionFracturesPerSecond; rate > 0) {
        collisionBudget_ = std::min(collisionBudget_ + rate * dt, std::max(1.0, 0.25 * rate));
        const auto allowed = static_cast<std::size_t>(std::max(0.0, std::floor(collisionBudget_)));
        if (collisions.size() > allowed) {
            std::stable_sort(collisions.begin(), collisions.end(),
                             [](const PendingImpact* a, const PendingImpact* b) {
                                 return a->impact.impulse > b->impact.impulse;
                             });
            out.collisionsOverBudget = static_cast<int>(collisions.size() - allowed);
            collisions.resize(allowed);
            std::sort(collisions.begin(), collisions.end(),
                      [](const PendingImpact* a, const PendingImpact* b) { return a->object < b->object; });
        }
        collisionBudget_ -= static_cast<double>(collisions.size());
    }
    for (const PendingImpact* p : collisions)
        out.impacts.push_back(*p);
    out.frozenHits = std::move(frozenHits_);
    out.projectileHits = projectileHits_;
    projectileImpacts_.clear();
    collisionImpacts_.clear();
    frozenHits_.clear();
    projectileHits_ = 0;
    return out;
}

} // namespace rubble::detail
