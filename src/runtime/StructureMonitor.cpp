#include "runtime/StructureMonitor.hpp"

#include <algorithm>
#include <set>

namespace rubble::detail {

StructureMonitor::StructureMonitor(const StructurePolicy& policy) : policy_(policy), graph_(policy.bonds) {}

void StructureMonitor::add(BodyId id, const std::vector<ConvexPolytope>& worldParts, const Material& material,
                           bool root, std::uint64_t solid, bool classify) {
    remove(id);
    Node n;
    n.solid = solid;
    n.material = &material;
    n.slot = solver_.addNode(structureNode(worldParts, material.density, root));
    if (bodyOf_.size() <= n.slot)
        bodyOf_.resize(n.slot + 1, 0);
    bodyOf_[n.slot] = id;
    nodes_[id] = n;
    for (Bond& b : graph_.add(n.slot, worldParts)) {
        const Node& na = nodes_.at(bodyOf_[b.a]);
        const Node& nb = nodes_.at(bodyOf_[b.b]);
        StrengthLimits limits = bondLimits(*na.material, *nb.material);
        if (na.solid != nb.solid)
            limits.friction = policy_.bearingFriction;
        (void)solver_.addBond(std::move(b), limits);
    }
    if (classify && !root)
        unclassified_.push_back(id);
}

void StructureMonitor::remove(BodyId id) {
    const auto it = nodes_.find(id);
    if (it == nodes_.end())
        return;
    (void)graph_.remove(it->second.slot);
    solver_.removeNode(it->second.slot);
    bodyOf_[it->second.slot] = 0;
    nodes_.erase(it);
}

bool StructureMonitor::anchored(BodyId id) const {
    const auto it = nodes_.find(id);
    return it != nodes_.end() && it->second.anchor;
}

void StructureMonitor::addLoad(BodyId id, const Vec3& force, const Vec3& point) {
    pendingLoads_.push_back({id, force, point});
}

void StructureMonitor::damage(const Vec3& point, double impulse) {
    pendingDamage_.push_back({point, impulse});
}

void StructureMonitor::classify() {
    // As SupportGraph::classify: the fresh members of a component that reaches no root become roots.
    std::vector<BodyId> pending;
    pending.swap(unclassified_);
    const std::set<BodyId> fresh(pending.begin(), pending.end());
    std::set<BodyId> decided;
    for (BodyId id : pending) {
        const auto it = nodes_.find(id);
        if (it == nodes_.end() || decided.count(id) || solver_.root(it->second.slot))
            continue;
        std::vector<std::uint32_t> component{it->second.slot};
        std::set<std::uint32_t> seen{it->second.slot};
        bool rooted = false;
        for (std::size_t k = 0; k < component.size() && !rooted; ++k)
            for (std::size_t i : solver_.bondsOf(component[k])) {
                if (solver_.broken(i))
                    continue;
                const Bond& b = solver_.bond(i);
                const std::uint32_t m = b.other(component[k]);
                rooted = rooted || solver_.root(m);
                if (seen.insert(m).second)
                    component.push_back(m);
            }
        for (std::uint32_t slot : component) {
            const BodyId m = bodyOf_[slot];
            if (!fresh.count(m) || !decided.insert(m).second || rooted)
                continue;
            solver_.setRoot(slot, true);
            nodes_.at(m).anchor = true;
        }
    }
}

std::vector<BodyId> StructureMonitor::step(const Vec3& gravity, int& broken) {
    // Objects just placed have no warm start: their first solve may sweep ten times as often.
    const bool settle = !unclassified_.empty() || settle_;
    settle_ = false;
    if (!unclassified_.empty())
        classify();
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
    for (const Load& l : pendingLoads_)
        if (const auto it = nodes_.find(l.id); it != nodes_.end())
            solver_.addLoad(it->second.slot, l.force, l.point);
    pendingLoads_.clear();
    solver_.settings() = policy_.stress;
    solver_.settings().gravity = gravity;
    const bool budget = policy_.stress.method == StressMethod::SweepBudget;
    if (settle && budget)
        solver_.settings().iterations *= 10;
    solver_.solve();
    // A converged solve finds the new load path of what broke in the same frame (a few rounds at most).
    for (int round = 0; round < policy_.breakRounds; ++round) {
        if (solver_.breakOverstressed().empty() || budget)
            break;
        solver_.solve();
    }
    residual_ = solver_.residual();
    broken += static_cast<int>(before() - brokenBefore);
    breaks_.clear();
    for (const BondBreak& k : solver_.takeBreaks()) {
        const Bond& b = solver_.bond(k.bond);
        StructureBreak e;
        e.a = bodyOf_[b.a];
        e.b = bodyOf_[b.b];
        e.position = b.section.centroid;
        e.normal = b.section.normal;
        e.area = b.section.area;
        e.force = k.force;
        e.utilisation = k.utilisation;
        e.damaged = k.damaged;
        if (e.a > e.b) {
            std::swap(e.a, e.b);
            e.normal = -e.normal;
            e.force = -e.force;
        }
        for (const auto& [id, name] : {std::pair{e.a, &e.materialA}, std::pair{e.b, &e.materialB}})
            if (const auto it = nodes_.find(id); it != nodes_.end())
                *name = it->second.material->name;
        breaks_.push_back(std::move(e));
    }
    std::vector<BodyId> out;
    for (std::uint32_t n : solver_.unsupported())
        out.push_back(bodyOf_[n]);
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
        v.a = bodyOf_[b.a];
        v.b = bodyOf_[b.b];
        v.centroid = b.section.centroid;
        v.normal = b.section.normal;
        if (v.a > v.b) {
            std::swap(v.a, v.b);
            v.normal = -v.normal;
        }
        v.area = b.section.area;
        v.health = solver_.health(i);
        v.utilisation = solver_.utilisation(i);
        out.push_back(v);
    }
    std::sort(out.begin(), out.end(), [](const StructureBond& x, const StructureBond& y) {
        return x.a < y.a || (x.a == y.a && x.b < y.b);
    });
    return out;
}

StructureMonitor::SavedNode StructureMonitor::saved(BodyId id) const {
    const Node& n = nodes_.at(id);
    SavedNode out;
    out.solid = n.solid;
    out.material = n.material;
    out.root = solver_.root(n.slot);
    out.anchor = n.anchor;
    out.pending = std::find(unclassified_.begin(), unclassified_.end(), id) != unclassified_.end();
    return out;
}

std::vector<StructureMonitor::SavedBond> StructureMonitor::savedBonds() const {
    std::vector<SavedBond> out;
    for (const auto& [id, n] : nodes_)
        for (std::size_t i : solver_.bondsOf(n.slot)) {
            const Bond& b = solver_.bond(i);
            const BodyId other = bodyOf_[b.other(n.slot)];
            if (id < other)
                out.push_back({id, other, solver_.health(i), solver_.broken(i)});
        }
    return out;
}

void StructureMonitor::markAnchor(BodyId id) {
    nodes_.at(id).anchor = true;
}

bool StructureMonitor::restoreBond(BodyId a, BodyId b, double health, bool broken) {
    const auto ia = nodes_.find(a), ib = nodes_.find(b);
    if (ia == nodes_.end() || ib == nodes_.end())
        return false;
    const std::uint32_t sa = ia->second.slot, sb = ib->second.slot;
    for (std::size_t i : solver_.bondsOf(sa)) {
        const Bond& bond = solver_.bond(i);
        if (bond.other(sa) != sb)
            continue;
        solver_.setHealth(i, health);
        if (broken)
            solver_.breakBond(i);
        return true;
    }
    return false;
}

} // namespace rubble::detail
