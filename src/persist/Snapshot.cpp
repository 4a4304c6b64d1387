#include "rubble/Snapshot.hpp"

#include "persist/Bytes.hpp"
#include "rubble/JournalFile.hpp"

namespace rubble {
namespace {

using persist::ByteReader;
using persist::ByteWriter;

constexpr std::uint8_t kMagic[4] = {'R', 'B', 'S', 'N'};
constexpr std::uint16_t kVersion = 1;

void vec(ByteWriter& w, const Vec3& v) {
    w.f64(v.x);
    w.f64(v.y);
    w.f64(v.z);
}
void mat(ByteWriter& w, const Mat3& m) {
    for (const auto& row : m.m)
        for (double x : row)
            w.f64(x);
}
void frame(ByteWriter& w, const Frame& f) {
    mat(w, f.rotation);
    vec(w, f.translation);
}
void text(ByteWriter& w, const std::string& s) {
    w.u32(static_cast<std::uint32_t>(s.size()));
    w.bytes(s.data(), s.size());
}

Vec3 vec(ByteReader& r, const std::string& field) {
    Vec3 v;
    v.x = r.finite(field + ".x");
    v.y = r.finite(field + ".y");
    v.z = r.finite(field + ".z");
    return v;
}
Mat3 mat(ByteReader& r, const std::string& field) {
    Mat3 m;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            m.m[i][j] = r.finite(field + "[" + std::to_string(i) + "][" + std::to_string(j) + "]");
    return m;
}
Frame frame(ByteReader& r, const std::string& field) {
    Frame f;
    f.rotation = mat(r, field + ".rotation");
    f.translation = vec(r, field + ".translation");
    return f;
}
std::string text(ByteReader& r, const std::uint8_t* data, const std::string& field) {
    const std::uint32_t n = r.count(field + ".length", 1);
    std::string s;
    if (r.ok())
        s.assign(reinterpret_cast<const char*>(data + r.offset()), n);
    for (std::uint32_t i = 0; i < n && r.ok(); ++i)
        (void)r.u8(field);
    return s;
}

void writeObject(ByteWriter& w, const ObjectState& o) {
    w.u32(o.id);
    w.u32(o.version);
    w.u8(o.destructible ? 1 : 0);
    w.f64(o.density);
    w.f64(o.impulseThreshold);
    w.u64(o.crumbleAbove);
    const FractureParams& f = o.fracture;
    w.u8(static_cast<std::uint8_t>(f.pattern));
    w.i32(f.seedPoints);
    w.i32(f.cells);
    for (double x :
         {f.sizeLaw.base, f.sizeLaw.scale, f.sizeLaw.exponent, f.sizeLaw.minSize, f.sizeLaw.maxSize})
        w.f64(x);
    w.u8(static_cast<std::uint8_t>(f.backend));
    w.f64(f.minPieceVolumeFraction);
    w.f64(f.uvScale);
    w.u8(f.simplifyPieces ? 1 : 0);
    w.f64(o.mass.volume);
    vec(w, o.mass.centerOfMass);
    mat(w, o.mass.inertia);
    vec(w, o.mass.principalMoments);
    mat(w, o.mass.principalAxes);
    const Mesh& m = o.mesh;
    w.u32(static_cast<std::uint32_t>(m.positions.size()));
    for (const Vec3& p : m.positions)
        vec(w, p);
    w.u32(static_cast<std::uint32_t>(m.triangles.size()));
    for (const Triangle& t : m.triangles)
        for (auto i : t)
            w.u32(i);
    w.u32(static_cast<std::uint32_t>(m.normals.size()));
    for (const Vec3& n : m.normals)
        vec(w, n);
    w.u32(static_cast<std::uint32_t>(m.uvs.size()));
    for (const Vec2& u : m.uvs) {
        w.f64(u.x);
        w.f64(u.y);
    }
    w.u32(static_cast<std::uint32_t>(m.materials.size()));
    for (std::uint32_t id : m.materials)
        w.u32(id);
    w.u32(static_cast<std::uint32_t>(m.materialNames.size()));
    for (const std::string& s : m.materialNames)
        text(w, s);
    w.u32(static_cast<std::uint32_t>(o.convexParts.size()));
    for (const ConvexPolytope& part : o.convexParts) {
        w.u32(static_cast<std::uint32_t>(part.faces().size()));
        for (const PolytopeFace& face : part.faces()) {
            vec(w, face.plane.normal);
            w.f64(face.plane.offset);
            w.i32(face.tag);
            w.u32(static_cast<std::uint32_t>(face.corners.size()));
            for (const Vec3& c : face.corners)
                vec(w, c);
        }
    }
    text(w, o.warning);
}

ObjectState readObject(ByteReader& r, const std::uint8_t* data, const std::string& at) {
    ObjectState o;
    o.id = r.u32(at + ".id");
    o.version = r.u32(at + ".version");
    o.destructible = r.u8(at + ".destructible") != 0;
    o.density = r.finite(at + ".density");
    o.impulseThreshold = r.finite(at + ".impulseThreshold");
    o.crumbleAbove = r.u64(at + ".crumbleAbove");
    FractureParams& f = o.fracture;
    std::size_t pos = r.offset();
    const std::uint8_t pattern = r.u8(at + ".fracture.pattern");
    if (r.ok() && pattern > static_cast<std::uint8_t>(CellPattern::Shatter))
        r.fail(pos, at + ".fracture.pattern", "unknown pattern " + std::to_string(pattern));
    f.pattern = static_cast<CellPattern>(pattern);
    f.seedPoints = r.i32(at + ".fracture.seedPoints");
    f.cells = r.i32(at + ".fracture.cells");
    f.sizeLaw.base = r.finite(at + ".fracture.sizeLaw.base");
    f.sizeLaw.scale = r.finite(at + ".fracture.sizeLaw.scale");
    f.sizeLaw.exponent = r.finite(at + ".fracture.sizeLaw.exponent");
    f.sizeLaw.minSize = r.finite(at + ".fracture.sizeLaw.minSize");
    f.sizeLaw.maxSize = r.finite(at + ".fracture.sizeLaw.maxSize");
    pos = r.offset();
    const std::uint8_t backend = r.u8(at + ".fracture.backend");
    if (r.ok() && backend > static_cast<std::uint8_t>(BooleanKind::Fast))
        r.fail(pos, at + ".fracture.backend", "unknown backend " + std::to_string(backend));
    f.backend = static_cast<BooleanKind>(backend);
    f.minPieceVolumeFraction = r.finite(at + ".fracture.minPieceVolumeFraction");
    f.uvScale = r.finite(at + ".fracture.uvScale");
    f.simplifyPieces = r.u8(at + ".fracture.simplifyPieces") != 0;
    o.mass.volume = r.finite(at + ".mass.volume");
    o.mass.centerOfMass = vec(r, at + ".mass.centerOfMass");
    o.mass.inertia = mat(r, at + ".mass.inertia");
    o.mass.principalMoments = vec(r, at + ".mass.principalMoments");
    o.mass.principalAxes = mat(r, at + ".mass.principalAxes");
    Mesh& m = o.mesh;
    const std::uint32_t nPos = r.count(at + ".mesh.positions.count", 24);
    m.positions.reserve(nPos);
    for (std::uint32_t i = 0; i < nPos && r.ok(); ++i)
        m.positions.push_back(vec(r, at + ".mesh.positions"));
    const std::uint32_t nTri = r.count(at + ".mesh.triangles.count", 12);
    m.triangles.reserve(nTri);
    for (std::uint32_t i = 0; i < nTri && r.ok(); ++i) {
        Triangle t{};
        for (auto& v : t) {
            pos = r.offset();
            v = r.u32(at + ".mesh.triangles");
            if (r.ok() && v >= nPos)
                r.fail(pos, at + ".mesh.triangles",
                       "vertex index " + std::to_string(v) + " out of range (" + std::to_string(nPos) + ")");
        }
        m.triangles.push_back(t);
    }
    auto perCorner = [&](std::uint32_t n, const std::string& field, std::size_t where) {
        if (r.ok() && n != 0 && n != 3ull * nTri)
            r.fail(where, field, std::to_string(n) + " entries for " + std::to_string(nTri) + " triangles");
    };
    pos = r.offset();
    const std::uint32_t nNormals = r.count(at + ".mesh.normals.count", 24);
    perCorner(nNormals, at + ".mesh.normals.count", pos);
    for (std::uint32_t i = 0; i < nNormals && r.ok(); ++i)
        m.normals.push_back(vec(r, at + ".mesh.normals"));
    pos = r.offset();
    const std::uint32_t nUvs = r.count(at + ".mesh.uvs.count", 16);
    perCorner(nUvs, at + ".mesh.uvs.count", pos);
    for (std::uint32_t i = 0; i < nUvs && r.ok(); ++i) {
        Vec2 u;
        u.x = r.finite(at + ".mesh.uvs");
        u.y = r.finite(at + ".mesh.uvs");
        m.uvs.push_back(u);
    }
    pos = r.offset();
    const std::uint32_t nMat = r.count(at + ".mesh.materials.count", 4);
    if (r.ok() && nMat != 0 && nMat != nTri)
        r.fail(pos, at + ".mesh.materials.count",
               std::to_string(nMat) + " entries for " + std::to_string(nTri) + " triangles");
    for (std::uint32_t i = 0; i < nMat && r.ok(); ++i)
        m.materials.push_back(r.u32(at + ".mesh.materials"));
    const std::uint32_t nNames = r.count(at + ".mesh.materialNames.count", 4);
    for (std::uint32_t i = 0; i < nNames && r.ok(); ++i)
        m.materialNames.push_back(text(r, data, at + ".mesh.materialNames"));
    const std::uint32_t nParts = r.count(at + ".convexParts.count", 4);
    for (std::uint32_t i = 0; i < nParts && r.ok(); ++i) {
        const std::string part = at + ".convexParts[" + std::to_string(i) + "]";
        const std::uint32_t nFaces = r.count(part + ".faces.count", 40);
        std::vector<PolytopeFace> faces;
        for (std::uint32_t k = 0; k < nFaces && r.ok(); ++k) {
            PolytopeFace face;
            face.plane.normal = vec(r, part + ".plane.normal");
            face.plane.offset = r.finite(part + ".plane.offset");
            face.tag = r.i32(part + ".tag");
            const std::uint32_t nCorners = r.count(part + ".corners.count", 24);
            for (std::uint32_t c = 0; c < nCorners && r.ok(); ++c)
                face.corners.push_back(vec(r, part + ".corners"));
            faces.push_back(std::move(face));
        }
        o.convexParts.push_back(ConvexPolytope::fromFaces(std::move(faces)));
    }
    o.warning = text(r, data, at + ".warning");
    return o;
}

} // namespace

Snapshot takeSnapshot(const DestructionWorld& world, const DestructionWorld::Config& config,
                      std::vector<ObjectPlacement> placements) {
    Snapshot s;
    s.seed = config.seed;
    s.delayFrames = config.delayFrames;
    s.world = world.saveState();
    s.placements = std::move(placements);
    return s;
}

Status restoreSnapshot(DestructionWorld& world, const DestructionWorld::Config& config, Snapshot snapshot) {
    if (snapshot.seed != config.seed)
        return Error{ErrorCode::InvalidInput, "snapshot field seed is " + std::to_string(snapshot.seed) +
                                                  ", the world's is " + std::to_string(config.seed)};
    if (snapshot.delayFrames != config.delayFrames)
        return Error{ErrorCode::InvalidInput, "snapshot field delayFrames is " +
                                                  std::to_string(snapshot.delayFrames) + ", the world's is " +
                                                  std::to_string(config.delayFrames)};
    return world.loadState(std::move(snapshot.world));
}

std::vector<std::uint8_t> encodeSnapshot(const Snapshot& s) {
    ByteWriter w;
    w.bytes(kMagic, 4);
    w.u16(kVersion);
    w.u16(0); // reserved
    w.u64(s.seed);
    w.i32(s.delayFrames);
    w.u64(s.world.frame);
    w.u32(s.world.nextId);
    w.u64(s.world.journalPosition);
    w.u32(static_cast<std::uint32_t>(s.world.objects.size()));
    for (const ObjectState& o : s.world.objects)
        writeObject(w, o);
    w.u32(static_cast<std::uint32_t>(s.placements.size()));
    for (const ObjectPlacement& p : s.placements) {
        w.u32(p.object);
        w.u8(static_cast<std::uint8_t>(p.motion));
        frame(w, p.objectToWorld);
        vec(w, p.linearVelocity);
        vec(w, p.angularVelocity);
    }
    w.u32(static_cast<std::uint32_t>(s.world.work.size()));
    for (const PendingWork& p : s.world.work) {
        w.u32(p.object);
        w.u32(p.version);
        w.u8(p.inFlight ? 1 : 0);
        w.u64(p.readyFrame);
        w.u32(static_cast<std::uint32_t>(p.impacts.size()));
        for (std::size_t i = 0; i < p.impacts.size(); ++i) {
            vec(w, p.impacts[i].point);
            vec(w, p.impacts[i].normal);
            w.f64(p.impacts[i].impulse);
            w.u64(i < p.ticks.size() ? p.ticks[i] : 0);
        }
    }
    w.u32(persist::crc32(w.data().data(), w.size()));
    return std::move(w.data());
}

Result<Snapshot> decodeSnapshot(const std::uint8_t* data, std::size_t size, const std::string& source) {
    ByteReader r(data, size, source);
    auto bad = [&] { return Error{ErrorCode::ParseError, r.error()}; };
    std::uint8_t magic[4];
    for (auto& m : magic)
        m = r.u8("magic");
    if (r.ok() && !std::equal(magic, magic + 4, kMagic))
        r.fail(0, "magic", "not a Rubble snapshot (expected RBSN)");
    const std::uint16_t version = r.u16("version");
    if (r.ok() && version != kVersion)
        r.fail(4, "version",
               "version " + std::to_string(version) + " is not supported (this build reads " +
                   std::to_string(kVersion) + ")");
    (void)r.u16("reserved");
    if (!r.ok())
        return bad();
    if (size < 12) {
        r.fail(size, "crc32", "file too short");
        return bad();
    }
    ByteReader tail(data + size - 4, 4, source);
    if (tail.u32("crc32") != persist::crc32(data, size - 4)) {
        r.fail(size - 4, "crc32", "checksum mismatch (the file is corrupted or truncated)");
        return bad();
    }
    // The payload is parsed as if the checksum were not there, so that a hostile file with a valid checksum
    // still ends at the right place.
    ByteReader body(data, size - 4, source);
    for (int i = 0; i < 8; ++i)
        (void)body.u8("header");
    Snapshot s;
    s.seed = body.u64("seed");
    s.delayFrames = body.i32("delayFrames");
    s.world.frame = body.u64("frame");
    s.world.nextId = body.u32("nextId");
    s.world.journalPosition = body.u64("journalPosition");
    const std::uint32_t nObjects = body.count("objects.count", 64);
    for (std::uint32_t i = 0; i < nObjects && body.ok(); ++i)
        s.world.objects.push_back(readObject(body, data, "objects[" + std::to_string(i) + "]"));
    const std::uint32_t nPlacements = body.count("placements.count", 149);
    for (std::uint32_t i = 0; i < nPlacements && body.ok(); ++i) {
        const std::string at = "placements[" + std::to_string(i) + "]";
        ObjectPlacement p;
        p.object = body.u32(at + ".object");
        const std::size_t pos = body.offset();
        const std::uint8_t motion = body.u8(at + ".motion");
        if (body.ok() && motion > static_cast<std::uint8_t>(BodyMotionState::Frozen))
            body.fail(pos, at + ".motion", "unknown motion state " + std::to_string(motion));
        p.motion = static_cast<BodyMotionState>(motion);
        p.objectToWorld = frame(body, at + ".objectToWorld");
        p.linearVelocity = vec(body, at + ".linearVelocity");
        p.angularVelocity = vec(body, at + ".angularVelocity");
        s.placements.push_back(p);
    }
    const std::uint32_t nWork = body.count("work.count", 21);
    for (std::uint32_t i = 0; i < nWork && body.ok(); ++i) {
        const std::string at = "work[" + std::to_string(i) + "]";
        PendingWork p;
        p.object = body.u32(at + ".object");
        p.version = body.u32(at + ".version");
        p.inFlight = body.u8(at + ".inFlight") != 0;
        p.readyFrame = body.u64(at + ".readyFrame");
        const std::uint32_t nImpacts = body.count(at + ".impacts.count", 64);
        for (std::uint32_t k = 0; k < nImpacts && body.ok(); ++k) {
            Impact im;
            im.point = vec(body, at + ".impacts.point");
            im.normal = vec(body, at + ".impacts.normal");
            im.impulse = body.finite(at + ".impacts.impulse");
            p.impacts.push_back(im);
            p.ticks.push_back(body.u64(at + ".impacts.tick"));
        }
        s.world.work.push_back(std::move(p));
    }
    if (body.ok() && body.remaining() != 0)
        body.fail(body.offset(), "crc32", std::to_string(body.remaining()) + " unexpected bytes before it");
    if (!body.ok())
        return Error{ErrorCode::ParseError, body.error()};
    return s;
}

Status saveSnapshot(const std::filesystem::path& path, const Snapshot& snapshot) {
    return writeFileAtomic(path, encodeSnapshot(snapshot));
}

Result<Snapshot> loadSnapshot(const std::filesystem::path& path) {
    Result<std::vector<std::uint8_t>> bytes = readFileBinary(path);
    if (!bytes)
        return bytes.error();
    return decodeSnapshot(bytes->data(), bytes->size(), path.string());
}

} // namespace rubble
