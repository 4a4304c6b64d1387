#include "rubble/persist/WorldState.hpp"

#include <algorithm>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <utility>

#include "persist/SnapshotInPlace.hpp"
#include "rubble/collision/ConvexDecomposition.hpp"
#include "rubble/structure/Material.hpp"
#include "runtime/StateAccess.hpp"

namespace rubble {

using detail::StateAccess;

namespace {

// The world's state without its objects.
WorldState captureSettingsAndWork(const DestructionWorld& world) {
    const DestructionWorld::Config& c = StateAccess::config(world);
    WorldState w;
    w.seed = c.seed;
    w.delayFrames = c.delayFrames;
    w.crumbleTriangles = c.crumbleTriangles;
    w.crumbleCells = c.crumbleCells;
    w.minPieceVolume = c.minPieceVolume;
    w.decomposition = c.decomposition;
    w.frame = world.frame();
    w.nextId = StateAccess::nextId(world);
    w.journalPosition = world.journalPosition();
    for (const detail::WorldWork& work : StateAccess::work(world)) {
        PendingWork p{work.object, work.version, work.inFlight, work.readyFrame, {}, {}};
        for (const detail::TickedImpact& t : work.impacts) {
            p.impacts.push_back(t.impact);
            p.ticks.push_back(t.tick);
        }
        w.work.push_back(std::move(p));
    }
    return w;
}

} // namespace

WorldState captureState(const DestructionWorld& world) {
    WorldState w = captureSettingsAndWork(world);
    w.objects = StateAccess::objects(world);
    return w;
}

detail::StateInPlace detail::captureInPlace(const DestructionWorld& world) {
    (void)world.geometryHash(); // computes the mesh hashes not computed yet
    StateInPlace s{captureSettingsAndWork(world), {}};
    for (ObjectId id : world.objects())
        s.objects.push_back(world.object(id));
    return s;
}

namespace {

// The world settings a state carries, written into c.
void applySettings(const WorldState& w, DestructionWorld::Config& c) {
    c.seed = w.seed;
    c.delayFrames = w.delayFrames;
    c.crumbleTriangles = static_cast<std::size_t>(w.crumbleTriangles);
    c.crumbleCells = w.crumbleCells;
    c.minPieceVolume = w.minPieceVolume;
    c.decomposition = w.decomposition;
}

} // namespace

Status restoreState(DestructionWorld& world, WorldState w) {
    auto bad = [](const std::string& what) { return Error{ErrorCode::InvalidInput, "world state: " + what}; };
    DestructionWorld::Config settings = StateAccess::config(world);
    applySettings(w, settings);
    if (const Status s = DestructionWorld::checkConfig(settings); !s)
        return bad("settings out of range: " + s.message());
    ObjectId last = 0;
    std::map<ObjectId, std::uint32_t> versions;
    for (const ObjectState& o : w.objects) {
        if (o.id <= last || o.id >= w.nextId)
            return bad("object id " + std::to_string(o.id) + " is not ascending or not below nextId " +
                       std::to_string(w.nextId));
        if (o.mesh.triangles.empty() || o.mesh.positions.empty())
            return bad("object " + std::to_string(o.id) + " has an empty mesh");
        last = o.id;
        versions[o.id] = o.version;
    }
    std::set<ObjectId> busy, waiting;
    for (const PendingWork& p : w.work) {
        auto v = versions.find(p.object);
        const std::string which = "work on object " + std::to_string(p.object);
        if (v == versions.end() || v->second != p.version)
            return bad(which + ": no such object or version");
        if (p.impacts.empty() || p.ticks.size() != p.impacts.size())
            return bad(which + ": no impacts, or not one tick per impact");
        if (!(p.inFlight ? busy : waiting).insert(p.object).second)
            return bad(which + ": listed twice");
        if (!p.inFlight && !busy.count(p.object))
            return bad(which + ": impacts wait for a job that is not in flight");
    }
    // Consistent: replace everything. Jobs of the old state finish on their own; their results are dropped.
    StateAccess::replace(world, std::move(w.objects), w.frame, w.nextId, w.journalPosition);
    StateAccess::config(world) = settings;
    for (const PendingWork& p : w.work) {
        detail::WorldWork work{p.object, p.version, p.inFlight, p.readyFrame, {}};
        for (std::size_t i = 0; i < p.impacts.size(); ++i)
            work.impacts.push_back({p.impacts[i], p.ticks[i]});
        StateAccess::resume(world, work);
    }
    return Status::ok();
}

StructureState captureStructure(const DestructionRuntime& runtime) {
    const detail::BodyTable& bodies = StateAccess::bodies(runtime);
    const detail::StructureMonitor& structure = StateAccess::structure(runtime);
    StructureState out;
    if (!StateAccess::config(runtime).structure.enabled)
        return out;
    out.saved = true;
    for (const auto& [id, r] : bodies.all()) {
        if (!r.hasObject || !structure.contains(id))
            continue;
        const detail::StructureMonitor::SavedNode n = structure.saved(id);
        StructureNodeState v;
        v.object = r.object;
        v.solid = static_cast<ObjectId>(n.solid);
        v.material = static_cast<std::uint8_t>(n.material - materialPresets().data());
        v.root = n.root;
        v.anchor = n.anchor;
        v.pending = n.pending;
        out.nodes.push_back(v);
    }
    std::sort(out.nodes.begin(), out.nodes.end(),
              [](const StructureNodeState& x, const StructureNodeState& y) { return x.object < y.object; });
    auto key = [&](BodyId id) -> std::uint64_t {
        const BodyRecord* r = bodies.find(id);
        return r && r->hasObject ? r->object : kSceneryNodeKey | id;
    };
    for (const detail::StructureMonitor::SavedBond& b : structure.savedBonds()) {
        const std::uint64_t ka = key(b.a), kb = key(b.b);
        out.bonds.push_back({std::min(ka, kb), std::max(ka, kb), b.health, b.broken});
    }
    std::sort(out.bonds.begin(), out.bonds.end(),
              [](const StructureBondState& x, const StructureBondState& y) {
                  return x.a < y.a || (x.a == y.a && x.b < y.b);
              });
    return out;
}

namespace {

// A saved structure names static objects (nodes once each) and, in bonds, nodes or this runtime's ground and
// scenery bodies in the structure; `nodes` gets the records by object.
Status checkStructure(const DestructionRuntime& runtime, const StructureState& saved,
                      const std::map<ObjectId, const ObjectPlacement*>& where,
                      std::map<ObjectId, const StructureNodeState*>& nodes) {
    if (!saved.saved && !(saved.nodes.empty() && saved.bonds.empty()))
        return Error{ErrorCode::InvalidInput, "structure: nodes or bonds but not saved"};
    for (const StructureNodeState& n : saved.nodes) {
        const std::string which = "structure node of object " + std::to_string(n.object);
        const auto it = where.find(n.object);
        if (it == where.end() || it->second->motion != BodyMotionState::Static)
            return Error{ErrorCode::InvalidInput, which + ": no static object"};
        if (n.material >= materialPresets().size())
            return Error{ErrorCode::InvalidInput, which + ": unknown material " + std::to_string(n.material)};
        if ((n.anchor && !n.root) || (n.pending && n.root))
            return Error{ErrorCode::InvalidInput, which + ": an anchor is a root, a pending node is not"};
        if (!nodes.emplace(n.object, &n).second)
            return Error{ErrorCode::InvalidInput, which + ": listed twice"};
    }
    const detail::BodyTable& bodies = StateAccess::bodies(runtime);
    const detail::StructureMonitor& structure = StateAccess::structure(runtime);
    const bool enabled = StateAccess::config(runtime).structure.enabled;
    for (const StructureBondState& b : saved.bonds)
        for (std::uint64_t key : {b.a, b.b}) {
            const std::string which = "structure bond " + std::to_string(b.a) + "-" + std::to_string(b.b);
            if (!(key & kSceneryNodeKey)) {
                if (key > 0xFFFFFFFFull || !nodes.count(static_cast<ObjectId>(key)))
                    return Error{ErrorCode::InvalidInput, which + ": names no structure node"};
                continue;
            }
            const BodyRecord* r = bodies.find(static_cast<BodyId>(key));
            if (enabled &&
                (key >> 32 != kSceneryNodeKey >> 32 || !r || r->hasObject || !structure.contains(r->id)))
                return Error{ErrorCode::InvalidInput, which + ": names no ground or scenery body"};
        }
    return Status::ok();
}

// The bonds rebuilt from geometry take their saved health and broken state; the next solve settles.
void restoreBonds(DestructionRuntime& runtime, const StructureState& saved) {
    if (!StateAccess::config(runtime).structure.enabled)
        return;
    const detail::BodyTable& bodies = StateAccess::bodies(runtime);
    detail::StructureMonitor& structure = StateAccess::structure(runtime);
    auto bodyOfKey = [&](std::uint64_t key) -> BodyId {
        if (key & kSceneryNodeKey)
            return static_cast<BodyId>(key);
        const BodyRecord* r = bodies.findObject(static_cast<ObjectId>(key));
        return r ? r->id : 0;
    };
    for (const StructureBondState& b : saved.bonds)
        (void)structure.restoreBond(bodyOfKey(b.a), bodyOfKey(b.b), b.health, b.broken);
    structure.settleNext();
}

} // namespace

Status restoreState(DestructionRuntime& runtime, WorldState state,
                    const std::vector<ObjectPlacement>& placements, const VolumeLedger& volumes,
                    const StructureState& structure) {
    for (double v : {volumes.retired, volumes.dust, volumes.dropped})
        if (!(v >= 0 && v < 1e300))
            return Error{ErrorCode::InvalidInput,
                         "volume ledger: " + std::to_string(v) + " is negative or not finite"};
    std::map<ObjectId, const ObjectPlacement*> where;
    for (const ObjectPlacement& p : placements) {
        const std::string which = "placement of object " + std::to_string(p.object);
        if (p.role != BodyRole::Object && p.role != BodyRole::Piece)
            return Error{ErrorCode::InvalidInput, which + ": role is neither object nor piece"};
        if (!where.emplace(p.object, &p).second)
            return Error{ErrorCode::InvalidInput, which + ": listed twice"};
    }
    if (where.size() != state.objects.size())
        return Error{ErrorCode::InvalidInput, std::to_string(state.objects.size()) + " objects but " +
                                                  std::to_string(where.size()) + " placements"};
    for (const ObjectState& o : state.objects)
        if (!where.count(o.id))
            return Error{ErrorCode::InvalidInput, "object " + std::to_string(o.id) + " has no placement"};
    std::map<ObjectId, const StructureNodeState*> nodes;
    if (Status s = checkStructure(runtime, structure, where, nodes); !s)
        return s;
    // The old objects' bodies go (the world's objects are replaced below); nothing is journaled.
    std::vector<BodyId> old;
    for (const auto& [id, r] : StateAccess::bodies(runtime).all())
        if (r.hasObject)
            old.push_back(id);
    DestructionWorld& world = StateAccess::world(runtime);
    if (Status s = restoreState(world, std::move(state)); !s)
        return s;
    for (BodyId id : old)
        StateAccess::dropBody(runtime, id);
    StateAccess::continueLedger(runtime, volumes);
    for (ObjectId id : world.objects()) {
        const auto it = nodes.find(id);
        std::optional<detail::StructureMonitor::SavedNode> node;
        if (it != nodes.end()) {
            const StructureNodeState& n = *it->second;
            node = detail::StructureMonitor::SavedNode{n.solid, &materialPresets()[n.material], n.root,
                                                       n.anchor, n.pending};
        }
        StateAccess::placeObject(runtime, id, *where.at(id), structure.saved, node ? &*node : nullptr);
    }
    restoreBonds(runtime, structure);
    return Status::ok();
}

} // namespace rubble
