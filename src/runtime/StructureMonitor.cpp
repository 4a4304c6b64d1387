#include "runtime/StructureMonitor.hpp"

#include <algorithm>
#include <deque>

namespace rubble::detail {

void StructureMonitor::add(BodyId id, const std::vector<ConvexPolytope>& worldParts, const Material& material,
                           bool root, std::uint64_t solid) {
    Node n;
    n.solid = solid;
    n.parts = worldParts;
    n.material = &material;
    n.node = structureNode(worldParts, material.density, root);
    nodes_[id] = std::move(n);
    dirty_ = true;
}

void StructureMonitor::remove(BodyId id) {
    if (nodes_.erase(id) > 0)
        dirty_ = true;
}

void StructureMonitor::addLoad(BodyId id, const Vec3& force, const Vec3& point) {
    pendingLoads_.push_back({id, force, point});
}

void StructureMonitor::damage(const Vec3& point, double impulse) {
    pendingDamage_.push_back({point, impulse});
}

StructureMonitor::Pair StructureMonitor::pairOf(std::size_t bond) const {
    return {order_[solver_.bond(bond).a], order_[solver_.bond(bond).b]};
}

void StructureMonitor::rebuild() {
    // Carry health over by body pair.
    for (std::size_t i = 0; i < solver_.bondCount(); ++i) {
        if (solver_.broken(i))
            broken_.insert(pairOf(i));
        else if (solver_.health(i) < 1)
            health_[pairOf(i)] = solver_.health(i);
    }
    // Forget pairs whose bodies are gone (ids are never reused).
    auto gone = [&](const Pair& p) { return !nodes_.count(p.first) || !nodes_.count(p.second); };
    std::erase_if(health_, [&](const auto& e) { return gone(e.first); });
    std::erase_if(broken_, gone);
    order_.clear();
    std::vector<std::vector<ConvexPolytope>> solids;
    std::vector<StructureNode> nodes;
    for (const auto& [id, n] : nodes_) {
        order_.push_back(id);
        solids.push_back(n.parts);
        nodes.push_back(n.node);
    }
    std::vector<Bond> all = buildBonds(solids, policy_.bonds);
    std::vector<Bond> bonds;
    std::vector<StrengthLimits> limits;
    for (Bond& b : all) {
        if (broken_.count({order_[b.a], order_[b.b]}))
            continue;
        const Node& na = nodes_.at(order_[b.a]);
        const Node& nb = nodes_.at(order_[b.b]);
        limits.push_back(bondLimits(*na.material, *nb.material));
        if (na.solid != nb.solid)
            limits.back().friction = policy_.bearingFriction;
        bonds.push_back(std::move(b));
    }
    // Components that reach no root hold themselves up (anchors).
    std::vector<std::vector<std::uint32_t>> adjacent(nodes.size());
    for (const Bond& b : bonds) {
        adjacent[b.a].push_back(b.b);
        adjacent[b.b].push_back(b.a);
    }
    std::vector<int> component(nodes.size(), -1);
    for (std::uint32_t start = 0; start < nodes.size(); ++start) {
        if (component[start] >= 0)
            continue;
        std::vector<std::uint32_t> members{start};
        component[start] = static_cast<int>(start);
        bool rooted = false;
        for (std::size_t k = 0; k < members.size(); ++k) {
            rooted = rooted || nodes[members[k]].root;
            for (std::uint32_t m : adjacent[members[k]])
                if (component[m] < 0) {
                    component[m] = static_cast<int>(start);
                    members.push_back(m);
                }
        }
        if (!rooted)
            for (std::uint32_t m : members)
                nodes[m].root = true;
    }
    solver_.reset(std::move(nodes), std::move(bonds), std::move(limits));
    for (std::size_t i = 0; i < solver_.bondCount(); ++i)
        if (auto it = health_.find(pairOf(i)); it != health_.end())
            solver_.setHealth(i, it->second);
    dirty_ = false;
}

std::vector<BodyId> StructureMonitor::step(const Vec3& gravity, int& broken) {
    if (dirty_)
        rebuild();
    const auto before = [&] {
        std::size_t n = 0;
        for (std::size_t i = 0; i < solver_.bondCount(); ++i)
            n += solver_.broken(i);
        return n;
    };
    const std::size_t brokenBefore = before();
    for (const auto& [point, impulse] : pendingDamage_)
        solver_.damage(point, policy_.damageRadius, impulse * policy_.damagePerImpulse);
    pendingDamage_.clear();
    for (const Load& l : pendingLoads_) // order_ is ascending
        if (const auto it = std::lower_bound(order_.begin(), order_.end(), l.id);
            it != order_.end() && *it == l.id)
            solver_.addLoad(static_cast<std::uint32_t>(it - order_.begin()), l.force, l.point);
    pendingLoads_.clear();
    solver_.settings() = policy_.stress;
    solver_.settings().gravity = gravity;
    solver_.solve();
    (void)solver_.breakOverstressed();
    broken += static_cast<int>(before() - brokenBefore);
    std::vector<BodyId> out;
    for (std::uint32_t n : solver_.unsupported())
        out.push_back(order_[n]);
    std::sort(out.begin(), out.end());
    return out;
}

std::vector<StructureBond> StructureMonitor::bonds() const {
    std::vector<StructureBond> out;
    for (std::size_t i = 0; i < solver_.bondCount(); ++i) {
        if (solver_.broken(i))
            continue;
        const Bond& b = solver_.bond(i);
        StructureBond v;
        v.a = order_[b.a];
        v.b = order_[b.b];
        v.centroid = b.section.centroid;
        v.normal = b.section.normal;
        v.area = b.section.area;
        v.health = solver_.health(i);
        v.utilisation = solver_.utilisation(i);
        out.push_back(v);
    }
    return out;
}

} // namespace rubble::detail
