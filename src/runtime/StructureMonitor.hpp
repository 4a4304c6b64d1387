#pragma once
// The structure's bonds and stresses over the static structural bodies: which bonds break, what falls.

#include <map>
#include <set>
#include <utility>
#include <vector>

#include "rubble/DestructionRuntime.hpp"

namespace rubble::detail {

/// Static structural bodies as stress-solver nodes. The bond graph is rebuilt from their convex parts when
/// the set changes (bond health and broken bonds carry over by body pair); every step solves, breaks
/// overstressed bonds and reports the bodies no chain of bonds holds up any more. Components that no bond
/// links to a root when the graph is built hold themselves up (as SupportGraph's anchors).
class StructureMonitor {
public:
    /// Reads the policy at every call.
    explicit StructureMonitor(const StructurePolicy& policy) : policy_(policy) {}

    /// Adds a node (parts in world coordinates); `solid` names the object it was cut from (bonds between
    /// different solids are bearings when the policy says so).
    void add(BodyId id, const std::vector<ConvexPolytope>& worldParts, const Material& material, bool root,
             std::uint64_t solid);
    /// Removes a node; its bonds go with it.
    void remove(BodyId id);
    /// True when id is a node.
    bool contains(BodyId id) const { return nodes_.count(id) > 0; }
    /// A load on a node for the next step (a contact force, N, at a world point).
    void addLoad(BodyId id, const Vec3& force, const Vec3& point);
    /// Weakens the bonds near a hit.
    void damage(const Vec3& point, double impulse);
    /// Solves under gravity, breaks overstressed bonds (counted in `broken`); returns the bodies that lost
    /// their support, ascending.
    std::vector<BodyId> step(const Vec3& gravity, int& broken);
    /// Bonds with their stress, ordered by (a, b).
    std::vector<StructureBond> bonds() const;
    /// Nodes.
    std::size_t size() const { return nodes_.size(); }

private:
    struct Node {
        std::vector<ConvexPolytope> parts;
        const Material* material = nullptr;
        StructureNode node;
        std::uint64_t solid = 0;
    };
    using Pair = std::pair<BodyId, BodyId>;
    void rebuild();
    Pair pairOf(std::size_t bond) const;

    const StructurePolicy& policy_;
    std::map<BodyId, Node> nodes_;
    std::vector<BodyId> order_; // solver node index -> body
    std::map<Pair, double> health_;
    std::set<Pair> broken_;
    std::vector<std::pair<Vec3, double>> pendingDamage_;
    struct Load {
        BodyId id;
        Vec3 force, point;
    };
    std::vector<Load> pendingLoads_;
    StressSolver solver_;
    bool dirty_ = false;
};

} // namespace rubble::detail
