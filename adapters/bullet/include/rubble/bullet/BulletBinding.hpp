#pragma once
/// \file BulletBinding.hpp
/// Rubble's PhysicsBinding for Bullet: bodies of convex compounds in a PhysicsWorld, their motion and sleep
/// state, and each step's contacts. Everything else (impacts, adoption, support, debris) is the
/// engine-neutral DestructionRuntime's.

#include <memory>
#include <unordered_map>

#include <btBulletDynamicsCommon.h>

#include "rubble/bullet/CollisionShape.hpp"
#include "rubble/bullet/DebugDraw.hpp"
#include "rubble/bullet/PhysicsWorld.hpp"
#include "rubble/rubble.hpp"

namespace rubble::bullet {

/// Bullet behind Rubble's PhysicsBinding. Destroy it after the DestructionRuntime that uses it.
class BulletBinding final : public PhysicsBinding {
public:
    /// Tunables.
    struct Config {
        double collisionMargin = 0.02; ///< convex hull margin (hulls are eroded by it)
        double linearSleep = 0.8;      ///< sleeping threshold (m/s)
        double angularSleep = 1.0;     ///< sleeping threshold (rad/s)
        int maxHullPoints = 0; ///< > 0: each convex part collides as a hull of at most this many points
                               ///< (CollisionShape::cappedHullPoints)
    };

    /// A binding that creates its bodies in physics.
    BulletBinding(PhysicsWorld& physics, Config config);
    /// A binding with the default tunables.
    explicit BulletBinding(PhysicsWorld& physics);
    /// Removes and frees every body still there.
    ~BulletBinding() override;
    BulletBinding(const BulletBinding&) = delete;
    BulletBinding& operator=(const BulletBinding&) = delete;

    void createBody(BodyId id, const BodyDesc& desc) override;
    void removeBody(BodyId id) override;
    void setMass(BodyId id, double mass, const Vec3& inertia) override;
    void setVelocity(BodyId id, const Vec3& linear, const Vec3& angular) override;
    BodyMotion motion(BodyId id) const override;
    int step(double dt, std::vector<ContactReport>& contacts) override;
    Vec3 gravity() const override;
    bool filtersMovingPairs() const override { return true; }
    void setCollidesWithMoving(BodyId id, bool collides) override;

    /// The Bullet body (for engine-specific settings such as friction or damping), or null.
    btRigidBody* rigid(BodyId id) const;
    /// The collision shape of a body, or null.
    const CollisionShape* shape(BodyId id) const;
    /// The physics world.
    PhysicsWorld& physics() { return physics_; }
    /// Line segments for a debug renderer: collision shapes coloured by role, bounding boxes, recent impacts.
    DebugDraw debugDraw(const DestructionRuntime& runtime, const DebugDrawOptions& options = {}) const;

private:
    struct Entry {
        BodyId id = 0;
        std::unique_ptr<CollisionShape> shape;
        std::unique_ptr<btRigidBody> rigid;
        btVector3 preLinear{0, 0, 0};
        btVector3 preAngular{0, 0, 0};
    };
    Entry& entry(BodyId id) const;
    void preTick();
    void postTick();

    PhysicsWorld& physics_;
    Config config_;
    std::unordered_map<BodyId, std::unique_ptr<Entry>> bodies_;
    std::vector<ContactReport>* sink_ = nullptr;
};

} // namespace rubble::bullet
