#pragma once
/// \file NetClient.hpp
/// The following side of loopback multiplayer: loads the host's snapshot, then replays its journal events
/// and checks its geometry hash against the host's at every frame sync (docs/netplay.md).

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "rubble/core/Result.hpp"
#include "rubble/runtime/DestructionWorld.hpp"

namespace rubble::net {

/// Totals of a client.
struct ClientStats {
    bool connected = false;         ///< the host accepted the connection
    bool joined = false;            ///< the snapshot arrived and was loaded
    double joinMs = 0;              ///< connect → snapshot loaded (ms)
    double helloMs = 0;             ///< hashing its objects for the Hello, mostly while connecting (ms)
    double connectMs = 0;           ///< of joinMs: connect → ENet's connection made (ms)
    double firstChunkMs = 0;        ///< of joinMs: connect → the snapshot's first chunk (ms)
    double snapshotLoadMs = 0;      ///< of joinMs: inflating, decoding and loading the snapshot (ms)
    double snapshotDecodeMs = 0;    ///< of snapshotLoadMs: inflating and decoding it (ms)
    long long events = 0;           ///< journal events applied
    long long syncs = 0;            ///< frame syncs checked
    long long mismatchedHashes = 0; ///< syncs whose geometry hash differed from the host's
    std::uint64_t frame = 0;        ///< the world's frame after the last sync
    long long placements = 0;       ///< placement records received
    long long placementBytes = 0;   ///< bytes of placement messages received
    long long resyncs = 0;          ///< snapshots loaded after an outage instead of cutting the backlog
    double resyncLoadMs = 0;        ///< time spent decoding and loading them (ms)
    long long keepAlives = 0;       ///< times ENet was served from within a long catch-up
    long long reliableResent = 0;   ///< reliable commands ENet sent again after its retransmission timeout
    std::string firstMismatch;      ///< what differed at the first mismatched sync (empty: none)
};

/// A client of a NetHost on a loopback address. Its world must be built with the host's settings (any
/// worker count); the snapshot replaces its content. Objects the world has when it connects (e.g. the scene,
/// loaded by the client itself) are announced to the host, which then sends by id those it has in the same
/// state: a client that loaded the host's scene joins with a much smaller snapshot.
class NetClient {
public:
    /// Starts connecting to address:port (a loopback address) and, while the connection is being made, hashes
    /// the world's objects for the Hello; service() completes it, sending the handshake again every 0.5 s
    /// while no answer comes, and fails when none came within the timeout (setTimeout; 10 s by default).
    static Result<std::unique_ptr<NetClient>> connect(DestructionWorld& world,
                                                      const DestructionWorld::Config& config,
                                                      const std::string& address, std::uint16_t port);
    ~NetClient();
    NetClient(const NetClient&) = delete;
    NetClient& operator=(const NetClient&) = delete;

    /// Receives and applies what arrived within timeoutMs. Fails when the host sent something the world
    /// refuses (a corrupted snapshot or an event out of order) or the connection was lost.
    Status service(int timeoutMs = 0);
    /// Where an object is at (fractional) host frame `frame`: interpolated between the placements the host
    /// sent for it in its last 120 frames (position linearly, rotation by normalised quaternion blend), held
    /// at the ends. A new piece starts where its parent was. Empty for an object the client has no placement
    /// of.
    std::optional<Frame> placement(ObjectId object, double frame) const;
    /// Asks the host to fire a shot (it checks it first: docs/netplay.md, 'Trust model'). Fails when not
    /// connected.
    Status shoot(const Vec3& origin, const Vec3& velocity);
    /// Saves what replays this game up to now: the snapshot it joined with (saveSnapshot) and every journal
    /// event applied since (writeJournal); restoreSnapshot and a JournalPlayer then rebuild its world. Call
    /// it when the host stopped (service() failed with an IoError) to keep the game. Fails before the join.
    Status writeReplay(const std::filesystem::path& snapshot, const std::filesystem::path& journal) const;
    /// Host frame of the latest placement received for an object (empty when none arrived).
    std::optional<double> placementFrame(ObjectId object) const;
    /// How long the host may be silent before service() fails with an IoError saying it stopped answering,
    /// or that no host answered while connecting (default 10 s: a partition shorter than that is survived, a
    /// host killed without closing is noticed).
    void setTimeout(int ms);
    /// Whether it keeps what writeReplay needs (default true): a copy of the world it joined (or resynced)
    /// with, which costs a copy of every object at each load.
    void setKeepReplay(bool keep);
    /// After an outage (the host silent for 1 s), a client more than `frames` behind the host asks for the
    /// world as it is, its own unchanged objects by id, instead of cutting the pieces of what it missed
    /// (default 60; 0: never, it cuts them all).
    void setResyncFrames(int frames);
    /// Called for every outcome the world adopts (its pieces are in the world already).
    void setOnOutcome(std::function<void(const FractureOutcome&)> callback);
    /// Totals.
    const ClientStats& stats() const;

private:
    struct Impl;
    explicit NetClient(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

} // namespace rubble::net
