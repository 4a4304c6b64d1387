#pragma once
// Private to the core: what the persist layer reads and replaces inside a world and a runtime to save and
// load them (rubble/persist/WorldState.hpp). Both classes befriend it; no public header includes it.

#include <cstdint>
#include <vector>

#include "rubble/runtime/DestructionRuntime.hpp"
#include "rubble/runtime/DestructionWorld.hpp"
#include "runtime/BodyTable.hpp"
#include "runtime/StructureMonitor.hpp"

namespace rubble::detail {

/// One impact of unadopted work and the frame it was submitted in.
struct TickedImpact {
    Impact impact;
    std::uint64_t tick = 0;
};

/// Unadopted work on one object: a job in flight or impacts waiting for the object's job.
struct WorldWork {
    ObjectId object = 0;
    std::uint32_t version = 0;
    bool inFlight = false;
    std::uint64_t readyFrame = 0; // in flight: the frame it is adopted in (deterministic mode)
    std::vector<TickedImpact> impacts;
};

/// The insides of a DestructionWorld and a DestructionRuntime that saving and loading need.
class StateAccess {
public:
    /// The world's settings.
    static DestructionWorld::Config& config(DestructionWorld& world);
    /// The world's settings.
    static const DestructionWorld::Config& config(const DestructionWorld& world);
    /// The id the world's next new object gets.
    static ObjectId nextId(const DestructionWorld& world);
    /// The live objects, ascending id, with their mesh hashes.
    static std::vector<ObjectState> objects(const DestructionWorld& world);
    /// Jobs in flight (launch order), then impacts waiting for them (by object).
    static std::vector<WorldWork> work(const DestructionWorld& world);
    /// Replaces the objects and counters and drops all work (jobs in flight finish; their results are
    /// dropped). An object without a mesh hash gets one.
    static void replace(DestructionWorld& world, std::vector<ObjectState> objects, std::uint64_t frame,
                        ObjectId nextId, std::uint64_t journalPosition);
    /// Relaunches a job in flight, or queues impacts behind the object's job.
    static void resume(DestructionWorld& world, const WorldWork& work);

    /// The runtime's settings.
    static const DestructionRuntime::Config& config(const DestructionRuntime& runtime);
    /// The runtime's world.
    static DestructionWorld& world(DestructionRuntime& runtime);
    /// The runtime's bodies.
    static const BodyTable& bodies(const DestructionRuntime& runtime);
    /// The runtime's structure.
    static const StructureMonitor& structure(const DestructionRuntime& runtime);
    /// The runtime's structure.
    static StructureMonitor& structure(DestructionRuntime& runtime);
    /// Removes a body from the engine and every component; its object stays in the world.
    static void dropBody(DestructionRuntime& runtime, BodyId id);
    /// Continues the volume ledger from these retired, dust and dropped volumes.
    static void continueLedger(DestructionRuntime& runtime, const VolumeLedger& volumes);
    /// Gives a world object a body at its placement, with its velocities and motion state: a static one joins
    /// the support graph and the structure (with savedStructure as node says, no node: not at all; without,
    /// as a scene object does at load), a frozen one the governor's grid.
    static void placeObject(DestructionRuntime& runtime, ObjectId id, const ObjectPlacement& placement,
                            bool savedStructure, const StructureMonitor::SavedNode* node);
};

} // namespace rubble::detail
