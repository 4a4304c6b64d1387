#include "runtime/SupportGraph.hpp"

#include <algorithm>

namespace rubble::detail {
namespace {

const std::vector<BodyId> kNone;

bool boundsWithin(const Aabb& a, const Aabb& b, double gap) {
    for (int k = 0; k < 3; ++k)
        if (a.lo[k] - b.hi[k] > gap || b.lo[k] - a.hi[k] > gap)
            return false;
    return true;
}

} // namespace

bool SupportGraph::touching(const Node& a, const Node& b) const {
    const double gap = policy_.tolerance;
    if (!boundsWithin(a.bounds, b.bounds, gap))
        return false;
    for (const ConvexPolytope& pa : a.parts) {
        const Aabb ba = pa.bounds();
        if (!boundsWithin(ba, b.bounds, gap))
            continue;
        for (const ConvexPolytope& pb : b.parts)
            if (withinGap(pa, pb, gap))
                return true;
    }
    return false;
}

void SupportGraph::add(BodyId id, std::vector<ConvexPolytope> worldParts, bool root, bool classify) {
    Node node;
    node.parts = std::move(worldParts);
    for (const ConvexPolytope& p : node.parts)
        node.bounds.extend(p.bounds());
    node.root = root;
    for (auto& [other, n] : nodes_)
        if (touching(node, n)) {
            node.adjacent.push_back(other); // ascending: nodes_ is ordered
            n.adjacent.insert(std::upper_bound(n.adjacent.begin(), n.adjacent.end(), id), id);
        }
    nodes_[id] = std::move(node);
    if (classify)
        unclassified_.push_back(id);
}

void SupportGraph::remove(BodyId id) {
    auto it = nodes_.find(id);
    if (it == nodes_.end())
        return;
    for (BodyId other : it->second.adjacent) {
        Node& n = nodes_.at(other);
        std::erase(n.adjacent, id);
        if (!n.root)
            queue(other);
    }
    nodes_.erase(it);
}

bool SupportGraph::isRoot(BodyId id) const {
    auto it = nodes_.find(id);
    return it != nodes_.end() && it->second.root;
}

void SupportGraph::setRoot(BodyId id, bool root) {
    if (auto it = nodes_.find(id); it != nodes_.end())
        it->second.root = root;
}

const std::vector<BodyId>& SupportGraph::neighbours(BodyId id) const {
    auto it = nodes_.find(id);
    return it == nodes_.end() ? kNone : it->second.adjacent;
}

void SupportGraph::queue(BodyId id) {
    if (queued_.insert(id).second)
        queue_.push_back(id);
}

SupportGraph::Support SupportGraph::search(BodyId start, std::vector<BodyId>& component) const {
    // breadth first over non-root nodes until a root turns up
    component.assign(1, start);
    std::set<BodyId> seen{start};
    for (std::size_t next = 0; next < component.size(); ++next) {
        if (static_cast<int>(next) >= policy_.maxVisits)
            return Support::Unknown;
        for (BodyId h : nodes_.at(component[next]).adjacent) {
            if (nodes_.at(h).root)
                return Support::Supported;
            if (seen.insert(h).second)
                component.push_back(h);
        }
    }
    return Support::Unsupported;
}

std::vector<BodyId> SupportGraph::classify() {
    std::vector<BodyId> anchors;
    std::vector<BodyId> pending;
    pending.swap(unclassified_);
    const std::set<BodyId> fresh(pending.begin(), pending.end());
    std::set<BodyId> decided;
    std::vector<BodyId> component;
    for (BodyId id : pending) {
        if (!nodes_.count(id) || decided.count(id) || nodes_.at(id).root)
            continue;
        const Support s = search(id, component);
        for (BodyId m : component) {
            if (!fresh.count(m) || decided.count(m))
                continue;
            decided.insert(m);
            if (s == Support::Unsupported) {
                nodes_.at(m).root = true;
                anchors.push_back(m);
            }
        }
    }
    std::sort(anchors.begin(), anchors.end());
    return anchors;
}

std::vector<BodyId> SupportGraph::settle(int& searches) {
    std::vector<BodyId> fallen;
    std::set<BodyId> fell;
    std::vector<BodyId> component;
    while (!queue_.empty() && searches > 0) {
        const BodyId id = queue_.front();
        queue_.pop_front();
        queued_.erase(id);
        auto it = nodes_.find(id);
        if (it == nodes_.end() || it->second.root)
            continue;
        if (fell.count(id))
            continue;
        --searches;
        if (search(id, component) != Support::Unsupported)
            continue;
        std::sort(component.begin(), component.end());
        fallen.insert(fallen.end(), component.begin(), component.end());
        fell.insert(component.begin(), component.end());
    }
    return fallen;
}

} // namespace rubble::detail
