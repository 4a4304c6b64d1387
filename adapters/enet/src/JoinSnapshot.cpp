#include "JoinSnapshot.hpp"

#include <zlib.h>
#include <zstd.h>

#include <algorithm>
#include <string>

#include "Placements.hpp"
#include "Protocol.hpp"

namespace rubble::net::detail {

namespace {

// The largest snapshot a client inflates (bytes).
constexpr std::uint64_t kMaxRaw = std::uint64_t{1} << 30;

Error malformed(const std::string& what) {
    return Error{ErrorCode::ParseError, "netplay: snapshot message: " + what};
}

} // namespace

std::vector<std::uint8_t> encodeHello(const DestructionWorld& world) {
    std::vector<std::uint8_t> out{static_cast<std::uint8_t>(Message::Hello)};
    const std::vector<ObjectId> ids = world.objects();
    putVarint(out, ids.size());
    ObjectId previous = 0;
    for (ObjectId id : ids) {
        putVarint(out, id - previous); // ascending
        previous = id;
        appendU64(out, objectStateHash(*world.object(id)));
    }
    return out;
}

bool decodeHello(const std::uint8_t* data, std::size_t size, KnownObjects& out) {
    if (size == 0 || data[0] != static_cast<std::uint8_t>(Message::Hello))
        return false;
    const std::uint8_t *p = data + 1, *end = data + size;
    std::uint64_t n = 0;
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
    return true;
}

std::vector<std::uint8_t> encodeJoinSnapshot(Snapshot snapshot, const KnownObjects& known,
                                             JoinSnapshotSize* size, SnapshotCodec codec) {
    std::vector<ObjectId> referenced;
    std::vector<ObjectState> sent;
    for (ObjectState& o : snapshot.world.objects) {
        const auto k = known.find(o.id);
        if (k != known.end() && k->second == objectStateHash(o))
            referenced.push_back(o.id);
        else
            sent.push_back(std::move(o));
    }
    snapshot.world.objects = std::move(sent);
    const std::vector<std::uint8_t> raw = encodeSnapshot(snapshot);
    std::vector<std::uint8_t> out{static_cast<std::uint8_t>(Message::Snapshot)};
    putVarint(out, referenced.size());
    ObjectId previous = 0;
    for (ObjectId id : referenced) {
        putVarint(out, id - previous);
        previous = id;
    }
    out.push_back(static_cast<std::uint8_t>(codec));
    putVarint(out, raw.size());
    const std::size_t at = out.size();
    if (codec == SnapshotCodec::Zstd) {
        out.resize(at + ZSTD_compressBound(raw.size()));
        const std::size_t packed = ZSTD_compress(out.data() + at, out.size() - at, raw.data(), raw.size(), 3);
        if (ZSTD_isError(packed))
            return {}; // only when out of memory
        out.resize(at + packed);
    } else {
        uLongf packed = compressBound(static_cast<uLong>(raw.size()));
        out.resize(at + packed);
        if (compress2(out.data() + at, &packed, raw.data(), static_cast<uLong>(raw.size()), 1) != Z_OK)
            return {}; // only when out of memory
        out.resize(at + packed);
    }
    if (size)
        *size = {raw.size(), out.size(), referenced.size()};
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
