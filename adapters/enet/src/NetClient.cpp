#include "rubble/enet/NetClient.hpp"

#include <chrono>
#include <deque>
#include <map>

#include <algorithm>

#include "Events.hpp"
#include "JoinSnapshot.hpp"
#include "Placements.hpp"
#include "Protocol.hpp"
#include "Track.hpp"
#include "rubble/persist/JournalFile.hpp"
#include "rubble/persist/Snapshot.hpp"
#include "rubble/runtime/JobSeed.hpp"
#include "rubble/runtime/JournalPlayer.hpp"

namespace rubble::net {

using detail::Message;
using Clock = std::chrono::steady_clock;

using detail::PublishLog;
using detail::Track;

namespace {
constexpr auto kOutage =
    std::chrono::seconds(1); // a host silent this long: the backlog may be worth a resync
constexpr auto kResyncWait = std::chrono::seconds(5);      // how long it waits for a resync's first chunk
constexpr auto kKeepAlive = std::chrono::milliseconds(50); // the longest it leaves ENet alone while cutting
} // namespace

struct NetClient::Impl {
    Impl(DestructionWorld& w, const DestructionWorld::Config& c) : world(w), config(c), player(w) {
        player.setOnOutcome([this](const FractureOutcome& o) { adopted(o); });
    }
    DestructionWorld& world;
    DestructionWorld::Config config;
    JournalPlayer player;
    ENetHost* host = nullptr;
    ENetPeer* server = nullptr;
    Clock::time_point connected;
    Clock::time_point heard; // when the host was last heard
    enet_uint32 timeoutMs = detail::kPeerTimeoutMs;
    ClientStats stats;
    std::map<ObjectId, Track> tracks; // also of pieces the world does not have yet
    PublishLog publishes;             // the placements datagrams received
    detail::PlacementDecoder decoder;
    std::deque<detail::WireEvent> held; // events received, applied when the world reaches their tick
    std::vector<detail::WireEvent> arrived;
    std::uint64_t seed = 0;             // the host world's seed (from the snapshot)
    std::optional<Snapshot> joinedWith; // the snapshot it joined with (for a replay)
    std::vector<JournalEvent> applied;  // every event applied since
    // Resync after an outage: far behind, it asks for the world as it is (its own objects by id) instead of
    // cutting the backlog's pieces, and keeps the events that arrive meanwhile by journal position.
    std::uint64_t resyncFrames = 60;  // frames behind the host after an outage that ask for one (0: never)
    std::uint64_t streamPosition = 0; // journal position of the next event the host sends (once joined)
    std::uint64_t skipUntil = 0;      // events before this position are in the world already (a resync)
    std::uint64_t hostFrame = 0;      // the newest host frame named by a message
    bool afterOutage = false;         // the host was silent for kOutage, and the world has not caught up
    bool resyncing = false;           // asked for a resync: keeps events, no syncs
    Clock::time_point resyncAsked;    // when
    std::vector<std::pair<std::uint64_t, detail::WireEvent>> pending; // events kept meanwhile, by position
    struct SyncMsg {
        std::uint64_t frame = 0, position = 0, hash = 0;
    };
    std::optional<SyncMsg> keptSync; // the latest sync received while resyncing
    std::uint64_t keptSyncAt = 0;    // the journal position of the event after it in the stream
    std::uint64_t resyncFrom = 0;    // its journal position when it asked
    std::uint64_t resyncedAt = 0;    // the frame of the latest resync's snapshot
    std::string resyncNote;          // what it was (for a mismatch after it)
    bool keepReplay = true;          // keeps the snapshot it joined (or resynced) with, for writeReplay
    detail::StateHashes stateHashes; // its objects' state hashes, by version (Hello, Resync)

    // Applies the held events of the world's current frame, with the fields the host left out.
    Status applyHeld() {
        while (!held.empty() && held.front().event.tick == world.frame()) {
            JournalEvent e = held.front().event;
            const std::uint8_t check = held.front().check;
            held.pop_front();
            if (e.kind == JournalEventKind::Impact) {
                const ObjectState* o = world.object(e.object);
                if (!o)
                    return Error{ErrorCode::InvalidInput, "netplay: impact on object " +
                                                              std::to_string(e.object) +
                                                              ", which this world does not have"};
                e.pattern = patternByte(o->fracture);
                e.cells = static_cast<std::uint16_t>(std::clamp(o->fracture.cells, 0, 65535));
                e.seed = jobSeed(seed, o->id, o->version); // the world's next job seed
                if (detail::eventCheck(e) != check)
                    return Error{ErrorCode::InvalidInput,
                                 "netplay: impact on object " + std::to_string(e.object) +
                                     ": its pattern or job seed differs from the host's"};
            }
            if (Status st = player.receive(e); !st)
                return st;
            applied.push_back(e);
        }
        return Status::ok();
    }

    // A sync: the world advanced to its frame must have its hash (checked, and reported to the host). One
    // older than the world (sent before a resync's snapshot was taken) is passed over.
    Status sync(const SyncMsg& m) {
        if (m.frame < world.frame())
            return Status::ok();
        if (Status st = advanceTo(m.frame); !st)
            return st;
        const std::uint64_t mine = world.geometryHash();
        ++stats.syncs;
        stats.frame = world.frame();
        if (mine != m.hash || world.journalPosition() != m.position) {
            if (stats.mismatchedHashes++ == 0) // what differed, the first time
                stats.firstMismatch =
                    "frame " + std::to_string(m.frame) + ": geometry hash " + std::to_string(mine) +
                    (mine == m.hash ? " (the host's)" : " against the host's " + std::to_string(m.hash)) +
                    ", journal position " + std::to_string(world.journalPosition()) +
                    (world.journalPosition() == m.position
                         ? " (the host's)"
                         : " against the host's " + std::to_string(m.position)) +
                    (stats.resyncs > 0 ? ", " + std::to_string(m.frame - resyncedAt) +
                                             " frames after its resync (" + resyncNote + ")"
                                       : "");
        }
        if (afterOutage && hostFrame <= world.frame() + resyncFrames)
            afterOutage = false; // caught up
        std::vector<std::uint8_t> ack{static_cast<std::uint8_t>(Message::Ack)};
        detail::appendU64(ack, m.frame);
        detail::appendU64(ack, mine);
        detail::sendReliable(server, ack);
        return Status::ok();
    }

    // Takes an event (the next in the host's journal) into `held`, or `pending` while resyncing.
    Status take(const detail::WireEvent& w) {
        const std::uint64_t position = streamPosition++;
        if (position < skipUntil)
            return Status::ok(); // the resync's snapshot has it
        ++stats.events;
        if (resyncing) {
            pending.emplace_back(position, w);
            return Status::ok();
        }
        const std::uint32_t last = held.empty() ? 0 : held.back().event.tick;
        if (w.event.tick < world.frame() || w.event.tick < last)
            return Error{ErrorCode::InvalidInput,
                         "netplay: journal event of tick " + std::to_string(w.event.tick) + " arrived late"};
        held.push_back(w);
        return Status::ok();
    }

    // Where it was when the host went: its frame against the host's newest, and the last message's age.
    std::string whereItStopped() const {
        const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(Clock::now() - heard).count();
        return "; this world at frame " + std::to_string(world.frame()) + ", the host's newest " +
               std::to_string(hostFrame) + ", last heard " + std::to_string(ms) + " ms ago" +
               (resyncing ? ", waiting for a resync" : "");
    }

    // The host's newest frame, from a sync, placements or frame message about to be handled.
    void noteHostFrame(const std::uint8_t* d, std::size_t n) {
        if ((n == 25 && d[0] == static_cast<std::uint8_t>(Message::Sync)) ||
            (n == 9 && d[0] == static_cast<std::uint8_t>(Message::Frame))) {
            hostFrame = std::max(hostFrame, detail::readU64(d + 1));
        } else if (n > 5 && d[0] == static_cast<std::uint8_t>(Message::Placements)) {
            const std::uint8_t* p = d + 5;
            std::uint64_t frame = 0;
            if (detail::getVarint(p, d + n, frame))
                hostFrame = std::max(hostFrame, frame);
        }
    }

    // After an outage, far behind the host: asks for a resync (the events it holds wait with their
    // positions). Gives up on one whose first chunk did not come within kResyncWait.
    Status checkLag() {
        const Clock::time_point now = Clock::now();
        if (resyncing && incoming.id == 0 && now - resyncAsked > kResyncWait)
            return endResync(0);
        if (!afterOutage || resyncing || !stats.joined || !server || resyncFrames == 0 ||
            hostFrame <= world.frame() + resyncFrames)
            return Status::ok();
        afterOutage = false;
        if (!detail::sendReliable(server, detail::encodeHello(world, true, &stateHashes)))
            return Error{ErrorCode::IoError, "netplay: cannot ask for a resync"};
        resyncing = true;
        resyncAsked = now;
        resyncFrom = world.journalPosition();
        std::uint64_t position = streamPosition - held.size();
        for (const detail::WireEvent& w : held)
            pending.emplace_back(position++, w);
        held.clear();
        enet_host_flush(host);
        return Status::ok();
    }

    // Leaves resync mode: the kept events from journal position `from` on follow in the order they came,
    // the latest sync kept among them: the events that came before it, then it, then the rest (an event the
    // host recorded after a sync of the same frame must not be applied before that sync is checked).
    Status endResync(std::uint64_t from) {
        resyncing = false;
        skipUntil = std::max(skipUntil, from);
        const std::optional<SyncMsg> m = keptSync;
        keptSync.reset();
        const std::vector<std::pair<std::uint64_t, detail::WireEvent>> kept = std::move(pending);
        pending.clear();
        const auto hold = [&](bool beforeSync) -> Status {
            for (const auto& [position, w] : kept) {
                if (position < skipUntil || (m && (position < keptSyncAt) != beforeSync))
                    continue;
                const std::uint32_t last = held.empty() ? 0 : held.back().event.tick;
                if (w.event.tick < world.frame() || w.event.tick < last)
                    return Error{ErrorCode::InvalidInput, "netplay: journal event of tick " +
                                                              std::to_string(w.event.tick) + " arrived late"};
                held.push_back(w);
            }
            return applyHeld();
        };
        for (const auto& [position, w] : kept)
            stats.events -= position < skipUntil; // in the snapshot
        if (Status st = hold(true); !st)
            return st;
        if (m)
            if (Status st = sync(*m); !st)
                return st;
        return m ? hold(false) : Status::ok();
    }

    // Advances the world to `frame`, applying the events of each frame as it begins; ENet goes on meanwhile
    // (a long catch-up would leave the host's packets unacknowledged until it timed the client out).
    Status advanceTo(std::uint64_t frame) {
        if (Status st = applyHeld(); !st)
            return st;
        while (world.frame() < frame) {
            if (Status st = player.advanceTo(world.frame() + 1); !st)
                return st;
            if (Status st = applyHeld(); !st)
                return st;
            keepAlive();
        }
        return Status::ok();
    }

    // The connection is made: the Hello goes out in the datagram that carries ENet's acknowledgement of it
    // (queued before ENet runs again). Sent after it, in a datagram of its own, it could overtake that
    // acknowledgement, and the host drops a reliable command of a peer not yet connected: it came again
    // after ENet's first retransmission timeout, about 0.5 s later. False when it could not be queued.
    bool hello() {
        stats.connected = true;
        heard = Clock::now(); // silence counts from the connection
        stats.connectMs = std::chrono::duration<double, std::milli>(Clock::now() - connected).count();
        detail::configurePeer(server, timeoutMs);
        const Clock::time_point hashing = Clock::now();
        const std::vector<std::uint8_t> msg = detail::encodeHello(world, false, &stateHashes);
        stats.helloMs += std::chrono::duration<double, std::milli>(Clock::now() - hashing).count();
        return detail::sendReliable(server, msg);
    }

    // Lets ENet send and receive (what arrives waits for the next service) if it has not for kKeepAlive.
    void keepAlive() {
        const Clock::time_point now = Clock::now();
        if (!host || now - pumped < kKeepAlive)
            return;
        pumped = now;
        ++stats.keepAlives;
        enet_host_service(host, nullptr, 0);
    }
    Clock::time_point pumped; // when ENet last ran
    enet_uint32 lostSeen = 0; // ENet's packetsLost of the host's peer when last read (it restarts every 10 s)
    std::vector<detail::DecodedPlacement> decoded;
    std::function<void(const FractureOutcome&)> onOutcome;

    void adopted(const FractureOutcome& o) {
        if (auto t = tracks.find(o.parent); t != tracks.end()) {
            const Track parent = t->second;
            tracks.erase(t);
            const double born = static_cast<double>(world.frame()); // piece → parent local → world
            const Frame where = parent.points.empty() ? Frame{} : parent.at(born);
            if (!parent.points.empty())
                for (const AdoptedPiece& p : o.pieces)
                    tracks[p.id].add(born, where * p.frame);
        }
        if (onOutcome)
            onOutcome(o);
    }

    void placements(const std::uint8_t* d, std::size_t n) {
        if (!stats.joined)
            return; // the baselines come with the snapshot; unacknowledged, these are sent again
        std::uint64_t frameNumber = 0;
        decoded.clear();
        if (!decoder.decode(d, n, frameNumber, decoded))
            return; // unreliable channel: a malformed packet is dropped
        stats.placementBytes += static_cast<long long>(n);
        const double frame = static_cast<double>(frameNumber);
        const std::uint32_t seq = detail::readU32(d + 1), latest = decoder.latest();
        if (seq == latest ||
            (seq < latest && latest - seq <= 32 && (decoder.mask() >> (latest - seq - 1)) & 1))
            publishes.received(seq, frame); // decoded whole (a record without its baseline is left out)
        for (const detail::DecodedPlacement& r : decoded) {
            const Frame f = detail::dequantize(r.q);
            tracks[r.id].add(frame, f, &publishes);
            ++stats.placements;
        }
        std::vector<std::uint8_t> ack{static_cast<std::uint8_t>(Message::PlacementAck)};
        for (std::uint32_t v : {decoder.latest(), decoder.mask()})
            for (int i = 0; i < 4; ++i)
                ack.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
        detail::sendUnreliable(server, ack);
    }

    // The snapshot's chunks as they arrive (Message::SnapshotChunk), and what it acknowledges.
    struct Incoming {
        std::uint32_t id = 0, total = 0;
        std::vector<std::uint8_t> bytes;
        std::vector<bool> got;
        std::size_t left = 0;
    } incoming;
    std::uint32_t doneTransfer = 0; // the transfer it has whole (its chunks are acknowledged, all of them)
    std::size_t doneChunks = 0;
    bool ackDue = false;
    std::vector<std::vector<std::uint8_t>> early; // events messages that came before the snapshot was whole

    // A chunk of the snapshot; the whole message is loaded once every chunk is in. Malformed chunks (the
    // unreliable channel) are dropped.
    Status chunk(const std::uint8_t* d, std::size_t n) {
        if (n < 13)
            return Status::ok();
        const std::uint32_t id = detail::readU32(d + 1), index = detail::readU32(d + 5),
                            total = detail::readU32(d + 9);
        ackDue = true;
        if (id <= doneTransfer || total == 0 || total > (1u << 30))
            return Status::ok();
        const std::size_t count = (total + detail::kSnapshotChunk - 1) / detail::kSnapshotChunk;
        if (stats.joined && !resyncing && id != incoming.id) { // a resync it gave up waiting for
            doneTransfer = id; // acknowledged whole, so that the host stops sending it
            doneChunks = count;
            return Status::ok();
        }
        if (incoming.id != id) {
            incoming = {id, total, std::vector<std::uint8_t>(total), std::vector<bool>(count), count};
            if (!stats.joined)
                stats.firstChunkMs =
                    std::chrono::duration<double, std::milli>(Clock::now() - connected).count();
        }
        const std::size_t at = static_cast<std::size_t>(index) * detail::kSnapshotChunk;
        if (incoming.total != total || index >= count ||
            n != 13 + std::min(detail::kSnapshotChunk, total - at))
            return Status::ok();
        if (!incoming.got[index]) {
            std::copy(d + 13, d + n, incoming.bytes.begin() + static_cast<std::ptrdiff_t>(at));
            incoming.got[index] = true;
            --incoming.left;
        }
        if (incoming.left > 0)
            return Status::ok();
        doneTransfer = id;
        doneChunks = count;
        acknowledgeChunks(); // before loading it, so that the host sends no chunk again meanwhile
        const std::vector<std::uint8_t> whole = std::move(incoming.bytes);
        incoming = {};
        if (Status st = receive(whole.data(), whole.size()); !st)
            return st;
        for (const std::vector<std::uint8_t>& m : early) // then what came meanwhile, in order
            if (Status st = receive(m.data(), m.size()); !st)
                return st;
        early.clear();
        return Status::ok();
    }

    // Tells the host which chunks it has (once per service, when chunks came).
    void acknowledgeChunks() {
        if (!ackDue || !server)
            return;
        ackDue = false;
        const bool whole = incoming.id == 0; // else a transfer on its way (a resync's, after the join's)
        const std::uint32_t id = whole ? doneTransfer : incoming.id;
        const std::size_t count = whole ? doneChunks : incoming.got.size();
        std::vector<std::uint8_t> ack{static_cast<std::uint8_t>(Message::SnapshotAck)};
        for (int b = 0; b < 4; ++b)
            ack.push_back(static_cast<std::uint8_t>(id >> (8 * b)));
        ack.resize(5 + (count + 7) / 8, 0);
        for (std::size_t i = 0; i < count; ++i)
            if (whole || incoming.got[i])
                ack[5 + i / 8] |= static_cast<std::uint8_t>(1u << (i % 8));
        detail::sendUnreliable(server, ack);
        enet_host_flush(host);
    }

    // A resync's snapshot: the world becomes the host's (its own unchanged objects were sent by id), and the
    // events kept meanwhile that the snapshot does not hold follow.
    Status resynced(Snapshot s, Clock::time_point received) {
        const std::uint64_t position = s.world.journalPosition;
        const double frame = static_cast<double>(s.world.frame);
        if (position < resyncFrom)
            return Error{ErrorCode::InvalidInput,
                         "netplay: the resync's snapshot (journal position " + std::to_string(position) +
                             ") is older than this world (" + std::to_string(resyncFrom) + ")"};
        std::optional<Snapshot> kept;
        if (keepReplay)
            kept = s;
        if (Status st = restoreSnapshot(world, std::move(s)); !st)
            return st;
        joinedWith = std::move(kept); // a replay starts here now
        applied.clear();
        for (auto t = tracks.begin(); t != tracks.end();) // objects gone before the snapshot
            t = !world.object(t->first) && (t->second.points.empty() || t->second.points.back().first < frame)
                    ? tracks.erase(t)
                    : std::next(t);
        held.clear();
        ++stats.resyncs;
        resyncedAt = static_cast<std::uint64_t>(frame);
        std::size_t after = 0;
        for (const auto& p : pending)
            after += p.first >= position;
        resyncNote = "snapshot at frame " + std::to_string(resyncedAt) + ", position " +
                     std::to_string(position) + "; asked at position " + std::to_string(resyncFrom) + "; " +
                     std::to_string(pending.size()) + " events kept, " + std::to_string(after) +
                     " of them after the snapshot; next event position " + std::to_string(streamPosition);
        stats.resyncLoadMs += std::chrono::duration<double, std::milli>(Clock::now() - received).count();
        return endResync(position);
    }

    Status receive(const std::uint8_t* d, std::size_t n) {
        if (n == 0)
            return Error{ErrorCode::ParseError, "netplay: empty message"};
        switch (static_cast<Message>(d[0])) {
        case Message::Snapshot: {
            const Clock::time_point received = Clock::now();
            Result<Snapshot> s = detail::decodeJoinSnapshot(d, n, world);
            if (!s)
                return s.error();
            if (!stats.joined)
                stats.snapshotDecodeMs =
                    std::chrono::duration<double, std::milli>(Clock::now() - received).count();
            if (stats.joined)
                return resynced(std::move(*s), received);
            const double frame = static_cast<double>(s->world.frame);
            std::map<ObjectId, Track> fresh;
            detail::PlacementDecoder baselines;
            for (const ObjectPlacement& p : s->placements) {
                fresh[p.object].add(frame, p.objectToWorld);
                baselines.setBaseline(p.object, detail::quantize(p.objectToWorld));
            }
            const std::uint64_t hostSeed = s->world.seed, position = s->world.journalPosition;
            std::optional<Snapshot> kept;
            if (keepReplay)
                kept = *s;
            if (Status st = restoreSnapshot(world, std::move(*s)); !st)
                return st;
            joinedWith = std::move(kept);
            applied.clear();
            tracks = std::move(fresh);
            decoder = std::move(baselines);
            publishes =
                {}; // its datagrams start at seq 1; the snapshot's placements are no publish it had whole
            held.clear();
            seed = hostSeed;
            streamPosition = skipUntil = position; // the host's events go on from there
            stats.joined = true;
            stats.joinMs = std::chrono::duration<double, std::milli>(Clock::now() - connected).count();
            stats.snapshotLoadMs = std::chrono::duration<double, std::milli>(Clock::now() - received).count();
            return Status::ok();
        }
        case Message::Events: {
            if (!stats.joined) { // the snapshot is still on its way
                early.emplace_back(d, d + n);
                return Status::ok();
            }
            arrived.clear();
            if (!detail::decodeEvents(d, n, arrived))
                return Error{ErrorCode::ParseError,
                             "netplay: events message of " + std::to_string(n) + " bytes"};
            for (const detail::WireEvent& w : arrived)
                if (Status st = take(w); !st)
                    return st;
            return applyHeld();
        }
        case Message::Sync: {
            if (n != 25)
                return Error{ErrorCode::ParseError,
                             "netplay: sync message of " + std::to_string(n) + " bytes"};
            if (!stats.joined)
                return Status::ok();
            const SyncMsg m{detail::readU64(d + 1), detail::readU64(d + 9), detail::readU64(d + 17)};
            if (resyncing) {
                keptSync = m;
                keptSyncAt = streamPosition;
                return Status::ok();
            }
            return sync(m);
        }
        case Message::Placements:
            placements(d, n);
            return Status::ok();
        case Message::SnapshotChunk:
            return chunk(d, n);
        case Message::Frame: // read by noteHostFrame
            return Status::ok();
        default:
            return Error{ErrorCode::ParseError, "netplay: unknown message type " + std::to_string(d[0])};
        }
    }
};

NetClient::NetClient(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

NetClient::~NetClient() {
    if (impl_->host) {
        if (impl_->server)
            enet_peer_disconnect_now(impl_->server, detail::kGoodbye);
        enet_host_destroy(impl_->host);
    }
}

Result<std::unique_ptr<NetClient>> NetClient::connect(DestructionWorld& world,
                                                      const DestructionWorld::Config& config,
                                                      const std::string& address, std::uint16_t port) {
    if (!config.deterministic)
        return Error{ErrorCode::InvalidInput, "netplay needs a deterministic world"};
    detail::initialiseEnet();
    Result<ENetAddress> a = detail::loopbackAddress(address, port);
    if (!a)
        return a.error();
    auto impl = std::make_unique<Impl>(world, config);
    impl->host = enet_host_create(nullptr, 1, 2, 0, 0);
    if (!impl->host)
        return Error{ErrorCode::IoError, "cannot create an ENet client"};
    auto client = std::unique_ptr<NetClient>(new NetClient(std::move(impl)));
    Impl& im = *client->impl_;
    im.connected = Clock::now();
    im.server = enet_host_connect(im.host, &*a, 2, 0);
    if (!im.server)
        return Error{ErrorCode::IoError, "cannot connect to " + address + ":" + std::to_string(port)};
    enet_peer_timeout(im.server, 0, im.timeoutMs, im.timeoutMs); // no host answered within the timeout
    enet_host_flush(im.host); // the connect goes out; the Hello's hashes are taken while it travels
    const Clock::time_point hashing = Clock::now();
    (void)detail::encodeHello(im.world, false, &im.stateHashes);
    im.stats.helloMs = std::chrono::duration<double, std::milli>(Clock::now() - hashing).count();
    return client;
}

Status NetClient::service(int timeoutMs) {
    Impl& im = *impl_;
    // Everything that arrived, first: after an outage, how far ahead the host is decides whether to ask for
    // a resync before a sync makes it cut the backlog.
    std::vector<ENetEvent> events;
    if (im.server && im.server->state == ENET_PEER_STATE_CONNECTING)
        detail::retryEvery(im.server, detail::kHandshakeRetryMs);
    ENetEvent e;
    int r = enet_host_service(im.host, &e, static_cast<enet_uint32>(std::max(0, timeoutMs)));
    const Clock::time_point started = im.pumped = Clock::now();
    bool helloSent = true;
    for (; r > 0; r = enet_host_service(im.host, &e, 0)) {
        events.push_back(e);
        if (e.type == ENET_EVENT_TYPE_CONNECT) // before ENet runs again: see hello()
            helloSent = im.hello();
        if (e.type != ENET_EVENT_TYPE_RECEIVE)
            continue;
        const Clock::time_point now = Clock::now();
        if (now - im.heard > std::chrono::milliseconds(300) && im.server && im.stats.connected)
            detail::retransmitSoon(im.server); // the host was silent: an outage ended
        if (now - im.heard > kOutage && im.stats.joined)
            im.afterOutage = true;
        im.heard = now;
        im.noteHostFrame(e.packet->data, e.packet->dataLength);
    }
    Status status = im.checkLag();
    for (ENetEvent& ev : events) {
        if (ev.type == ENET_EVENT_TYPE_RECEIVE) {
            if (status)
                status = im.receive(ev.packet->data, ev.packet->dataLength);
            enet_packet_destroy(ev.packet); // after a failure, the rest is dropped
        } else if (!status) {
            continue;
        } else if (ev.type == ENET_EVENT_TYPE_CONNECT && !helloSent) {
            status = Error{ErrorCode::IoError, "netplay: cannot send the hello"};
        } else if (ev.type == ENET_EVENT_TYPE_DISCONNECT) {
            im.server = nullptr;
            if (!im.stats.connected)
                status = Error{ErrorCode::IoError,
                               "netplay: no host answered within " + std::to_string(im.timeoutMs) + " ms"};
            else
                status = Error{ErrorCode::IoError,
                               ev.data == detail::kGoodbye
                                   ? "netplay: the host closed the connection"
                                   : "netplay: the host stopped answering (no reply for " +
                                         std::to_string(im.timeoutMs) + " ms" + im.whereItStopped() + ")"};
        }
    }
    if (!status)
        return status;
    if (im.server) {
        if (im.server->packetsLost >= im.lostSeen)
            im.stats.reliableResent += im.server->packetsLost - im.lostSeen;
        im.lostSeen = im.server->packetsLost;
    }
    im.acknowledgeChunks();
    enet_host_flush(im.host); // its acks, without waiting for the next call
    if (const Clock::time_point now = Clock::now(); now - started > std::chrono::milliseconds(300))
        im.heard = std::max(im.heard, now); // it was not listening: what comes next is no outage
    if (r < 0)
        return Error{ErrorCode::IoError, "netplay: ENet service failed"};
    return Status::ok();
}

void NetClient::setTimeout(int ms) {
    impl_->timeoutMs = static_cast<enet_uint32>(std::max(1, ms));
    if (impl_->server && impl_->stats.connected)
        detail::configurePeer(impl_->server, impl_->timeoutMs);
    else if (impl_->server) // still connecting: nothing may be sent to the host yet
        enet_peer_timeout(impl_->server, 0, impl_->timeoutMs, impl_->timeoutMs);
}

void NetClient::setKeepReplay(bool keep) {
    impl_->keepReplay = keep;
    if (!keep)
        impl_->joinedWith.reset();
}

void NetClient::setResyncFrames(int frames) {
    impl_->resyncFrames = static_cast<std::uint64_t>(std::max(0, frames));
}

void NetClient::setOnOutcome(std::function<void(const FractureOutcome&)> callback) {
    impl_->onOutcome = std::move(callback);
}

std::optional<Frame> NetClient::placement(ObjectId object, double frame) const {
    auto it = impl_->tracks.find(object);
    if (it == impl_->tracks.end() || it->second.points.empty())
        return std::nullopt;
    return it->second.at(frame, &impl_->publishes);
}

Status NetClient::shoot(const Vec3& origin, const Vec3& velocity) {
    if (!impl_->server || !impl_->stats.connected)
        return Error{ErrorCode::IoError, "netplay: not connected"};
    std::vector<std::uint8_t> msg{static_cast<std::uint8_t>(Message::Shot)};
    for (const Vec3& v : {origin, velocity})
        for (int i = 0; i < 3; ++i)
            detail::appendF32(msg, static_cast<float>(v[i]));
    if (!detail::sendReliable(impl_->server, msg))
        return Error{ErrorCode::IoError, "netplay: cannot send a shot"};
    enet_host_flush(impl_->host);
    return Status::ok();
}

Status NetClient::writeReplay(const std::filesystem::path& snapshot,
                              const std::filesystem::path& journal) const {
    const Impl& im = *impl_;
    if (!im.keepReplay)
        return Error{ErrorCode::InvalidInput, "netplay: this client keeps no replay (setKeepReplay)"};
    if (!im.joinedWith)
        return Error{ErrorCode::InvalidInput, "netplay: no replay before the join"};
    if (Status st = saveSnapshot(snapshot, *im.joinedWith); !st)
        return st;
    JournalFile file;
    const WorldState& w = im.joinedWith->world;
    file.header.seed = w.seed;
    file.header.delayFrames = w.delayFrames;
    file.header.crumbleTriangles = w.crumbleTriangles;
    file.header.crumbleCells = w.crumbleCells;
    file.header.minPieceVolume = w.minPieceVolume;
    file.header.scene = snapshot.filename().string(); // what the events replay on
    file.events = im.applied;
    return writeJournal(journal, file);
}

std::optional<double> NetClient::placementFrame(ObjectId object) const {
    const auto it = impl_->tracks.find(object);
    if (it == impl_->tracks.end())
        return std::nullopt;
    return it->second.points.empty() ? std::nullopt : std::optional<double>(it->second.points.back().first);
}

const ClientStats& NetClient::stats() const {
    return impl_->stats;
}

} // namespace rubble::net
