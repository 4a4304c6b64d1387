#include "rubble/persist/JournalFile.hpp"

#include <cmath>

#include "persist/Bytes.hpp"
#include "rubble/runtime/JournalPlayer.hpp"

namespace rubble {
namespace {

constexpr std::uint8_t kMagic[4] = {'R', 'B', 'J', 'L'};
constexpr std::uint16_t kVersion = 1;

void writeEvent(persist::ByteWriter& w, const JournalEvent& e) {
    w.u8(static_cast<std::uint8_t>(e.kind));
    w.u8(e.pattern);
    w.u16(e.cells);
    w.u32(e.object);
    w.u32(e.tick);
    for (float x : e.point)
        w.f32(x);
    for (float x : e.normal)
        w.f32(x);
    w.f32(e.impulse);
    w.u64(e.seed);
}

JournalEvent readEvent(persist::ByteReader& r) {
    const std::size_t start = r.offset();
    JournalEvent e;
    const std::uint8_t kind = r.u8("kind");
    if (r.ok() && kind != 1 && kind != 2)
        r.fail(start, "kind", "unknown event kind " + std::to_string(kind));
    e.kind = static_cast<JournalEventKind>(kind);
    e.pattern = r.u8("pattern");
    if (r.ok() && !validPatternByte(e.pattern))
        r.fail(start + 1, "pattern", "unknown pattern " + std::to_string(e.pattern));
    e.cells = r.u16("cells");
    e.object = r.u32("object");
    e.tick = r.u32("tick");
    const char* names[7] = {"point.x", "point.y", "point.z", "normal.x", "normal.y", "normal.z", "impulse"};
    float* fields[7] = {&e.point[0],  &e.point[1],  &e.point[2], &e.normal[0],
                        &e.normal[1], &e.normal[2], &e.impulse};
    for (int i = 0; i < 7; ++i) {
        const std::size_t at = r.offset();
        *fields[i] = r.f32(names[i]);
        if (r.ok() && !std::isfinite(*fields[i]))
            r.fail(at, names[i], "is not finite");
    }
    e.seed = r.u64("seed");
    return e;
}

} // namespace

std::array<std::uint8_t, kJournalEventBytes> encodeJournalEvent(const JournalEvent& event) {
    persist::ByteWriter w;
    writeEvent(w, event);
    std::array<std::uint8_t, kJournalEventBytes> out{};
    std::copy(w.data().begin(), w.data().end(), out.begin());
    return out;
}

Result<JournalEvent> decodeJournalEvent(const std::uint8_t* bytes, std::size_t offset) {
    persist::ByteReader r(bytes, kJournalEventBytes, "journal event", offset);
    JournalEvent e = readEvent(r);
    if (!r.ok())
        return Error{ErrorCode::ParseError, r.error()};
    return e;
}

JournalHeader journalHeaderOf(const DestructionWorld::Config& c, std::string scene) {
    JournalHeader h;
    h.seed = c.seed;
    h.delayFrames = c.delayFrames;
    h.crumbleTriangles = c.crumbleTriangles;
    h.crumbleCells = c.crumbleCells;
    h.minPieceVolume = c.minPieceVolume;
    h.scene = std::move(scene);
    return h;
}

Status checkJournalHeader(const JournalHeader& h, const DestructionWorld::Config& c) {
    auto differs = [](const std::string& field, const std::string& journal, const std::string& world) {
        return Error{ErrorCode::InvalidInput,
                     "journal header field " + field + " is " + journal + ", the world's is " + world};
    };
    if (!c.deterministic)
        return Error{ErrorCode::InvalidInput, "a journal replays only on a deterministic world"};
    if (h.seed != c.seed)
        return differs("seed", std::to_string(h.seed), std::to_string(c.seed));
    if (h.delayFrames != c.delayFrames)
        return differs("delayFrames", std::to_string(h.delayFrames), std::to_string(c.delayFrames));
    if (h.crumbleTriangles != c.crumbleTriangles)
        return differs("crumbleTriangles", std::to_string(h.crumbleTriangles),
                       std::to_string(c.crumbleTriangles));
    if (h.crumbleCells != c.crumbleCells)
        return differs("crumbleCells", std::to_string(h.crumbleCells), std::to_string(c.crumbleCells));
    if (h.minPieceVolume != c.minPieceVolume)
        return differs("minPieceVolume", std::to_string(h.minPieceVolume), std::to_string(c.minPieceVolume));
    return Status::ok();
}

std::vector<std::uint8_t> encodeJournal(const JournalFile& j) {
    persist::ByteWriter w;
    w.bytes(kMagic, 4);
    w.u16(kVersion);
    w.u16(static_cast<std::uint16_t>(kJournalEventBytes));
    w.u64(j.header.seed);
    w.i32(j.header.delayFrames);
    w.u64(j.header.crumbleTriangles);
    w.i32(j.header.crumbleCells);
    w.f64(j.header.minPieceVolume);
    w.u32(static_cast<std::uint32_t>(j.header.scene.size()));
    w.bytes(j.header.scene.data(), j.header.scene.size());
    w.u32(static_cast<std::uint32_t>(j.events.size()));
    for (const JournalEvent& e : j.events)
        writeEvent(w, e);
    w.u32(persist::crc32(w.data().data(), w.size()));
    return std::move(w.data());
}

Result<JournalFile> decodeJournal(const std::uint8_t* data, std::size_t size, const std::string& source) {
    persist::ByteReader r(data, size, source);
    auto bad = [&] { return Error{ErrorCode::ParseError, r.error()}; };
    std::uint8_t magic[4];
    for (auto& m : magic)
        m = r.u8("magic");
    if (r.ok() && !std::equal(magic, magic + 4, kMagic))
        r.fail(0, "magic", "not a Rubble journal (expected RBJL)");
    const std::uint16_t version = r.u16("version");
    if (r.ok() && version != kVersion)
        r.fail(4, "version",
               "version " + std::to_string(version) + " is not supported (this build reads " +
                   std::to_string(kVersion) + ")");
    const std::uint16_t eventBytes = r.u16("eventBytes");
    if (r.ok() && eventBytes != kJournalEventBytes)
        r.fail(6, "eventBytes", "is " + std::to_string(eventBytes) + ", expected 48");
    if (!r.ok())
        return bad();
    // The checksum covers everything before it: check it first, so that a corrupted file is named as such.
    if (size < 4 + 4) {
        r.fail(size, "crc32", "file too short");
        return bad();
    }
    persist::ByteReader tail(data + size - 4, 4, source);
    const std::uint32_t stored = tail.u32("crc32");
    if (stored != persist::crc32(data, size - 4)) {
        r.fail(size - 4, "crc32", "checksum mismatch (the file is corrupted or truncated)");
        return bad();
    }
    JournalFile j;
    j.header.seed = r.u64("seed");
    j.header.delayFrames = r.i32("delayFrames");
    j.header.crumbleTriangles = r.u64("crumbleTriangles");
    j.header.crumbleCells = r.i32("crumbleCells");
    j.header.minPieceVolume = r.finite("minPieceVolume");
    const std::uint32_t nameLength = r.count("scene.length", 1);
    if (r.ok())
        j.header.scene.assign(reinterpret_cast<const char*>(data + r.offset()), nameLength);
    for (std::uint32_t i = 0; i < nameLength && r.ok(); ++i)
        (void)r.u8("scene");
    const std::uint32_t n = r.count("events.count", kJournalEventBytes);
    j.events.reserve(n);
    for (std::uint32_t i = 0; i < n && r.ok(); ++i) {
        const std::size_t at = r.offset();
        const JournalEvent e = readEvent(r);
        if (r.ok() && !j.events.empty()) {
            // In tick order, without a gap the replay would step through for hours.
            const std::uint64_t previous = j.events.back().tick;
            if (e.tick < previous)
                r.fail(at + 8, "tick",
                       "is " + std::to_string(e.tick) + ", before the previous event's tick " +
                           std::to_string(previous) + " (events are in tick order)");
            else if (e.tick - previous > kMaxJournalTickGap)
                r.fail(at + 8, "tick",
                       "is " + std::to_string(e.tick) + ", " + std::to_string(e.tick - previous) +
                           " frames after the previous event's tick " + std::to_string(previous) +
                           ", more than the limit of " + std::to_string(kMaxJournalTickGap) + " frames");
        }
        j.events.push_back(e);
    }
    if (r.ok() && r.remaining() != 4)
        r.fail(r.offset(), "crc32",
               std::to_string(r.remaining() - 4) + " unexpected bytes before the checksum");
    if (!r.ok())
        return bad();
    return j;
}

Status writeJournal(const std::filesystem::path& path, const JournalFile& journal) {
    return writeFileAtomic(path, encodeJournal(journal));
}

Result<JournalFile> readJournal(const std::filesystem::path& path) {
    Result<std::vector<std::uint8_t>> bytes = readFileBinary(path);
    if (!bytes)
        return bytes.error();
    return decodeJournal(bytes->data(), bytes->size(), path.string());
}

} // namespace rubble
