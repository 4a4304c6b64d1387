#pragma once
// The structure's bonds and stresses over the static structural bodies: which bonds break, what falls.

#include <map>
#include <utility>
#include <vector>

#include "rubble/runtime/DestructionRuntime.hpp"
#include "rubble/structure/BondGraph.hpp"
#include "rubble/structure/Material.hpp"
#include "rubble/structure/StressSolver.hpp"

namespace rubble::detail {

/// Static structural bodies as stress-solver nodes. The bond graph follows the set incrementally: an added
/// body bonds to the nodes it touches (BondGraph's grid), a removed one takes only its own bonds, and every
/// other bond keeps its health, broken state and warm-started forces. Every step solves, breaks overstressed
/// bonds and reports the bodies no chain of bonds holds up any more. Nodes added with `classify` whose
/// component reaches no root at the next step hold themselves up (anchors, as SupportGraph's).
class StructureMonitor {
public:
    /// Reads the policy at every call (its bond settings at construction).
    explicit StructureMonitor(const StructurePolicy& policy);

    /// Adds a node (parts in world coordinates); `solid` names the object it was cut from (bonds between
    /// different solids are bearings when the policy says so). `classify`: decide at the next step whether
    /// it floats (an object placed in the air, or a piece of an anchor, becomes an anchor).
    void add(BodyId id, const std::vector<ConvexPolytope>& worldParts, const Material& material, bool root,
             std::uint64_t solid, bool classify = false);
    /// Removes a node; its bonds go with it.
    void remove(BodyId id);
    /// True when id is a node.
    bool contains(BodyId id) const { return nodes_.count(id) > 0; }
    /// True when id is a node that holds itself up by the anchor rule.
    bool anchored(BodyId id) const;
    /// A load on a node for the next step (a contact force, N, at a world point).
    void addLoad(BodyId id, const Vec3& force, const Vec3& point);
    /// Weakens the bonds near a hit.
    void damage(const Vec3& point, double impulse);
    /// Solves under gravity, breaks overstressed bonds (counted in `broken`); returns the bodies that lost
    /// their support, ascending.
    std::vector<BodyId> step(const Vec3& gravity, int& broken);
    /// Bonds with their stress, a < b, ordered by (a, b).
    std::vector<StructureBond> bonds() const;
    /// Nodes.
    std::size_t size() const { return nodes_.size(); }
    /// The bonds the last step broke, in the order they broke (frame 0).
    const std::vector<StructureBreak>& breaks() const { return breaks_; }
    /// The relative residual of the last step's final solve.
    double residual() const { return residual_; }

    /// A node as a snapshot keeps it.
    struct SavedNode {
        std::uint64_t solid = 0;
        const Material* material = nullptr;
        bool root = false, anchor = false, pending = false;
    };
    /// The state of node id (a node).
    SavedNode saved(BodyId id) const;
    /// A bond's state: its bodies (a < b), health and broken state.
    struct SavedBond {
        BodyId a = 0, b = 0;
        double health = 1;
        bool broken = false;
    };
    /// Every bond, broken ones included.
    std::vector<SavedBond> savedBonds() const;
    /// Marks a root node as held by the anchor rule (a restored anchor).
    void markAnchor(BodyId id);
    /// Gives the bond between a and b this health and broken state; false when they share no bond.
    bool restoreBond(BodyId a, BodyId b, double health, bool broken);
    /// The next step solves without a warm start (as after objects are placed): ten times the sweeps.
    void settleNext() { settle_ = true; }

private:
    struct Node {
        const Material* material = nullptr;
        std::uint64_t solid = 0;
        std::uint32_t slot = 0; // solver node and bond-graph solid
        bool anchor = false;
    };
    void classify();

    const StructurePolicy& policy_;
    std::map<BodyId, Node> nodes_;
    std::vector<BodyId> bodyOf_; // solver slot -> body (0: free)
    std::vector<BodyId> unclassified_;
    double residual_ = 0;
    std::vector<StructureBreak> breaks_;
    bool settle_ = false;
    std::vector<std::pair<Vec3, double>> pendingDamage_;
    struct Load {
        BodyId id;
        Vec3 force, point;
    };
    std::vector<Load> pendingLoads_;
    BondGraph graph_;
    StressSolver solver_;
};

} // namespace rubble::detail
