#include "JoinSnapshot.hpp"

#include <zlib.h>
#include <zstd.h>

#include <algorithm>
#include <chrono>
#include <string>

#include "Placements.hpp"
#include "Protocol.hpp"
#include "persist/SnapshotInPlace.hpp"

namespace rubble::net::detail {

namespace {

// The largest snapshot a client inflates (bytes).
constexpr std::uint64_t kMaxRaw = std::uint64_t{1} << 30;

Error malformed(const std::string& what) {
    return Error{ErrorCode::ParseError, "netplay: snapshot message: " + what};
}

// Compresses bytes as one Zstandard frame (level 3) onto out; false when it failed (out of memory).
bool appendZstd(std::vector<std::uint8_t>& out, const std::uint8_t* data, std::size_t size) {
    const std::size_t at = out.size();
    out.resize(at + ZSTD_compressBound(size));
    const std::size_t packed = ZSTD_compress(out.data() + at, out.size() - at, data, size, 3);
    if (ZSTD_isError(packed))
        return false;
    out.resize(at + packed);
    return true;
}

// Where the object records begin in a snapshot's bytes (after the header and the object count), and the
// bytes after them in a snapshot without work, placements or structure.
struct Layout {
    std::size_t records = 0, emptyTail = 0;
};
const Layout& layout() {
    static const Layout l = [] {
        Snapshot none, one;
        one.world.objects.emplace_back();
        const std::vector<std::uint8_t> a = encodeSnapshot(none), b = encodeSnapshot(one);
        std::size_t i = 0;
        while (i < a.size() && a[i] == b[i])
            ++i;
        // The first byte that differs is the object count's lowest (0 against 1).
        return Layout{i + 4, a.size() - (i + 4)};
    }();
    return l;
}

std::uint32_t crcOf(std::uint32_t crc, const std::uint8_t* data, std::size_t size) {
    return static_cast<std::uint32_t>(::crc32(crc, data, static_cast<uInt>(size)));
}

} // namespace

bool packObject(const ObjectState& object, PackedObjects& cache) {
    const auto it = cache.find(object.id);
    if (it != cache.end() && it->second.version == object.version)
        return true;
    Snapshot one;
    one.world.objects.push_back(object);
    const std::vector<std::uint8_t> bytes = encodeSnapshot(one);
    const Layout& l = layout();
    PackedObject p;
    p.version = object.version;
    p.raw = bytes.size() - l.records - l.emptyTail;
    p.crc = crcOf(0, bytes.data() + l.records, p.raw);
    if (!appendZstd(p.zstd, bytes.data() + l.records, p.raw))
        return false;
    cache[object.id] = std::move(p);
    return true;
}

std::uint64_t stateHash(const ObjectState& object, StateHashes* cache) {
    if (!cache)
        return objectStateHash(object);
    const auto it = cache->find(object.id);
    if (it != cache->end() && it->second.first == object.version)
        return it->second.second;
    const std::uint64_t h = objectStateHash(object);
    (*cache)[object.id] = {object.version, h};
    return h;
}

std::vector<std::uint8_t> encodeHello(const DestructionWorld& world, bool resync, StateHashes* cache) {
    std::vector<std::uint8_t> out{static_cast<std::uint8_t>(resync ? Message::Resync : Message::Hello)};
    if (resync)
        putVarint(out, world.journalPosition());
    const std::vector<ObjectId> ids = world.objects();
    putVarint(out, ids.size());
    ObjectId previous = 0;
    for (ObjectId id : ids) {
        putVarint(out, id - previous); // ascending
        previous = id;
        appendU64(out, stateHash(*world.object(id), cache));
    }
    return out;
}

bool decodeHello(const std::uint8_t* data, std::size_t size, KnownObjects& out, bool resync,
                 std::uint64_t* position) {
    if (size == 0 || data[0] != static_cast<std::uint8_t>(resync ? Message::Resync : Message::Hello))
        return false;
    const std::uint8_t *p = data + 1, *end = data + size;
    std::uint64_t at = 0, n = 0;
    if (resync && !getVarint(p, end, at))
        return false;
    if (!getVarint(p, end, n) || n > size)
        return false;
    KnownObjects known;
    std::uint64_t id = 0;
    for (std::uint64_t i = 0; i < n; ++i) {
        std::uint64_t step = 0;
        if (!getVarint(p, end, step) || end - p < 8 || (i > 0 && step == 0) || id + step > 0xffffffffULL)
            return false;
        id += step;
        known[static_cast<ObjectId>(id)] = readU64(p);
        p += 8;
    }
    if (p != end)
        return false;
    out = std::move(known);
    if (position)
        *position = at;
    return true;
}

namespace {

// Whether a client that has `known` has this object in the same state.
bool has(const KnownObjects& known, const ObjectState& o, StateHashes* cache) {
    const auto k = known.find(o.id);
    return k != known.end() && k->second == stateHash(o, cache);
}

double msSince(std::chrono::steady_clock::time_point t) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

} // namespace

JoinCapture captureJoin(const DestructionWorld& world, const KnownObjects& known,
                        std::vector<ObjectPlacement> placements, StateHashes* cache) {
    rubble::detail::StateInPlace in = rubble::detail::captureInPlace(world);
    JoinCapture c;
    c.rest.world = std::move(in.rest);
    c.rest.placements = std::move(placements);
    for (const ObjectState* o : in.objects) {
        if (has(known, *o, cache))
            c.byId.push_back(o->id);
        else
            c.sent.push_back(o);
    }
    return c;
}

std::vector<std::uint8_t> encodeJoinSnapshot(Snapshot snapshot, const KnownObjects& known,
                                             JoinSnapshotSize* size, SnapshotCodec codec, StateHashes* cache,
                                             PackedObjects* packed) {
    JoinCapture c;
    c.owned = std::move(snapshot.world.objects);
    c.rest = std::move(snapshot);
    c.rest.world.objects.clear();
    for (const ObjectState& o : c.owned) {
        if (has(known, o, cache))
            c.byId.push_back(o.id);
        else
            c.sent.push_back(&o);
    }
    return encodeJoin(std::move(c), size, codec, packed); // the vector moves, its objects stay
}

std::vector<std::uint8_t> encodeJoin(JoinCapture capture, JoinSnapshotSize* size, SnapshotCodec codec,
                                     PackedObjects* packed) {
    const auto started = std::chrono::steady_clock::now();
    const Snapshot& snapshot = capture.rest;
    const std::vector<ObjectId>& referenced = capture.byId;
    const std::vector<const ObjectState*>& sent = capture.sent;
    std::vector<std::uint8_t> out{static_cast<std::uint8_t>(Message::Snapshot)};
    putVarint(out, referenced.size());
    ObjectId previous = 0;
    for (ObjectId id : referenced) {
        putVarint(out, id - previous);
        previous = id;
    }
    out.push_back(static_cast<std::uint8_t>(codec));
    if (codec == SnapshotCodec::Zstd && packed) {
        // The snapshot without objects gives the header and the rest; the records come from the cache.
        std::size_t fresh = 0, records = 0;
        std::uint32_t crc = 0;
        for (const ObjectState* o : sent) {
            const auto it = packed->find(o->id);
            if (it == packed->end() || it->second.version != o->version) {
                if (!packObject(*o, *packed))
                    return {};
                ++fresh;
            }
        }
        std::vector<std::uint8_t> shell = encodeSnapshot(snapshot);
        const std::size_t head = layout().records;
        const auto count = static_cast<std::uint32_t>(sent.size());
        for (int b = 0; b < 4; ++b)
            shell[head - 4 + static_cast<std::size_t>(b)] = static_cast<std::uint8_t>(count >> (8 * b));
        crc = crcOf(0, shell.data(), head);
        for (const ObjectState* o : sent) {
            const PackedObject& p = packed->at(o->id);
            crc = static_cast<std::uint32_t>(
                ::crc32_combine(crc, p.crc, static_cast<z_off_t>(p.raw))); // as if its bytes followed
            records += p.raw;
        }
        crc = crcOf(crc, shell.data() + head, shell.size() - head - 4);
        for (int b = 0; b < 4; ++b)
            shell[shell.size() - 4 + static_cast<std::size_t>(b)] = static_cast<std::uint8_t>(crc >> (8 * b));
        const std::size_t raw = shell.size() + records;
        putVarint(out, raw);
        if (!appendZstd(out, shell.data(), head))
            return {};
        for (const ObjectState* o : sent) {
            const std::vector<std::uint8_t>& z = packed->at(o->id).zstd;
            out.insert(out.end(), z.begin(), z.end());
        }
        if (!appendZstd(out, shell.data() + head, shell.size() - head))
            return {};
        if (size)
            *size = {raw, out.size(), referenced.size(), sent.size(), fresh, 0, msSince(started)};
        return out;
    }
    const std::vector<std::uint8_t> raw = rubble::detail::encodeSnapshotWith(snapshot, sent);
    const double encodeMs = msSince(started);
    const auto compressing = std::chrono::steady_clock::now();
    putVarint(out, raw.size());
    const std::size_t at = out.size();
    if (codec == SnapshotCodec::Zstd) {
        if (!appendZstd(out, raw.data(), raw.size()))
            return {}; // only when out of memory
    } else {
        uLongf deflated = compressBound(static_cast<uLong>(raw.size()));
        out.resize(at + deflated);
        if (compress2(out.data() + at, &deflated, raw.data(), static_cast<uLong>(raw.size()), 1) != Z_OK)
            return {}; // only when out of memory
        out.resize(at + deflated);
    }
    if (size)
        *size = {raw.size(),  out.size(), referenced.size(),   sent.size(),
                 sent.size(), encodeMs,   msSince(compressing)};
    return out;
}

Result<Snapshot> decodeJoinSnapshot(const std::uint8_t* data, std::size_t size,
                                    const DestructionWorld& world) {
    if (size == 0 || data[0] != static_cast<std::uint8_t>(Message::Snapshot))
        return malformed("not a snapshot");
    const std::uint8_t *p = data + 1, *end = data + size;
    std::uint64_t n = 0;
    if (!getVarint(p, end, n) || n > size)
        return malformed("bad count of objects sent by id");
    std::vector<ObjectState> referenced;
    std::uint64_t id = 0;
    for (std::uint64_t i = 0; i < n; ++i) {
        std::uint64_t step = 0;
        if (!getVarint(p, end, step) || (i > 0 && step == 0) || id + step > 0xffffffffULL)
            return malformed("object id " + std::to_string(i) + " is malformed or not ascending");
        id += step;
        const ObjectState* o = world.object(static_cast<ObjectId>(id));
        if (!o)
            return malformed("object " + std::to_string(id) +
                             " is sent by id, and this world does not have it");
        referenced.push_back(*o);
    }
    if (p == end || *p > static_cast<std::uint8_t>(SnapshotCodec::Zstd))
        return malformed("unknown codec");
    const auto codec = static_cast<SnapshotCodec>(*p++);
    std::uint64_t rawSize = 0;
    if (!getVarint(p, end, rawSize) || rawSize > kMaxRaw ||
        rawSize > 1032 * static_cast<std::uint64_t>(end - p) +
                      64) // deflate's largest ratio (snapshots pack < 20:1)
        return malformed("bad or too large inflated size");
    std::vector<std::uint8_t> raw(static_cast<std::size_t>(rawSize));
    const auto packed = static_cast<std::size_t>(end - p);
    bool whole = false;
    if (codec == SnapshotCodec::Zstd) {
        const std::size_t got = ZSTD_decompress(raw.data(), raw.size(), p, packed);
        whole = !ZSTD_isError(got) && got == rawSize;
    } else {
        uLongf got = static_cast<uLongf>(rawSize);
        whole = uncompress(raw.data(), &got, p, static_cast<uLong>(packed)) == Z_OK && got == rawSize;
    }
    if (!whole)
        return malformed("the compressed snapshot is corrupted or not " + std::to_string(rawSize) + " bytes");
    Result<Snapshot> s = decodeSnapshot(raw.data(), raw.size(), "host snapshot");
    if (!s)
        return s;
    std::vector<ObjectState>& objects = s->world.objects;
    for (ObjectState& o : referenced)
        objects.push_back(std::move(o));
    std::sort(objects.begin(), objects.end(),
              [](const ObjectState& a, const ObjectState& b) { return a.id < b.id; });
    for (std::size_t i = 1; i < objects.size(); ++i)
        if (objects[i].id == objects[i - 1].id)
            return malformed("object " + std::to_string(objects[i].id) + " is sent twice");
    return s;
}

} // namespace rubble::net::detail
