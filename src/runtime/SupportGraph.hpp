#pragma once
// Which static bodies touch which, and which of them a chain of touching static bodies still links to a root.

#include <deque>
#include <map>
#include <set>
#include <vector>

#include "rubble/geometry/ConvexPolytope.hpp"
#include "rubble/runtime/DestructionRuntime.hpp"

namespace rubble::detail {

/// The support graph: nodes are static structural bodies with their convex parts in world coordinates, edges
/// join bodies that touch within SupportPolicy::tolerance. Roots (ground, scenery, anchors) hold themselves
/// up; every other node stays up only while a path of nodes leads to a root.
class SupportGraph {
public:
    /// What a search found.
    enum class Support { Supported, Unsupported, Unknown };

    /// An empty graph; the policy is read at every call (it may change between frames).
    explicit SupportGraph(const SupportPolicy& policy) : policy_(policy) {}

    /// Adds a node and joins it to every node it touches. `classify`: decide at the next classify() whether
    /// it floats (a static object placed in the air becomes an anchor).
    void add(BodyId id, std::vector<ConvexPolytope> worldParts, bool root, bool classify = false);
    /// Removes a node; its non-root neighbours are queued for a support check.
    void remove(BodyId id);
    /// True when id is a node.
    bool contains(BodyId id) const { return nodes_.count(id) > 0; }
    /// True when id is a root.
    bool isRoot(BodyId id) const;
    /// Makes a node a root (or not).
    void setRoot(BodyId id, bool root);
    /// The nodes a node touches, ascending (empty for unknown ids).
    const std::vector<BodyId>& neighbours(BodyId id) const;
    /// Queues a node for a support check.
    void queue(BodyId id);
    /// Nodes.
    std::size_t size() const { return nodes_.size(); }

    /// Decides for the nodes added with `classify` since the last call whether they float: those whose
    /// component reaches no root become roots (anchors). Returns them, ascending.
    std::vector<BodyId> classify();
    /// Runs queued support checks while `searches` lasts (each check costs one); returns the nodes that lost
    /// their support, in a deterministic order. They stay nodes until the caller removes them.
    std::vector<BodyId> settle(int& searches);

private:
    struct Node {
        std::vector<ConvexPolytope> parts;
        Aabb bounds;
        bool root = false;
        std::vector<BodyId> adjacent;
    };
    Support search(BodyId start, std::vector<BodyId>& component) const;
    bool touching(const Node& a, const Node& b) const;

    const SupportPolicy& policy_;
    std::map<BodyId, Node> nodes_;
    std::deque<BodyId> queue_;
    std::set<BodyId> queued_;
    std::vector<BodyId> unclassified_;
};

} // namespace rubble::detail
