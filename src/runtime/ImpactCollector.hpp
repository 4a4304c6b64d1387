#pragma once
// Turns the contacts of a physics step into impacts on objects (ImpactPolicy: thresholds and coalescing).

#include <limits>
#include <map>
#include <set>
#include <vector>

#include "rubble/runtime/DestructionRuntime.hpp"
#include "runtime/BodyTable.hpp"

namespace rubble::detail {

/// An impact waiting to be submitted.
struct PendingImpact {
    BodyId body = 0;     ///< the body hit
    ObjectId object = 0; ///< its object
    Impact impact;       ///< in the object's coordinates
    Vec3 worldPoint;     ///< where (world)
    Vec3 worldNormal;    ///< out of the object (world)
};

/// What the contacts of one frame amount to.
struct ImpactBatch {
    std::vector<PendingImpact> impacts;  ///< projectile hits in contact order, then the strongest collision
                                         ///< impact of each object, by object id
    std::map<BodyId, double> frozenHits; ///< strongest impulse of a contact closing on each frozen body
                                         ///< (projectile hits: infinite)
    int projectileHits = 0;              ///< projectiles that hit anything
    int collisionsOverBudget = 0;        ///< collision impacts dropped over collisionFracturesPerSecond
};

/// Applies the ImpactPolicy to contact reports: a projectile's first hit on a destructible object always
/// counts (impulse ≥ the object's threshold), other contacts only above the policy's impulse and approach
/// speed and outside a new piece's grace period; each object keeps its strongest collision impact per frame.
/// Whether the object takes an impact is DestructionWorld::accepts, the one impact filter: every impact in a
/// batch is accepted when submitted in the same frame.
class ImpactCollector {
public:
    /// Reads the policy at every call.
    explicit ImpactCollector(const ImpactPolicy& policy) : policy_(policy) {}

    /// Adds one step's contacts to the frame's batch (marks projectiles spent). A contact on a frozen body
    /// is a hit only when it closes at wakeSpeed or more: what rests on it pushes every step, and is none.
    /// A contact of a light body (one of `light`, over the awake budget) neither breaks nor wakes anything.
    void gather(const std::vector<ContactReport>& contacts, BodyTable& bodies, const DestructionWorld& world,
                const PhysicsBinding& binding, std::uint64_t frame, double wakeSpeed,
                const std::set<BodyId>& light);
    /// The frame's batch, its collision impacts within the policy's budget for a frame of dt seconds (the
    /// strongest first; unspent budget carries over up to a quarter second's worth); starts a new one.
    ImpactBatch take(double dt);

private:
    const ImpactPolicy& policy_;
    std::vector<PendingImpact> projectileImpacts_;
    std::map<ObjectId, PendingImpact> collisionImpacts_;
    std::map<BodyId, double> frozenHits_;
    int projectileHits_ = 0;
    double collisionBudget_ = std::numeric_limits<double>::infinity(); // fractures the budget allows now
};

} // namespace rubble::detail
