#pragma once
/// \file NetHost.hpp
/// The authoritative side of loopback multiplayer: sends a joining client a snapshot (compressed, without the
/// objects it announced it has in the same state), then every journal event and, once per frame, the frame
/// number with the geometry hash it must match (docs/netplay.md).

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "rubble/core/Result.hpp"
#include "rubble/runtime/DestructionRuntime.hpp"
#include "rubble/runtime/DestructionWorld.hpp"

namespace rubble::net {

/// Totals of a host.
struct HostStats {
    int clients = 0;                          ///< clients connected now
    long long joins = 0;                      ///< clients that joined (each got a snapshot)
    long long eventsSent = 0;                 ///< journal events sent (per client)
    long long eventBytes = 0;                 ///< bytes of journal event messages sent (per client, payload)
    long long snapshotBuilds = 0;             ///< snapshots built (joins within 30 frames share one)
    long long snapshotBytes = 0;              ///< bytes of snapshot messages sent (compressed)
    long long snapshotRawBytes = 0;           ///< what they inflate to (the objects the clients did not have)
    long long snapshotObjectsByReference = 0; ///< objects sent by id: the client had them in that state
    long long snapshotObjectsPacked = 0;      ///< objects compressed while building (the rest were cached)
    long long objectsWarmed = 0;              ///< objects compressed and hashed ahead, while the game waited
    double snapshotBuildMs = 0;               ///< time spent taking, encoding and compressing snapshots (ms)
    double snapshotCaptureMs = 0;             ///< of snapshotBuildMs: placements and the world's state (ms)
    double snapshotEncodeMs = 0;              ///< of snapshotBuildMs: encoding it (ms)
    double snapshotCompressMs = 0;            ///< of snapshotBuildMs: compressing it (ms)
    long long snapshotChunksSent = 0;         ///< snapshot chunks sent, resends included
    double snapshotTransferMs =
        0;                 ///< time from sending snapshots' first chunks to their last acknowledgement (ms)
    long long resyncs = 0; ///< snapshots sent to joined clients far behind (Message::Resync)
    long long resyncBytes = 0;       ///< their bytes (compressed)
    long long resyncObjectsSent = 0; ///< objects in them (the rest went by id)
    double resyncTransferMs = 0;     ///< time from their first chunks to their last acknowledgement (ms)
    long long syncs = 0;             ///< frame syncs sent (per client)
    long long impactEvents = 0;      ///< of eventsSent: impacts (the rest are removals)
    long long placementBytes = 0;    ///< bytes of placement messages sent (per client, payload)
    long long legacyPlacementBytes =
        0; ///< what the 32-byte float records of every dynamic body would have been
    long long placementsDeferred = 0; ///< changed bodies left for a later publish by the budget (per client)
    long long placementPublishesFull = 0; ///< publishes per client whose budget ran out
    long long acks = 0;                   ///< clients' hash reports received
    long long mismatchedHashes = 0; ///< reports whose geometry hash differed from the host's at that frame
    long long shotsAccepted = 0;    ///< clients' shots that passed the checks (handed to the shot handler)
    long long shotsRefused = 0; ///< clients' shots refused: malformed, implausible, too many, or no handler
};

/// Placement bytes per client: `mean` per publishPlacements on average (10 Hz: 96 kbps), at most `peak` in
/// one; what quiet publishes leave unspent is saved, up to `reserve`, and spent while many bodies move.
struct PlacementBudget {
    std::size_t mean = 1200;
    std::size_t peak = 3600;
    std::size_t reserve = 24000;
};

/// What a client may ask for: a shot, checked by the host before anything happens.
struct ShotRules {
    double perSecond = 10; ///< sustained shots per second per client (a bucket refilled per published frame)
    double burst = 10;     ///< shots a client may fire at once
    double maxSpeed = 200; ///< m/s
    double maxDistance = 1e3; ///< how far from the world's origin a shot may start (m)
};

/// A client's shot that passed the checks.
struct ShotRequest {
    std::uint64_t client = 0; ///< the client, in the order they joined (0 = the first)
    Vec3 origin;              ///< where it starts (m)
    Vec3 velocity;            ///< m/s
};

/// A host on 127.0.0.1 (only loopback addresses are accepted). Replicates the world it is given; the world
/// must be deterministic (Config::deterministic), since clients replay its journal.
class NetHost {
public:
    /// Listens on address:port (port 0 = any free port) for at most maxClients, replicating the runtime's
    /// world (config: its DestructionWorld::Config). Fails for a non-loopback address, a world that is not
    /// deterministic, or when ENet cannot bind.
    static Result<std::unique_ptr<NetHost>> listen(DestructionRuntime& runtime,
                                                   const DestructionWorld::Config& config,
                                                   const std::string& address, std::uint16_t port,
                                                   int maxClients = 8);
    ~NetHost();
    NetHost(const NetHost&) = delete;
    NetHost& operator=(const NetHost&) = delete;

    /// Takes a journal event. listen() makes this the runtime's journal sink; a game that has its own sink
    /// forwards the events here instead.
    void journaled(const JournalEvent& event);
    /// The port it listens on.
    std::uint16_t port() const;
    /// Sends every client the journal events since its last publish and a sync for the world's current
    /// frame; call once per frame after the world (or runtime) stepped.
    void publish();
    /// Sends every client the placements that differ from what it acknowledged (unreliable, on channel 1;
    /// quantized, delta-coded, the most overdue first within the budget): the host is authoritative for
    /// motion. Bodies at rest cost nothing. Call at a modest rate (10 Hz). A client whose snapshot is on its
    /// way gets the latest ones as soon as it has the snapshot.
    void publishPlacements(const std::vector<ObjectPlacement>& placements);
    /// Bytes of placements per client (PlacementBudget: a mean, a peak and a reserve).
    void setPlacementBudget(const PlacementBudget& budget);
    /// Handles the network until every connected client confirmed the latest sync (or timeoutMs passed);
    /// true when they all did. Call before closing, so that the clients end in the host's state.
    bool finish(int timeoutMs);
    /// Stops serving: tells every client the host is going (they get an IoError from service() and can keep
    /// their replay, NetClient::writeReplay) and handles the network until they all confirmed or timeoutMs
    /// passed; true when they all did. Later clients are refused.
    bool close(int timeoutMs);
    /// Where joining clients' snapshots get the bodies' placements from (e.g. the runtime's placements()).
    void setPlacementSource(std::function<std::vector<ObjectPlacement>()> source);
    /// Handles the network (joins, leaves, clients' hash reports) for timeoutMs, sending snapshot chunks
    /// throughout at their own pace: a game that waits for its next frame should wait in here. Time to
    /// spare goes to compressing new objects for later snapshots.
    void service(int timeoutMs = 0);
    /// How long a client may leave the host's packets unacknowledged before it counts as gone (default 10 s),
    /// for the clients connected and those to come.
    void setTimeout(int ms);
    /// Whether snapshots keep each object's compressed record (by id and version) and compress new objects
    /// ahead in service(), so that a join compresses only what changed since (default off: on the
    /// demolition scene the snapshot grew by a third and its build did not get measurably faster).
    void setSnapshotCache(bool on);
    /// Takes clients' shots: each one that passes `rules` (finite, speed and origin in range, within the
    /// client's rate) goes to `handler`, which fires it in the host's world; everything else is refused and
    /// counted. Without a handler, every shot is refused: clients change nothing.
    void setShotHandler(std::function<void(const ShotRequest&)> handler, ShotRules rules = {});
    /// The latest frame each connected client confirmed (in the order they joined).
    std::vector<std::uint64_t> confirmedFrames() const;
    /// Totals.
    const HostStats& stats() const;

private:
    struct Impl;
    explicit NetHost(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

} // namespace rubble::net
