#pragma once
// A second PhysicsBinding for tests: a toy engine in a few dozen lines (gravity, a ground plane, projectiles
// that hit bounding boxes, sleeping), so that the runtime's support, collapse, freezing and retirement run
// without Bullet.

#include <map>
#include <vector>

#include "rubble/runtime/PhysicsBinding.hpp"

namespace rubble::test {

/// Bodies are their world bounding boxes: dynamic ones fall under gravity onto the highest static box top
/// below them (contact reported with impulse m·v), projectiles fly straight and stop at the first box they
/// enter, a dynamic body that moves slower than sleepSpeed for sleepSteps steps sleeps.
class ToyPhysics final : public PhysicsBinding {
public:
    /// Tunables.
    struct Config {
        Vec3 gravity{0, -9.81, 0}; ///< m/s²
        double step = 1.0 / 60;    ///< fixed step (s)
        double sleepSpeed = 0.05;  ///< m/s
        int sleepSteps = 20;       ///< steps below sleepSpeed before sleeping
        double stepDelayMs = 0;    ///< wall time each step() call takes (a slow engine)
        bool filtersPairs = false; ///< setCollidesWithMoving is honoured (bodies only land on static ones)
    };

    /// A toy world with the given tunables.
    explicit ToyPhysics(Config config) : config_(config) {}
    /// A toy world with the default tunables.
    ToyPhysics() : ToyPhysics(Config{}) {}

    void createBody(BodyId id, const BodyDesc& desc) override;
    void removeBody(BodyId id) override { bodies_.erase(id); }
    void setMass(BodyId id, double mass, const Vec3& inertia) override;
    void setVelocity(BodyId id, const Vec3& linear, const Vec3& angular) override;
    BodyMotion motion(BodyId id) const override;
    int step(double dt, std::vector<ContactReport>& contacts) override;
    Vec3 gravity() const override { return config_.gravity; }
    bool filtersMovingPairs() const override { return config_.filtersPairs; }
    void setCollidesWithMoving(BodyId id, bool collides) override;

    /// Whether a body collides with moving bodies (false after setCollidesWithMoving(id, false)).
    bool collidesWithMoving(BodyId id) const { return !bodies_.at(id).light; }

    /// Bodies in the world.
    std::size_t size() const { return bodies_.size(); }
    /// Calls to createBody so far.
    int created() const { return created_; }

private:
    struct Body {
        Frame transform;
        Vec3 velocity;
        Vec3 angular;
        double mass = 0;
        std::vector<Vec3> points; // hull points in body coordinates
        bool projectile = false;
        bool spent = false; // a projectile that hit something: it stays where it hit
        bool sleeping = false;
        bool neverSleeps = false;
        bool light = false; // collides with static bodies only
        int slowSteps = 0;
    };
    Aabb worldBounds(const Body& b) const;

    Config config_;
    std::map<BodyId, Body> bodies_;
    double pending_ = 0;
    int created_ = 0;
};

} // namespace rubble::test
