#pragma once
/// \file Body.hpp
/// One rigid body managed by the DestructionBridge, with what Rubble knows about it.

#include <cstdint>
#include <memory>

#include <btBulletDynamicsCommon.h>

#include "rubble/DestructionWorld.hpp"
#include "rubble/bullet/CollisionShape.hpp"

namespace rubble::bullet {

/// What a body is in the game.
enum class BodyKind {
    Ground,     ///< the static ground box
    Scenery,    ///< an indestructible body that is not a DestructionWorld object (e.g. the vehicle)
    Object,     ///< a destructible object loaded from the scene
    Piece,      ///< a piece produced by a fracture
    Projectile, ///< a fast small sphere that always may fracture what it hits (once)
};

/// A rigid body and its bookkeeping. The btRigidBody's user pointer points back to this record.
struct Body {
    BodyKind kind = BodyKind::Scenery;     ///< role
    bool hasObject = false;                ///< true when `object` names a DestructionWorld object
    ObjectId object = 0;                   ///< the DestructionWorld object (when hasObject)
    std::unique_ptr<CollisionShape> shape; ///< collision shape (owned)
    std::unique_ptr<btRigidBody> rigid;    ///< the Bullet body (owned)
    Frame objectToBody;                    ///< body → object coordinates: p_object = R · p_body + t
    double volume = 0;                     ///< solid volume (m³), for bookkeeping
    double mass = 0;                       ///< mass (0 for static bodies)
    bool isStatic = false;                 ///< does not move
    std::uint64_t bornFrame = 0;           ///< frame the body was created in
    bool spent = false;                    ///< projectile: its one hit has been counted
    double age = 0;                        ///< seconds since creation
    double spentAge = 0;                   ///< projectile: seconds since its hit
    btVector3 preLinearVelocity{0, 0, 0};  ///< velocity before the current internal step
    btVector3 preAngularVelocity{0, 0, 0}; ///< angular velocity before the current internal step
    bool anchor = false; ///< static object or piece that stays up by itself (a scene's floating platform, or
                         ///< the kept piece of one): it supports what touches it, like the ground
    bool supportKnown = false; ///< static object: whether it is an anchor has been decided

    /// World transform of the object's local frame (world ← object coordinates).
    btTransform objectTransform() const;
};

} // namespace rubble::bullet
