#pragma once
/// \file PhysicsBinding.hpp
/// The small interface between Rubble's runtime and a physics engine: bodies made of convex hulls, their
/// motion and sleep state, and the contacts of a step. Bullet is one binding (rubble_bullet); any engine that
/// implements these few functions gets support, collapse, adoption and the debris governor for free.

#include <cstdint>
#include <vector>

#include "rubble/core/Export.hpp"
#include "rubble/core/Frame.hpp"
#include "rubble/core/Vec3.hpp"
#include "rubble/geometry/ConvexPolytope.hpp"

namespace rubble {

/// Identifies a body of a DestructionRuntime (chosen by the runtime, never reused).
using BodyId = std::uint32_t;

/// The collision shape of a body, in body coordinates (origin at the centre of mass, principal axes).
struct RUBBLE_API BodyShape {
    /// How the shape is given.
    enum class Kind : std::uint8_t {
        Convex, ///< a compound of convex parts (or, without parts, the convex hull of points)
        Box,    ///< a box of halfExtents
        Sphere, ///< a sphere of radius
    };
    Kind kind = Kind::Convex;          ///< which of the fields below describe it
    std::vector<ConvexPolytope> parts; ///< Convex: the parts
    std::vector<Vec3> points;          ///< Convex without parts: one hull around these points
    Vec3 halfExtents{0.5, 0.5, 0.5};   ///< Box: half extents
    double radius = 0.5;               ///< Sphere: radius
};

/// Everything an engine needs to create a rigid body.
struct RUBBLE_API BodyDesc {
    BodyShape shape;          ///< collision shape in body coordinates
    Frame transform;          ///< world ← body
    double mass = 0;          ///< kg; 0 = static (never moves)
    Vec3 inertia;             ///< principal moments of inertia (kg·m²) about the body axes
    Vec3 linearVelocity;      ///< m/s (world)
    Vec3 angularVelocity;     ///< rad/s (world)
    double friction = 0.7;    ///< friction coefficient
    double restitution = 0.1; ///< restitution coefficient
    bool continuous = false;  ///< fast and small: needs continuous collision detection (projectiles)
    bool neverSleeps = false; ///< keep it awake (a player's vehicle, a projectile)
};

/// Where a body is and how it moves.
struct RUBBLE_API BodyMotion {
    Frame transform;       ///< world ← body
    Vec3 linearVelocity;   ///< m/s (world)
    Vec3 angularVelocity;  ///< rad/s (world)
    bool sleeping = false; ///< the engine has put it to sleep (at rest); always true for static bodies
};

/// The contact of two bodies during one step, summed over the pair's contact points.
struct RUBBLE_API ContactReport {
    BodyId a = 0;          ///< first body
    BodyId b = 0;          ///< second body
    Vec3 pointOnA;         ///< deepest contact point on a (world)
    Vec3 pointOnB;         ///< deepest contact point on b (world)
    Vec3 normalOnB;        ///< contact normal on b, pointing from b towards a (world, unit)
    double impulse = 0;    ///< total impulse the solver applied to the pair in this step (N·s)
    Vec3 relativeVelocity; ///< velocity of a minus velocity of b at the point, before the step (m/s)
    double distance = 0;   ///< separation at the deepest point (negative: penetration)
};

/// A physics engine as the runtime sees it. All calls come from the runtime's (main) thread.
class RUBBLE_API PhysicsBinding {
public:
    virtual ~PhysicsBinding() = default;
    /// Creates a body with the given id.
    virtual void createBody(BodyId id, const BodyDesc& desc) = 0;
    /// Removes a body.
    virtual void removeBody(BodyId id) = 0;
    /// Makes a body static (mass 0) or dynamic with the given mass and principal inertia, at rest, awake.
    virtual void setMass(BodyId id, double mass, const Vec3& inertia) = 0;
    /// Sets a dynamic body's velocities and wakes it.
    virtual void setVelocity(BodyId id, const Vec3& linear, const Vec3& angular) = 0;
    /// The body's transform, velocities and sleep state.
    virtual BodyMotion motion(BodyId id) const = 0;
    /// Advances the simulation by dt; appends the contacts of every internal step to contacts. Returns the
    /// number of internal steps.
    virtual int step(double dt, std::vector<ContactReport>& contacts) = 0;
    /// Gravity (m/s²), for particles.
    virtual Vec3 gravity() const = 0;
    /// Whether setCollidesWithMoving takes effect (an engine that cannot filter pairs leaves it a no-op).
    virtual bool filtersMovingPairs() const { return false; }
    /// A dynamic body collides with static bodies only (false) or with every body (true, as created);
    /// setMass resets it to true.
    virtual void setCollidesWithMoving(BodyId /*id*/, bool /*collides*/) {}
};

} // namespace rubble
