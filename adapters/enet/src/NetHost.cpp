#include "rubble/enet/NetHost.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <vector>

#include "Events.hpp"
#include "JoinSnapshot.hpp"
#include "Placements.hpp"
#include "Protocol.hpp"
#include "rubble/persist/JournalFile.hpp"
#include "rubble/persist/Snapshot.hpp"

namespace rubble::net {

using detail::Message;

namespace {
constexpr double kChunksPerMs = 8; // snapshot chunks per client per ms (about 8.8 MB/s)
constexpr double kChunkBurst = 96; // the most sent to a client at once (the relay's buffers hold them)
constexpr double kPumpEveryMs = 2; // chunks go out at most this often
constexpr int kServiceSliceMs = 2; // how long service() waits at a time while a snapshot is on its way
constexpr std::uint64_t kReuseFrames = 30; // how old a snapshot a joining client may be given (frames)
constexpr auto kSilence = std::chrono::milliseconds(300); // a client not heard for this long is cut off
constexpr std::uint64_t kSilentSyncEvery = 30;            // frames between syncs to a client cut off
constexpr auto kResyncEvery = std::chrono::seconds(3);    // the least time between two resyncs of a client
} // namespace

struct NetHost::Impl {
    Impl(DestructionRuntime& r, const DestructionWorld::Config& c)
        : runtime(r), world(r.world()), config(c) {}
    DestructionRuntime& runtime;
    const DestructionWorld& world;
    DestructionWorld::Config config;
    ENetHost* host = nullptr;
    std::vector<JournalEvent> journal;             // events since base
    std::uint64_t base = 0;                        // journal position of journal.front()
    std::map<ENetPeer*, std::uint64_t> peers;      // journal position each client has been sent up to
    std::map<ENetPeer*, std::uint64_t> acked;      // the latest frame each client confirmed
    std::uint64_t lastSync = 0;                    // frame of the latest sync sent
    std::uint64_t lastSyncPosition = 0;            // the journal position it named
    std::map<std::uint64_t, std::uint64_t> hashes; // frame → geometry hash sent in its sync (recent ones)
    HostStats stats;
    std::function<std::vector<ObjectPlacement>()> placementSource;
    std::map<ENetPeer*, detail::PlacementEncoder> encoders; // per client: its baselines and priorities
    PlacementBudget placementBudget;
    std::map<ENetPeer*, detail::PlacementAllowance> allowances; // per client: its saved placement bytes

    std::map<ENetPeer*, std::chrono::steady_clock::time_point> heard;      // when each client was last heard
    std::map<ENetPeer*, std::chrono::steady_clock::time_point> lastResync; // its latest resync
    bool packSnapshots = false; // objects compressed one by one and kept (setSnapshotCache)
    enet_uint32 timeoutMs = detail::kPeerTimeoutMs; // a client silent this long is dropped
    std::map<ENetPeer*, std::uint64_t> joinOrder;   // 0 for the first to join
    std::function<void(const ShotRequest&)> shotHandler;
    ShotRules shotRules;
    std::map<ENetPeer*, double> shotTokens; // each client's bucket
    bool closing = false;                   // close() was called
    // A snapshot on its way to a client in datagram-sized chunks on channel 1, each sent again until the
    // client acknowledged it: no reliable window, so it goes at the pace below whatever the round trip.
    struct Transfer {
        std::uint32_t id = 0;
        std::vector<std::uint8_t> bytes; // the Snapshot message
        std::vector<bool> acked;
        std::vector<std::chrono::steady_clock::time_point> sent; // last sent (epoch: never)
        std::uint64_t frame = 0;                                 // the snapshot's frame
        std::chrono::steady_clock::time_point started;
        double credit = kChunkBurst; // chunks it may send now
        bool resync = false;         // to a joined client far behind (Message::Resync)
    };
    std::map<ENetPeer*, Transfer> transfers;
    std::chrono::steady_clock::time_point lastPump;
    std::uint32_t nextTransfer = 1;
    detail::StateHashes stateHashes; // objectStateHash of the world's objects, by version
    detail::PackedObjects packed;    // their compressed snapshot records, by version
    bool warmDue = false;            // a frame passed: objects may be new since the last warm-up
    std::vector<ObjectId> warmQueue; // objects to pack and hash while the game waits

    // Packs and hashes the objects new since the last time (so that a snapshot does not have to), until
    // `until`.
    void warm(std::chrono::steady_clock::time_point until) {
        if (!warmDue)
            return;
        if (warmQueue.empty()) {
            for (ObjectId id : world.objects()) {
                const ObjectState* o = world.object(id);
                const auto it = packed.find(id);
                // A remainder cut in place has no mesh hash until it is read: a snapshot takes it then.
                if ((it == packed.end() || it->second.version != o->version) && o->meshHash != 0)
                    warmQueue.push_back(id);
            }
            warmDue = !warmQueue.empty();
        }
        while (!warmQueue.empty() && std::chrono::steady_clock::now() < until) {
            if (const ObjectState* o = world.object(warmQueue.back())) {
                detail::packObject(*o, packed);
                detail::stateHash(*o, &stateHashes);
                ++stats.objectsWarmed;
            }
            warmQueue.pop_back();
        }
    }
    // The latest snapshot built: a client that joins within kReuseFrames, announcing the same objects, gets
    // it too, and the journal since it is kept for that client.
    struct Built {
        bool valid = false;
        bool resync = false; // without placements, for a joined client
        std::uint64_t frame = 0, position = 0;
        detail::KnownObjects referenced; // the objects it sends by id, with their state hashes
        bool reusable = false;           // referenced is all of them
        std::vector<std::uint8_t> msg;
        std::vector<ObjectPlacement> placements;
        detail::JoinSnapshotSize size;
    } built;
    std::uint64_t placementsFrame = 0;                                 // of the latest publishPlacements
    std::vector<std::pair<ObjectId, detail::Quantized>> placementsNow; // what it was given then

    // Sends each transfer's chunks that are new or unacknowledged for longer than a round trip, as many as
    // the time since the last pump allows (kChunksPerMs per client, at most kChunkBurst at once).
    void pump() {
        const auto now = std::chrono::steady_clock::now();
        const double ms = std::chrono::duration<double, std::milli>(now - lastPump).count();
        if (transfers.empty() || ms < kPumpEveryMs)
            return;
        lastPump = now;
        for (auto it = transfers.begin();
             it != transfers.end();) { // a client that never has it all is dropped
            if (now - it->second.started > std::chrono::seconds(30)) {
                enet_peer_disconnect(it->first, detail::kGoodbye);
                it = transfers.erase(it);
            } else {
                ++it;
            }
        }
        for (auto& [peer, t] : transfers) {
            const auto resend =
                std::chrono::milliseconds(10 + peer->roundTripTime + peer->roundTripTimeVariance);
            t.credit = std::min(kChunkBurst, t.credit + ms * kChunksPerMs);
            for (std::size_t i = 0; i < t.acked.size() && t.credit >= 1; ++i) {
                if (t.acked[i] || (t.sent[i].time_since_epoch().count() != 0 && now - t.sent[i] < resend))
                    continue;
                const std::size_t at = i * detail::kSnapshotChunk;
                const std::size_t len = std::min(detail::kSnapshotChunk, t.bytes.size() - at);
                std::vector<std::uint8_t> msg{static_cast<std::uint8_t>(Message::SnapshotChunk)};
                for (std::uint32_t v :
                     {t.id, static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(t.bytes.size())})
                    for (int b = 0; b < 4; ++b)
                        msg.push_back(static_cast<std::uint8_t>(v >> (8 * b)));
                msg.insert(msg.end(), t.bytes.begin() + static_cast<std::ptrdiff_t>(at),
                           t.bytes.begin() + static_cast<std::ptrdiff_t>(at + len));
                detail::sendUnreliable(peer, msg);
                t.sent[i] = now;
                t.credit -= 1;
                ++stats.snapshotChunksSent;
            }
        }
        enet_host_flush(host);
    }

    // Sends a client the placements that differ from what it acknowledged, within its allowance.
    void sendPlacements(ENetPeer* peer, long long legacy) {
        detail::PlacementEncoder& encoder = encoders[peer];
        const PlacementBudget& b = placementBudget;
        detail::PlacementAllowance& allowance =
            allowances.try_emplace(peer, b.mean, b.peak, b.reserve).first->second;
        std::size_t spent = 0;
        for (const std::vector<std::uint8_t>& msg :
             encoder.encode(placementsFrame, placementsNow, allowance.next())) {
            detail::sendUnreliable(peer, msg);
            spent += msg.size();
        }
        allowance.spent(spent);
        stats.placementBytes += static_cast<long long>(spent);
        stats.placementsDeferred += static_cast<long long>(encoder.deferred());
        stats.placementPublishesFull += encoder.deferred() > 0;
        stats.legacyPlacementBytes += legacy;
    }

    // The journal events from `position` to `end` (recorded by `frame`), if any; position becomes end.
    void sendEvents(ENetPeer* peer, std::uint64_t& position, std::uint64_t end, std::uint64_t frame) {
        if (position >= end)
            return;
        const auto n = static_cast<std::size_t>(end - position);
        const JournalEvent* first = journal.data() + (position - base);
        for (std::size_t k = 0; k < n; ++k)
            stats.impactEvents += first[k].kind == JournalEventKind::Impact;
        const std::vector<std::uint8_t> msg = detail::encodeEvents(frame, first, n);
        detail::sendReliable(peer, msg);
        stats.eventsSent += static_cast<long long>(n);
        stats.eventBytes += static_cast<long long>(msg.size());
        position = end;
    }

    // A sync: everything sent so far, applied up to `frame`, gives `hash`.
    void sendSync(ENetPeer* peer, std::uint64_t frame, std::uint64_t position, std::uint64_t hash) {
        std::vector<std::uint8_t> sync{static_cast<std::uint8_t>(Message::Sync)};
        detail::appendU64(sync, frame);
        detail::appendU64(sync, position);
        detail::appendU64(sync, hash);
        detail::sendReliable(peer, sync);
        ++stats.syncs;
    }

    // A client's SnapshotAck: the chunks it has are not sent again; once it has all, the transfer ends.
    void snapshotAck(ENetPeer* peer, const std::uint8_t* d, std::size_t n) {
        const auto t = transfers.find(peer);
        if (t == transfers.end() || n < 5 || detail::readU32(d + 1) != t->second.id ||
            n != 5 + (t->second.acked.size() + 7) / 8)
            return;
        bool all = true;
        for (std::size_t i = 0; i < t->second.acked.size(); ++i) {
            t->second.acked[i] = t->second.acked[i] || ((d[5 + i / 8] >> (i % 8)) & 1);
            all = all && t->second.acked[i];
        }
        if (!all)
            return;
        const std::uint64_t frame = t->second.frame;
        const bool resynced = t->second.resync;
        (resynced ? stats.resyncTransferMs : stats.snapshotTransferMs) +=
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t->second.started)
                .count();
        transfers.erase(t);
        if (lastSync >= frame && hashes.count(lastSync)) // the latest sync, which it was not sent
            sendSync(peer, lastSync, lastSyncPosition, hashes[lastSync]);
        if (!resynced && placementsFrame > frame) // the latest placements, newer than its snapshot's
            sendPlacements(peer, 0);
        enet_host_flush(host);
    }

    // A client's shot: fired through the handler if it passes the rules, else counted as refused.
    void shot(ENetPeer* peer, const std::uint8_t* d, std::size_t n) {
        const auto refuse = [this] { ++stats.shotsRefused; };
        if (n != 25 || !shotHandler || !peers.count(peer))
            return refuse();
        ShotRequest r;
        r.client = joinOrder.at(peer);
        r.origin = {detail::readF32(d + 1), detail::readF32(d + 5), detail::readF32(d + 9)};
        r.velocity = {detail::readF32(d + 13), detail::readF32(d + 17), detail::readF32(d + 21)};
        const double speed = length(r.velocity), distance = length(r.origin);
        if (!std::isfinite(speed) || !std::isfinite(distance) || speed <= 0 || speed > shotRules.maxSpeed ||
            distance > shotRules.maxDistance)
            return refuse();
        auto tokens = shotTokens.try_emplace(peer, shotRules.burst).first;
        if (tokens->second < 1)
            return refuse();
        tokens->second -= 1;
        ++stats.shotsAccepted;
        shotHandler(r);
    }

    // The latest snapshot for a client that has `known` (for a resync: without placements), built unless
    // the latest one built is recent, of the same kind, not older than journal position `since`, and names
    // by id only objects the client has in that state; false when it cannot be built.
    bool build(const detail::KnownObjects& known, bool resync, std::uint64_t since = 0) {
        const auto has = [&known](const std::pair<const ObjectId, std::uint64_t>& r) {
            const auto k = known.find(r.first);
            return k != known.end() && k->second == r.second;
        };
        if (built.valid && built.reusable && world.frame() <= built.frame + kReuseFrames &&
            built.resync == resync && built.position >= since &&
            std::all_of(built.referenced.begin(), built.referenced.end(), has))
            return true;
        const auto started = std::chrono::steady_clock::now();
        built = {};
        if (!resync)
            built.placements = placementSource ? placementSource() : std::vector<ObjectPlacement>{};
        detail::JoinCapture capture = detail::captureJoin(world, known, built.placements, &stateHashes);
        const double captureMs =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - started).count();
        built.msg = detail::encodeJoin(std::move(capture), &built.size, detail::SnapshotCodec::Zstd,
                                       packSnapshots ? &packed : nullptr);
        for (auto it = stateHashes.begin(); it != stateHashes.end();) // objects gone since
            it = world.object(it->first) ? std::next(it) : stateHashes.erase(it);
        for (auto it = packed.begin(); it != packed.end();)
            it = world.object(it->first) ? std::next(it) : packed.erase(it);
        if (built.msg.empty()) {
            built = {};
            return false;
        }
        built.valid = true;
        built.resync = resync;
        built.frame = world.frame();
        built.position = world.journalPosition();
        for (const auto& [id, hash] : known) // what it sent by id
            if (const auto h = stateHashes.find(id); h != stateHashes.end() && h->second.second == hash &&
                                                     world.object(id) &&
                                                     world.object(id)->version == h->second.first)
                built.referenced.emplace(id, hash);
        built.reusable = built.referenced.size() == built.size.referenced;
        ++stats.snapshotBuilds;
        stats.snapshotObjectsPacked += static_cast<long long>(built.size.packed);
        stats.snapshotBuildMs +=
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - started).count();
        stats.snapshotCaptureMs += captureMs;
        stats.snapshotEncodeMs += built.size.encodeMs;
        stats.snapshotCompressMs += built.size.compressMs;
        return true;
    }

    // Starts sending the latest snapshot built to a client.
    void startTransfer(ENetPeer* peer, bool resync) {
        Transfer& t = transfers[peer];
        t.id = nextTransfer++;
        t.resync = resync;
        t.bytes = built.msg;
        const std::size_t chunks = (t.bytes.size() + detail::kSnapshotChunk - 1) / detail::kSnapshotChunk;
        t.acked.assign(chunks, false);
        t.sent.assign(chunks, {});
        t.frame = built.frame;
        t.started = std::chrono::steady_clock::now();
    }

    // A client's Hello: it gets the snapshot, without the objects it has already (the latest one built, if
    // it is recent and for the same objects).
    void join(ENetPeer* peer, const detail::KnownObjects& known) {
        if (!build(known, false)) {
            enet_peer_disconnect(peer, detail::kGoodbye);
            return;
        }
        detail::PlacementEncoder& encoder = encoders[peer] = {};
        for (const ObjectPlacement& p : built.placements) // the client has these from its snapshot
            encoder.setBaseline(p.object, detail::quantize(p.objectToWorld));
        startTransfer(peer, false);
        std::uint64_t& position = peers[peer] = built.position; // it is sent the journal since its snapshot
        if (lastSync >= built.frame) // what the others were sent since, before any sync reaches it
            sendEvents(peer, position, lastSyncPosition, lastSync);
        joinOrder[peer] = static_cast<std::uint64_t>(stats.joins);
        ++stats.joins;
        stats.snapshotBytes += static_cast<long long>(built.size.wire);
        stats.snapshotRawBytes += static_cast<long long>(built.size.raw);
        stats.snapshotObjectsByReference += static_cast<long long>(built.size.referenced);
        enet_host_flush(host);
    }

    // A joined client's Resync: far behind, it gets the world as it is now without the objects it has in
    // the same state (the pieces of what it missed), keeps the events it was sent meanwhile by their
    // journal positions, and is sent no sync until it has it. Its placements go on as they were.
    void resync(ENetPeer* peer, const detail::KnownObjects& known, std::uint64_t position) {
        if (!build(known, true, position)) // not older than the client: it applied the events up to there
            return;                        // it goes on cutting the backlog itself
        startTransfer(peer, true);
        ++stats.resyncs;
        stats.resyncBytes += static_cast<long long>(built.size.wire);
        stats.resyncObjectsSent += static_cast<long long>(built.size.sent);
        enet_host_flush(host);
    }

    void receive(ENetPeer* peer, const ENetPacket* packet) {
        const auto now = std::chrono::steady_clock::now();
        if (auto h = heard.find(peer); h != heard.end() && now - h->second > kSilence) {
            detail::retransmitSoon(peer); // it was silent: an outage ended
            if (peers.count(peer) && !transfers.count(peer) && hashes.count(lastSync)) // the latest sync
                sendSync(peer, lastSync, lastSyncPosition, hashes[lastSync]);
        }
        heard[peer] = now;
        if (packet->dataLength == 0)
            return;
        const std::uint8_t* d = packet->data;
        if (packet->dataLength == 9 && d[0] == static_cast<std::uint8_t>(Message::PlacementAck)) {
            if (auto e = encoders.find(peer); e != encoders.end())
                e->second.acked(detail::readU32(d + 1), detail::readU32(d + 5));
            return;
        }
        if (d[0] == static_cast<std::uint8_t>(Message::Hello)) {
            detail::KnownObjects known;
            if (!closing && !peers.count(peer) && detail::decodeHello(d, packet->dataLength, known))
                join(peer, known);
            return;
        }
        if (d[0] == static_cast<std::uint8_t>(Message::Resync)) {
            detail::KnownObjects known;
            std::uint64_t position = 0;
            auto last = lastResync.find(peer);
            if (closing || !peers.count(peer) || transfers.count(peer) ||
                (last != lastResync.end() && now - last->second < kResyncEvery) ||
                !detail::decodeHello(d, packet->dataLength, known, true, &position))
                return;
            lastResync[peer] = now;
            return resync(peer, known, position);
        }
        if (d[0] == static_cast<std::uint8_t>(Message::SnapshotAck))
            return snapshotAck(peer, d, packet->dataLength);
        if (d[0] == static_cast<std::uint8_t>(Message::Shot))
            return shot(peer, d, packet->dataLength);
        if (packet->dataLength != 17 || d[0] != static_cast<std::uint8_t>(Message::Ack) || !peers.count(peer))
            return; // clients send nothing else
        ++stats.acks;
        const std::uint64_t frame = detail::readU64(d + 1), hash = detail::readU64(d + 9);
        acked[peer] = std::max(acked[peer], frame);
        if (auto it = hashes.find(frame); it != hashes.end() && it->second != hash)
            ++stats.mismatchedHashes;
    }
};

NetHost::NetHost(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

NetHost::~NetHost() {
    impl_->runtime.setJournalSink({});
    if (impl_->host) {
        for (auto& [peer, position] : impl_->peers)
            enet_peer_disconnect_now(peer, detail::kGoodbye);
        enet_host_destroy(impl_->host);
    }
}

Result<std::unique_ptr<NetHost>> NetHost::listen(DestructionRuntime& runtime,
                                                 const DestructionWorld::Config& config,
                                                 const std::string& address, std::uint16_t port,
                                                 int maxClients) {
    if (!config.deterministic)
        return Error{ErrorCode::InvalidInput,
                     "netplay needs a deterministic world (clients replay its journal)"};
    detail::initialiseEnet();
    Result<ENetAddress> a = detail::loopbackAddress(address, port);
    if (!a)
        return a.error();
    auto impl = std::make_unique<Impl>(runtime, config);
    impl->host = enet_host_create(&*a, static_cast<std::size_t>(maxClients), 2, 0, 0);
    if (!impl->host)
        return Error{ErrorCode::IoError, "cannot listen on " + address + ":" + std::to_string(port)};
    impl->base = runtime.world().journalPosition();
    Impl* raw = impl.get();
    runtime.setJournalSink([raw](const JournalEvent& e) { raw->journal.push_back(e); });
    return std::unique_ptr<NetHost>(new NetHost(std::move(impl)));
}

void NetHost::journaled(const JournalEvent& event) {
    impl_->journal.push_back(event);
}

std::uint16_t NetHost::port() const {
    return impl_->host->address.port;
}

void NetHost::publish() {
    Impl& im = *impl_;
    const std::uint64_t end = im.world.journalPosition();
    const std::uint64_t frame = im.world.frame(), hash = im.world.geometryHash();
    im.hashes[frame] = hash;
    for (auto& [peer, tokens] : im.shotTokens) // the shot buckets refill per frame (60 Hz)
        tokens = std::min(im.shotRules.burst, tokens + im.shotRules.perSecond / 60);
    im.lastSync = frame;
    im.lastSyncPosition = end;
    im.warmDue = im.packSnapshots;
    while (im.hashes.size() > 4096)
        im.hashes.erase(im.hashes.begin());
    for (auto& [peer, position] : im.peers) {
        im.sendEvents(peer, position, end, frame);
        // Not while its snapshot is on its way (it keeps the events meanwhile); to a client not heard
        // lately (an outage), only every kSilentSyncEvery frames: the latest sync is all it needs.
        const auto h = im.heard.find(peer);
        const bool silent = h != im.heard.end() && std::chrono::steady_clock::now() - h->second > kSilence;
        if (!im.transfers.count(peer) && (!silent || frame % kSilentSyncEvery == 0))
            im.sendSync(peer, frame, end, hash);
        if (silent) { // unreliable, so that after an outage it arrives before the backlog
            std::vector<std::uint8_t> hint{static_cast<std::uint8_t>(Message::Frame)};
            detail::appendU64(hint, frame);
            detail::sendUnreliable(peer, hint);
        }
    }
    // Every client has been sent everything; a client that joins later gets a snapshot, and the events
    // since the latest one are kept while it may be reused.
    if (im.built.valid && frame > im.built.frame + kReuseFrames)
        im.built = {};
    const std::uint64_t keep = im.built.valid ? std::min(im.built.position, end) : end;
    im.journal.erase(im.journal.begin(), im.journal.begin() + static_cast<std::ptrdiff_t>(keep - im.base));
    im.base = keep;
    enet_host_flush(im.host);
    im.pump();
}

void NetHost::publishPlacements(const std::vector<ObjectPlacement>& placements) {
    Impl& im = *impl_;
    im.placementsNow.clear();
    im.placementsNow.reserve(placements.size());
    std::size_t dynamic = 0;
    for (const ObjectPlacement& p : placements) {
        im.placementsNow.emplace_back(p.object, detail::quantize(p.objectToWorld));
        dynamic += p.motion == BodyMotionState::Dynamic;
    }
    im.placementsFrame = im.world.frame();
    // The previous protocol: 13 + 32 n bytes per 37 dynamic bodies, every time.
    const auto legacy = static_cast<long long>((dynamic + 36) / 37 * 13 + dynamic * 32);
    for (auto& [peer, position] : im.peers) // one whose join snapshot is on its way gets them once it is in
        if (const auto t = im.transfers.find(peer); t == im.transfers.end() || t->second.resync)
            im.sendPlacements(peer, legacy);
    enet_host_flush(im.host);
}

void NetHost::setPlacementBudget(const PlacementBudget& budget) {
    impl_->placementBudget = budget;
    impl_->allowances.clear();
}

bool NetHost::finish(int timeoutMs) {
    Impl& im = *impl_;
    const auto confirmed = [&im] {
        for (const auto& [peer, position] : im.peers)
            if (auto a = im.acked.find(peer); a == im.acked.end() || a->second < im.lastSync)
                return false;
        return true;
    };
    const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeoutMs);
    while (!confirmed() && std::chrono::steady_clock::now() < end)
        service(5);
    return confirmed();
}

bool NetHost::close(int timeoutMs) {
    Impl& im = *impl_;
    im.closing = true;
    for (ENetPeer* peer = im.host->peers; peer < im.host->peers + im.host->peerCount; ++peer)
        if (peer->state != ENET_PEER_STATE_DISCONNECTED)
            enet_peer_disconnect(peer, detail::kGoodbye);
    const auto connected = [&im] {
        for (ENetPeer* peer = im.host->peers; peer < im.host->peers + im.host->peerCount; ++peer)
            if (peer->state != ENET_PEER_STATE_DISCONNECTED)
                return true;
        return false;
    };
    const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeoutMs);
    while (connected() && std::chrono::steady_clock::now() < end)
        service(5);
    return !connected();
}

void NetHost::setPlacementSource(std::function<std::vector<ObjectPlacement>()> source) {
    impl_->placementSource = std::move(source);
}

void NetHost::service(int timeoutMs) {
    Impl& im = *impl_;
    const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(std::max(0, timeoutMs));
    for (;;) {
        if (end - std::chrono::steady_clock::now() > std::chrono::milliseconds(1)) // time to spare
            im.warm(std::min(end - std::chrono::milliseconds(1),
                             std::chrono::steady_clock::now() + std::chrono::milliseconds(kServiceSliceMs)));
        const auto left =
            std::chrono::duration_cast<std::chrono::milliseconds>(end - std::chrono::steady_clock::now())
                .count();
        // While a snapshot is on its way, wake often enough to pace its chunks.
        const auto wait = static_cast<enet_uint32>(
            std::max<long long>(0, im.transfers.empty() ? left : std::min<long long>(left, kServiceSliceMs)));
        for (std::size_t i = 0; i < im.host->peerCount; ++i) // clients whose connection is being made
            if (im.host->peers[i].state == ENET_PEER_STATE_ACKNOWLEDGING_CONNECT)
                detail::retryEvery(&im.host->peers[i], detail::kHandshakeRetryMs);
        ENetEvent e;
        for (int r = enet_host_service(im.host, &e, wait); r > 0; r = enet_host_service(im.host, &e, 0)) {
            switch (e.type) {
            case ENET_EVENT_TYPE_CONNECT: // it joins with its Hello
                detail::configurePeer(e.peer, im.timeoutMs);
                if (im.closing)
                    enet_peer_disconnect(e.peer, detail::kGoodbye);
                break;
            case ENET_EVENT_TYPE_RECEIVE:
                im.receive(e.peer, e.packet);
                enet_packet_destroy(e.packet);
                break;
            case ENET_EVENT_TYPE_DISCONNECT:
                im.peers.erase(e.peer);
                im.acked.erase(e.peer);
                im.encoders.erase(e.peer);
                im.allowances.erase(e.peer);
                im.heard.erase(e.peer);
                im.lastResync.erase(e.peer);
                im.joinOrder.erase(e.peer);
                im.transfers.erase(e.peer);
                im.shotTokens.erase(e.peer);
                break;
            default:
                break;
            }
        }
        im.pump();
        if (std::chrono::steady_clock::now() >= end)
            break;
    }
    im.stats.clients = static_cast<int>(im.peers.size());
}

void NetHost::setTimeout(int ms) {
    impl_->timeoutMs = static_cast<enet_uint32>(std::max(1, ms));
    for (auto& [peer, position] : impl_->peers)
        detail::configurePeer(peer, impl_->timeoutMs);
}

void NetHost::setSnapshotCache(bool on) {
    impl_->packSnapshots = on;
    impl_->packed.clear();
    impl_->warmQueue.clear();
    impl_->warmDue = false;
}

void NetHost::setShotHandler(std::function<void(const ShotRequest&)> handler, ShotRules rules) {
    impl_->shotHandler = std::move(handler);
    impl_->shotRules = rules;
}

std::vector<std::uint64_t> NetHost::confirmedFrames() const {
    std::vector<std::pair<std::uint64_t, std::uint64_t>> order; // (join order, frame)
    for (const auto& [peer, position] : impl_->peers) {
        const auto a = impl_->acked.find(peer);
        order.emplace_back(impl_->joinOrder.at(peer), a == impl_->acked.end() ? 0 : a->second);
    }
    std::sort(order.begin(), order.end());
    std::vector<std::uint64_t> frames;
    for (const auto& [k, frame] : order)
        frames.push_back(frame);
    return frames;
}

const HostStats& NetHost::stats() const {
    return impl_->stats;
}

} // namespace rubble::net
