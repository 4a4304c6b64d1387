#pragma once
/// \file WorldState.hpp
/// The saved state of a world and of a runtime's structure, and the functions that take it from them and give
/// it back (the runtime knows nothing of saving).

#include <cstdint>
#include <vector>

#include "rubble/core/Export.hpp"
#include "rubble/core/Result.hpp"
#include "rubble/runtime/DestructionRuntime.hpp"
#include "rubble/runtime/DestructionWorld.hpp"

namespace rubble {

/// Fracture work not yet adopted: a job in flight (to be relaunched on load) or impacts waiting for one.
struct RUBBLE_API PendingWork {
    ObjectId object = 0;              ///< the object hit
    std::uint32_t version = 0;        ///< its version when the job started
    bool inFlight = false;            ///< a launched job (true) or impacts waiting for the object's job
    std::uint64_t readyFrame = 0;     ///< in flight: the frame it is adopted in (deterministic mode)
    std::vector<Impact> impacts;      ///< as submitted (journal precision), in order
    std::vector<std::uint64_t> ticks; ///< frame of each impact's submission
};

/// Everything a DestructionWorld holds besides its threads and timings: what a snapshot saves. The settings
/// (DestructionWorld::Config) that decide the geometry travel with it, so that a world loading it cuts the
/// same pieces.
struct RUBBLE_API WorldState {
    std::uint64_t seed = 1;             ///< Config::seed
    std::int32_t delayFrames = 2;       ///< Config::delayFrames
    std::uint64_t crumbleTriangles = 0; ///< Config::crumbleTriangles
    std::int32_t crumbleCells = 0;      ///< Config::crumbleCells
    double minPieceVolume = 0;          ///< Config::minPieceVolume
    DecompositionParams decomposition;  ///< Config::decomposition (convex parts of new pieces)
    std::uint64_t frame = 0;            ///< DestructionWorld::frame()
    ObjectId nextId = 1;                ///< the id the next new object gets
    std::uint64_t journalPosition = 0;  ///< journal events so far
    std::vector<ObjectState> objects;   ///< live objects, ascending id
    std::vector<PendingWork> work;      ///< jobs in flight (launch order), then waiting impacts (by object)
};

/// What a snapshot keeps of a structure node (a static object or piece in the stress solver).
struct RUBBLE_API StructureNodeState {
    ObjectId object = 0;       ///< the object
    ObjectId solid = 0;        ///< the scene object it was cut from (its own id for a scene object)
    std::uint8_t material = 0; ///< its material: an index into materialPresets()
    bool root = false;         ///< held in place (an anchor, or the piece an anchor kept)
    bool anchor = false;       ///< made a root by the anchor rule (its pieces are classified again)
    bool pending = false;      ///< placed since the last step: the anchor rule decides at the next one
};

/// What a snapshot keeps of a bond: what geometry cannot give back. Its nodes are object ids, or
/// kSceneryNodeKey | body id for ground and scenery (the same bodies in the same order as in the saver).
struct RUBBLE_API StructureBondState {
    std::uint64_t a = 0, b = 0; ///< its nodes, a < b
    double health = 1;          ///< remaining fraction of the section
    bool broken = false;        ///< broken (it stays broken while both nodes stay)
};

/// The structure's saved state (docs/journal.md, Snapshots).
struct RUBBLE_API StructureState {
    bool saved = false; ///< false: not saved (no structure, a world-only or a version 2 snapshot)
    std::vector<StructureNodeState> nodes; ///< ascending object
    std::vector<StructureBondState> bonds; ///< every bond, broken ones included, ascending (a, b)
};

/// The world's state (objects, frame, id counter, journal position, unadopted work).
RUBBLE_API WorldState captureState(const DestructionWorld& world);
/// Replaces the world's state and settings (pending results are dropped; saved work is relaunched). Fails,
/// changing nothing, on an inconsistent state (ids, work, empty meshes, settings out of range).
RUBBLE_API Status restoreState(DestructionWorld& world, WorldState state);

/// The runtime's structure nodes and bonds (saved false unless StructurePolicy::enabled).
RUBBLE_API StructureState captureStructure(const DestructionRuntime& runtime);
/// Replaces the runtime's world state and the bodies of its objects by a saved world: each object gets a body
/// at its placement (static ones join the support graph and, as saved or fresh, the structure; frozen ones
/// the governor's grid); other bodies stay; the volume ledger continues from volumes. Fails, changing
/// nothing, on an inconsistent state, placements that do not match the objects, a negative or non-finite
/// volume, or a structure node or bond that names no static object (or no ground or scenery body of this
/// runtime).
RUBBLE_API Status restoreState(DestructionRuntime& runtime, WorldState state,
                               const std::vector<ObjectPlacement>& placements,
                               const VolumeLedger& volumes = {}, const StructureState& structure = {});

} // namespace rubble
