#pragma once
// Turns a fracture outcome into piece bodies: where they go, how they move, what stays static
// (AdoptionPolicy).

#include <vector>

#include "rubble/runtime/DestructionRuntime.hpp"

namespace rubble::detail {

/// One piece body to create.
struct PieceSpawn {
    ObjectId object = 0;       ///< the piece's object
    BodyDesc desc;             ///< the body (mass 0 when it stays static)
    Frame objectToBody;        ///< body → object coordinates
    double volume = 0;         ///< solid volume
    double mass = 0;           ///< mass when dynamic
    Vec3 inertia;              ///< principal moments when dynamic
    std::size_t triangles = 0; ///< triangles of its mesh
    bool isStatic = false;     ///< stays static
    bool structural = false;   ///< joins the support graph (and is checked for support)
    bool anchor = false;       ///< holds itself up (the kept piece of a floating parent)
};

/// What adopting one outcome creates.
struct AdoptionPlan {
    std::vector<PieceSpawn> spawns;        ///< in the outcome's piece order
    std::vector<DebrisParticle> particles; ///< the outcome's dust
};

/// The body of an object in its principal frame: mass, principal inertia (floored so that slivers stay
/// stable), the frame, and its collision hulls in body coordinates (one hull when below singleHullVolume).
PieceSpawn describeObjectBody(const ObjectState& state, bool isStatic, double singleHullVolume);

/// The bodies and particles of an outcome whose parent body is `parent`, moving as `parentMotion`.
/// `collapse`: structural support is on (remainder pieces of a static parent stay static and are checked).
/// `bondDebris`: so do its debris pieces (they stay bonded in the structure).
AdoptionPlan planAdoption(const FractureOutcome& outcome, const BodyRecord& parent,
                          const BodyMotion& parentMotion, const AdoptionPolicy& policy, bool collapse,
                          double particleLifetime, bool bondDebris = false);

} // namespace rubble::detail
