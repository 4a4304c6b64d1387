#include "ToyPhysics.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>

namespace rubble::test {

void ToyPhysics::createBody(BodyId id, const BodyDesc& desc) {
    Body b;
    b.transform = desc.transform;
    b.velocity = desc.linearVelocity;
    b.angular = desc.angularVelocity;
    b.mass = desc.mass;
    b.projectile = desc.continuous;
    b.neverSleeps = desc.neverSleeps;
    const BodyShape& s = desc.shape;
    auto corners = [&](const Vec3& h) {
        for (int i = 0; i < 8; ++i)
            b.points.push_back({i & 1 ? h.x : -h.x, i & 2 ? h.y : -h.y, i & 4 ? h.z : -h.z});
    };
    switch (s.kind) {
    case BodyShape::Kind::Box:
        corners(s.halfExtents);
        break;
    case BodyShape::Kind::Sphere:
        corners(Vec3{s.radius, s.radius, s.radius});
        break;
    case BodyShape::Kind::Convex:
        for (const ConvexPolytope& p : s.parts)
            for (const Vec3& v : p.vertices())
                b.points.push_back(v);
        b.points.insert(b.points.end(), s.points.begin(), s.points.end());
        break;
    }
    bodies_[id] = b;
    ++created_;
}

void ToyPhysics::setMass(BodyId id, double mass, const Vec3&) {
    Body& b = bodies_.at(id);
    b.mass = mass;
    b.velocity = b.angular = Vec3{};
    b.sleeping = false;
    b.slowSteps = 0;
    b.light = false;
}

void ToyPhysics::setCollidesWithMoving(BodyId id, bool collides) {
    Body& b = bodies_.at(id);
    if (config_.filtersPairs && b.mass > 0)
        b.light = !collides;
}

void ToyPhysics::setVelocity(BodyId id, const Vec3& linear, const Vec3& angular) {
    Body& b = bodies_.at(id);
    b.velocity = linear;
    b.angular = angular;
    b.sleeping = false;
    b.slowSteps = 0;
}

BodyMotion ToyPhysics::motion(BodyId id) const {
    const Body& b = bodies_.at(id);
    return {b.transform, b.velocity, b.angular, b.mass <= 0 || b.sleeping};
}

Aabb ToyPhysics::worldBounds(const Body& b) const {
    Aabb out;
    for (const Vec3& p : b.points)
        out.extend(b.transform.apply(p));
    return out;
}

int ToyPhysics::step(double dt, std::vector<ContactReport>& contacts) {
    if (config_.stepDelayMs > 0)
        std::this_thread::sleep_for(std::chrono::duration<double, std::milli>(config_.stepDelayMs));
    pending_ += dt;
    int steps = 0;
    while (pending_ >= config_.step * (1 - 1e-9)) {
        pending_ -= config_.step;
        ++steps;
        const double h = config_.step;
        for (auto& [id, b] : bodies_) {
            if (b.mass <= 0 || b.sleeping || b.spent)
                continue;
            const Vec3 before = b.velocity;
            if (!b.projectile)
                b.velocity += config_.gravity * h;
            const Aabb was = worldBounds(b);
            b.transform.translation += b.velocity * h;
            const Aabb now = worldBounds(b);
            if (b.projectile) { // the first box it enters
                for (auto& [oid, o] : bodies_) {
                    if (oid == id || o.projectile)
                        continue;
                    if (!now.overlaps(worldBounds(o)))
                        continue;
                    ContactReport c;
                    c.a = id;
                    c.b = oid;
                    c.pointOnA = c.pointOnB = now.center();
                    c.normalOnB = normalized(-1.0 * before);
                    c.relativeVelocity = before - o.velocity;
                    c.impulse = b.mass * length(before);
                    contacts.push_back(c);
                    b.velocity = Vec3{};
                    b.spent = true;
                    break;
                }
                continue;
            }
            // the highest static top under the body that it passed through this step
            double floor = -1e300;
            BodyId floorId = 0;
            for (const auto& [oid, o] : bodies_) {
                if (oid == id || o.projectile || (o.mass > 0 && !o.sleeping))
                    continue;
                const Aabb ob = worldBounds(o);
                const bool above =
                    now.lo.x < ob.hi.x && now.hi.x > ob.lo.x && now.lo.z < ob.hi.z && now.hi.z > ob.lo.z;
                if (above && was.lo.y >= ob.hi.y - 1e-6 && now.lo.y < ob.hi.y && ob.hi.y > floor) {
                    floor = ob.hi.y;
                    floorId = oid;
                }
            }
            if (floorId != 0) {
                b.transform.translation.y += floor - now.lo.y;
                ContactReport c;
                c.a = id;
                c.b = floorId;
                c.pointOnA = c.pointOnB = Vec3{now.center().x, floor, now.center().z};
                c.normalOnB = Vec3{0, 1, 0};
                c.relativeVelocity = b.velocity;
                c.impulse = b.mass * std::max(0.0, -b.velocity.y);
                contacts.push_back(c);
                b.velocity = Vec3{};
                b.angular = Vec3{};
            }
            if (b.neverSleeps)
                continue;
            b.slowSteps = length(b.velocity) < config_.sleepSpeed ? b.slowSteps + 1 : 0;
            b.sleeping = b.slowSteps >= config_.sleepSteps;
        }
    }
    return steps;
}

} // namespace rubble::test
