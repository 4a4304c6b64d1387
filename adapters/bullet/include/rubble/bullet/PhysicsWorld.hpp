#pragma once
/// \file PhysicsWorld.hpp
/// A btDiscreteDynamicsWorld with its collision configuration, dispatcher, broadphase and solver, stepped
/// with a fixed time step. Knows nothing about destruction (see DestructionBridge).

#include <functional>
#include <memory>

#include <btBulletDynamicsCommon.h>

#include "rubble/core/Vec3.hpp"

namespace rubble::bullet {

/// Owns a Bullet dynamics world stepped in fixed sub-steps.
class PhysicsWorld {
public:
    /// Configuration.
    struct Config {
        Vec3 gravity{0, -9.81, 0};   ///< m/s²
        double fixedStep = 1.0 / 60; ///< Bullet's internal step (s)
        int maxSubSteps = 4;         ///< at most this many internal steps per step() call
        int solverIterations = 10;   ///< sequential-impulse iterations
    };

    /// A world with the given configuration.
    explicit PhysicsWorld(Config config);
    /// A world with the default configuration.
    PhysicsWorld();
    /// Removes every body still in the world (their memory belongs to the callers).
    ~PhysicsWorld();
    PhysicsWorld(const PhysicsWorld&) = delete;
    PhysicsWorld& operator=(const PhysicsWorld&) = delete;

    /// The Bullet world.
    btDiscreteDynamicsWorld& world() { return *world_; }
    /// The Bullet world.
    const btDiscreteDynamicsWorld& world() const { return *world_; }
    /// The collision dispatcher (contact manifolds).
    btCollisionDispatcher& dispatcher() { return *dispatcher_; }
    /// The configuration.
    const Config& config() const { return config_; }

    /// Advances by dt seconds in fixed internal steps (at most Config::maxSubSteps); returns the number of
    /// internal steps taken.
    int step(double dt);
    /// Called before every internal step with its duration.
    void setPreTickCallback(std::function<void(double)> callback) { preTick_ = std::move(callback); }
    /// Called after every internal step with its duration (contact manifolds are fresh here).
    void setPostTickCallback(std::function<void(double)> callback) { postTick_ = std::move(callback); }
    /// Internal steps taken so far.
    long long ticks() const { return ticks_; }

private:
    static void preTickThunk(btDynamicsWorld* world, btScalar dt);
    static void postTickThunk(btDynamicsWorld* world, btScalar dt);

    Config config_;
    std::unique_ptr<btDefaultCollisionConfiguration> collisionConfig_;
    std::unique_ptr<btCollisionDispatcher> dispatcher_;
    std::unique_ptr<btBroadphaseInterface> broadphase_;
    std::unique_ptr<btSequentialImpulseConstraintSolver> solver_;
    std::unique_ptr<btDiscreteDynamicsWorld> world_;
    std::function<void(double)> preTick_;
    std::function<void(double)> postTick_;
    long long ticks_ = 0;
};

} // namespace rubble::bullet
