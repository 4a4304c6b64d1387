#include "rubble/persist/Snapshot.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <bit>
#include <map>

#include "geometry/PointBits.hpp"
#include "io/FileBytes.hpp"
#include "persist/Bytes.hpp"
#include "persist/CornerTable.hpp"
#include "persist/RoughnessRecord.hpp"
#include "persist/SnapshotInPlace.hpp"
#include "rubble/fracture/Roughness.hpp"
#include "rubble/persist/JournalFile.hpp"
#include "rubble/structure/Material.hpp"

namespace rubble {
namespace {

using persist::ByteReader;
using persist::ByteWriter;

constexpr std::uint8_t kMagic[4] = {'R', 'B', 'S', 'N'};
// Mesh arrays are copied in bulk on little-endian machines (the file's byte order); elsewhere value by value.
constexpr bool kBulk = std::endian::native == std::endian::little && sizeof(Vec3) == 24 &&
                       sizeof(Vec2) == 16 && sizeof(Vec3f) == 12 && sizeof(Vec2f) == 8 &&
                       sizeof(Triangle) == 12;

// Writes v's items without a count: in bulk on little-endian machines, else with `each`.
template <class T>
void writeItems(ByteWriter& w, const std::vector<T>& v, auto&& each) {
    if constexpr (kBulk)
        w.bytes(v.data(), v.size() * sizeof(T));
    else
        for (const T& x : v)
            each(x);
}
// Writes v's count, then its items.
template <class T>
void writeArray(ByteWriter& w, const std::vector<T>& v, auto&& each) {
    w.u32(static_cast<std::uint32_t>(v.size()));
    writeItems(w, v, each);
}

// Reads n records of T (bytes each) in bulk when possible, else with `each`; then `check` every record
// (index, byte offset of the record) for values that are not allowed.
template <class T>
void readArray(ByteReader& r, std::vector<T>& v, std::uint32_t n, const char* field, auto&& each) {
    if constexpr (kBulk) {
        v.resize(n);
        r.raw(v.data(), n * sizeof(T), field);
    } else {
        v.reserve(n);
        for (std::uint32_t i = 0; i < n && r.ok(); ++i)
            v.push_back(each());
    }
}

std::array<double, 3> coords(const Vec3& v) {
    return {v.x, v.y, v.z};
}
std::array<double, 3> coords(const Vec3f& v) {
    return {v.x, v.y, v.z};
}
std::array<double, 2> coords(const Vec2& v) {
    return {v.x, v.y};
}
std::array<double, 2> coords(const Vec2f& v) {
    return {v.x, v.y};
}

// Fails at the first non-finite coordinate of records stored from offset `start`, each `bytes` long.
template <class T>
void checkFinite(ByteReader& r, const std::vector<T>& v, std::size_t start, const char* field,
                 const char* what = "is not finite", std::size_t bytes = sizeof(T)) {
    static const char* axis[3] = {".x", ".y", ".z"};
    for (std::size_t i = 0; i < v.size() && r.ok(); ++i) {
        const auto c = coords(v[i]);
        for (std::size_t k = 0; k < c.size(); ++k)
            if (!(c[k] - c[k] == 0)) {
                r.fail(start + bytes * i + bytes / c.size() * k, std::string(field) + axis[k], what);
                break;
            }
    }
}

// 2: decomposition settings, each object's mesh hash, the volume ledger. 3: the structure. 4: roughness.
// 5: normals and texture coordinates in float. 6: mesh corners and part corners each once. 7: Mesh::hash in
// 64-bit words (read: 2 to 7; older files' mesh hashes are computed again).
constexpr std::uint16_t kVersion = 7;
constexpr std::uint16_t kOldestVersion = 2;

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

// A boolean stored as 0 or 1 (anything else is refused, so that an accepted file encodes to its own bytes).
bool flag(ByteReader& r, const char* field) {
    const std::size_t at = r.offset();
    const std::uint8_t v = r.u8(field);
    if (r.ok() && v > 1)
        r.fail(at, field, "is " + std::to_string(v) + ", expected 0 or 1");
    return v == 1;
}

// Readers with literal field names: a name with its index or axis is only built when something fails.
double real(ByteReader& r, const char* field, const char* part = "") {
    const std::size_t at = r.offset();
    const double v = r.f64(field);
    if (r.ok() && !(v - v == 0))
        r.fail(at, std::string(field) + part, "is not finite");
    return r.ok() ? v : 0;
}
float single(ByteReader& r, const char* field, const char* part) {
    const std::size_t at = r.offset();
    const float v = r.f32(field);
    if (r.ok() && !(v - v == 0))
        r.fail(at, std::string(field) + part, "is not finite");
    return r.ok() ? v : 0;
}
// Attributes of a version before 5 (double, stored from `start`) rounded to float; one beyond float's range
// fails.
template <class Wide, class Narrow>
void narrow(ByteReader& r, const std::vector<Wide>& wide, std::vector<Narrow>& out, std::size_t start,
            const char* field) {
    out.reserve(wide.size());
    for (const Wide& v : wide)
        out.emplace_back(v);
    checkFinite(r, out, start, field, "is beyond float's range", sizeof(Wide));
}
Vec3 vec(ByteReader& r, const char* field) {
    Vec3 v;
    v.x = real(r, field, ".x");
    v.y = real(r, field, ".y");
    v.z = real(r, field, ".z");
    return v;
}
Mat3 mat(ByteReader& r, const char* field) {
    static const char* cells[3][3] = {
        {"[0][0]", "[0][1]", "[0][2]"}, {"[1][0]", "[1][1]", "[1][2]"}, {"[2][0]", "[2][1]", "[2][2]"}};
    Mat3 m;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            m.m[i][j] = real(r, field, cells[i][j]);
    return m;
}
Frame frame(ByteReader& r, const char* rotation, const char* translation) {
    Frame f;
    f.rotation = mat(r, rotation);
    f.translation = vec(r, translation);
    return f;
}
std::string text(ByteReader& r, const std::uint8_t* data, const char* lengthField, const char* field) {
    const std::uint32_t n = r.count(lengthField, 1);
    std::string s;
    if (r.ok())
        s.assign(reinterpret_cast<const char*>(data + r.offset()), n);
    for (std::uint32_t i = 0; i < n && r.ok(); ++i)
        (void)r.u8(field);
    return s;
}

// Version 6: the positions, then each distinct corner once (CornerTable) and the triangles as its codes.
void writeMesh(ByteWriter& w, const Mesh& m) {
    writeArray(w, m.positions, [&](const Vec3& p) { vec(w, p); });
    const std::size_t corners = 3 * m.triangles.size();
    const bool normals = m.normals.size() == corners && corners > 0;
    const bool uvs = m.uvs.size() == corners && corners > 0;
    w.u32(static_cast<std::uint32_t>(m.triangles.size()));
    w.u8(static_cast<std::uint8_t>((normals ? 1 : 0) | (uvs ? 2 : 0)));
    if (!normals && !uvs) {
        writeItems(w, m.triangles, [&](const Triangle& t) {
            for (auto i : t)
                w.u32(i);
        });
    } else {
        const persist::CornerTable t = persist::cornerTable(m, normals, uvs);
        writeArray(w, t.vertex, [&](std::uint32_t v) { w.u32(v); });
        writeItems(w, t.normals, [&](const Vec3f& n) {
            for (float x : {n.x, n.y, n.z})
                w.f32(x);
        });
        writeItems(w, t.uvs, [&](const Vec2f& u) {
            for (float x : {u.x, u.y})
                w.f32(x);
        });
        writeItems(w, t.codes, [&](std::uint32_t c) { w.u32(c); });
    }
    writeArray(w, m.materials, [&](std::uint32_t id) { w.u32(id); });
    w.u32(static_cast<std::uint32_t>(m.materialNames.size()));
    for (const std::string& s : m.materialNames)
        text(w, s);
}

// A part's bit-distinct corners in the order its faces first use them, and each face corner's index.
struct PartCorners {
    std::vector<const Vec3*> corners;
    std::vector<std::uint32_t> index; // face after face
};
PartCorners partCorners(const ConvexPolytope& part) {
    struct Use {
        std::array<std::uint64_t, 3> bits;
        std::uint32_t first; // the first face corner that uses it
        std::uint32_t at;    // this face corner
    };
    std::vector<Use> uses;
    for (const PolytopeFaceView& face : part.faces())
        for (const Vec3& c : face.corners) {
            const auto at = static_cast<std::uint32_t>(uses.size());
            uses.push_back({detail::pointBits(c), at, at});
        }
    std::vector<Use> sorted = uses;
    std::sort(sorted.begin(), sorted.end(),
              [](const Use& a, const Use& b) { return a.bits != b.bits ? a.bits < b.bits : a.at < b.at; });
    for (std::size_t i = 1; i < sorted.size(); ++i)
        if (sorted[i].bits == sorted[i - 1].bits)
            sorted[i].first = sorted[i - 1].first;
    for (const Use& u : sorted)
        uses[u.at].first = u.first;
    PartCorners out;
    out.index.resize(uses.size());
    std::vector<std::uint32_t> renumbered(uses.size(), ~std::uint32_t{0});
    std::size_t at = 0;
    for (const PolytopeFaceView& face : part.faces())
        for (const Vec3& c : face.corners) {
            std::uint32_t& n = renumbered[uses[at].first];
            if (n == ~std::uint32_t{0}) {
                n = static_cast<std::uint32_t>(out.corners.size());
                out.corners.push_back(&c);
            }
            out.index[at++] = n;
        }
    return out;
}

// Bytes of a corner index in a part of n corners (version 6).
int indexBytes(std::size_t n) {
    return n <= 256 ? 1 : n <= 65536 ? 2 : 4;
}

// Version 6: each part's corners once (partCorners), its faces as planes, tags and corner indices.
void writeParts(ByteWriter& w, const std::vector<ConvexPolytope>& parts) {
    w.u32(static_cast<std::uint32_t>(parts.size()));
    for (const ConvexPolytope& part : parts) {
        const PartCorners corners = partCorners(part);
        w.u32(static_cast<std::uint32_t>(corners.corners.size()));
        for (const Vec3* c : corners.corners)
            vec(w, *c);
        const int bytes = indexBytes(corners.corners.size());
        std::size_t at = 0;
        w.u32(static_cast<std::uint32_t>(part.faces().size()));
        for (const PolytopeFaceView& face : part.faces()) {
            vec(w, face.plane.normal);
            w.f64(face.plane.offset);
            w.i32(face.tag);
            w.u32(static_cast<std::uint32_t>(face.corners.size()));
            for (std::size_t k = 0; k < face.corners.size(); ++k) {
                const std::uint32_t i = corners.index[at++];
                if (bytes == 1)
                    w.u8(static_cast<std::uint8_t>(i));
                else if (bytes == 2)
                    w.u16(static_cast<std::uint16_t>(i));
                else
                    w.u32(i);
            }
        }
    }
}

void writeObject(ByteWriter& w, const ObjectState& o) {
    w.u32(o.id);
    w.u32(o.version);
    w.u64(o.meshHash);
    w.u8(o.destructible ? 1 : 0);
    w.f64(o.density);
    w.f64(o.impulseThreshold);
    w.u64(o.crumbleAbove);
    const FractureParams& f = o.fracture;
    w.u8(patternByte(f));
    w.i32(f.seedPoints);
    w.i32(f.cells);
    for (double x :
         {f.sizeLaw.base, f.sizeLaw.scale, f.sizeLaw.exponent, f.sizeLaw.minSize, f.sizeLaw.maxSize})
        w.f64(x);
    w.u8(static_cast<std::uint8_t>(f.backend));
    w.f64(f.minPieceVolumeFraction);
    w.f64(f.uvScale);
    w.u8(f.simplifyPieces ? 1 : 0);
    persist::writeRoughness(w, f.roughness);
    w.f64(o.mass.volume);
    vec(w, o.mass.centerOfMass);
    mat(w, o.mass.inertia);
    vec(w, o.mass.principalMoments);
    mat(w, o.mass.principalAxes);
    writeMesh(w, o.mesh);
    writeParts(w, o.convexParts);
    text(w, o.warning);
}

// Reads n float normals (none after a failure), failing at the first non-finite one.
void readNormals(ByteReader& r, std::vector<Vec3f>& v, std::uint32_t n, const char* field) {
    const std::size_t start = r.offset();
    readArray(r, v, r.ok() ? n : 0, field, [&] {
        const float x = single(r, field, ".x"), y = single(r, field, ".y");
        return Vec3f{x, y, single(r, field, ".z")};
    });
    if (kBulk)
        checkFinite(r, v, start, field);
}

// Reads n float texture coordinates (none after a failure), failing at the first non-finite one.
void readUvs(ByteReader& r, std::vector<Vec2f>& v, std::uint32_t n, const char* field) {
    const std::size_t start = r.offset();
    readArray(r, v, r.ok() ? n : 0, field, [&] {
        const float u = single(r, field, ".x");
        return Vec2f{u, single(r, field, ".y")};
    });
    if (kBulk)
        checkFinite(r, v, start, field);
}

// Reads the mesh's positions (every version).
void readPositions(ByteReader& r, Mesh& m) {
    const std::uint32_t n = r.count("mesh.positions.count", 24);
    const std::size_t start = r.offset();
    readArray(r, m.positions, n, "mesh.positions", [&] { return vec(r, "mesh.positions"); });
    if (kBulk)
        checkFinite(r, m.positions, start, "mesh.positions");
}

// Reads n triangles, failing at the first vertex index beyond m's positions.
void readTriangles(ByteReader& r, Mesh& m, std::uint32_t n) {
    const std::size_t start = r.offset();
    readArray(r, m.triangles, n, "mesh.triangles", [&] {
        Triangle t{};
        for (auto& v : t)
            v = r.u32("mesh.triangles");
        return t;
    });
    for (std::size_t i = 0; i < m.triangles.size() && r.ok(); ++i)
        for (int k = 0; k < 3; ++k)
            if (m.triangles[i][k] >= m.positions.size()) {
                r.fail(start + 12 * i + 4 * k, "mesh.triangles",
                       "vertex index " + std::to_string(m.triangles[i][k]) + " out of range (" +
                           std::to_string(m.positions.size()) + ")");
                break;
            }
}

// Reads the per-triangle material ids and the material names (every version).
void readMaterials(ByteReader& r, const std::uint8_t* data, Mesh& m) {
    const std::size_t pos = r.offset();
    const std::uint32_t nMat = r.count("mesh.materials.count", 4);
    if (r.ok() && nMat != 0 && nMat != m.triangles.size())
        r.fail(pos, "mesh.materials.count",
               std::to_string(nMat) + " entries for " + std::to_string(m.triangles.size()) + " triangles");
    readArray(r, m.materials, r.ok() ? nMat : 0, "mesh.materials", [&] { return r.u32("mesh.materials"); });
    const std::uint32_t nNames = r.count("mesh.materialNames.count", 4);
    for (std::uint32_t i = 0; i < nNames && r.ok(); ++i)
        m.materialNames.push_back(text(r, data, "mesh.materialNames.length", "mesh.materialNames"));
}

// Version 6 (writeMesh).
void readMesh(ByteReader& r, const std::uint8_t* data, Mesh& m) {
    readPositions(r, m);
    const std::uint32_t nTri = r.count("mesh.triangles.count", 12);
    std::size_t pos = r.offset();
    const std::uint8_t attributes = r.u8("mesh.attributes");
    if (r.ok() && attributes > 3)
        r.fail(pos, "mesh.attributes", "is " + std::to_string(attributes) + ", expected 0 to 3");
    if (r.ok() && attributes != 0 && nTri == 0)
        r.fail(pos, "mesh.attributes", "is " + std::to_string(attributes) + " for a mesh without triangles");
    if (!r.ok())
        return;
    if (attributes == 0) {
        readTriangles(r, m, nTri);
    } else {
        persist::CornerTable t;
        const bool normals = attributes & 1, uvs = attributes & 2;
        const std::uint32_t n = r.count("mesh.corners.count", 4 + (normals ? 12 : 0) + (uvs ? 8 : 0));
        std::size_t start = r.offset();
        readArray(r, t.vertex, n, "mesh.corners.vertex", [&] { return r.u32("mesh.corners.vertex"); });
        if (const persist::CornerError e = persist::checkCornerVertices(t, m.positions.size());
            r.ok() && !e.what.empty())
            r.fail(start + 4 * e.index, "mesh.corners.vertex", e.what);
        start = r.offset();
        if (normals)
            readNormals(r, t.normals, n, "mesh.corners.normals");
        if (uvs)
            readUvs(r, t.uvs, n, "mesh.corners.uvs");
        start = r.offset();
        if (r.ok() && 12ull * nTri > r.remaining())
            r.fail(start, "mesh.triangles.codes",
                   "file ends before its " + std::to_string(3ull * nTri) + " codes");
        readArray(r, t.codes, r.ok() ? 3 * nTri : 0, "mesh.triangles.codes",
                  [&] { return r.u32("mesh.triangles.codes"); });
        if (r.ok())
            if (const persist::CornerError e = persist::expandCorners(t, m.positions.size(), m);
                !e.what.empty())
                r.fail(start + 4 * e.index, "mesh.triangles.codes", e.what);
    }
    readMaterials(r, data, m);
}

// The first corner bit-equal to an earlier one, or corners.size().
std::size_t repeatedCorner(const std::vector<Vec3>& corners) {
    std::vector<std::pair<std::array<std::uint64_t, 3>, std::size_t>> bits;
    bits.reserve(corners.size());
    for (std::size_t i = 0; i < corners.size(); ++i)
        bits.push_back({detail::pointBits(corners[i]), i});
    std::sort(bits.begin(), bits.end());
    std::size_t first = corners.size();
    for (std::size_t i = 1; i < bits.size(); ++i)
        if (bits[i].first == bits[i - 1].first)
            first = std::min(first, bits[i].second);
    return first;
}

// Reads the convex parts (version 6: writeParts; before, corners inline in each face).
std::vector<ConvexPolytope> readParts(ByteReader& r, std::uint16_t version) {
    const bool shared = version >= 6;
    std::vector<ConvexPolytope> parts;
    const std::uint32_t nParts = r.count("convexParts.count", shared ? 8 : 4);
    parts.reserve(nParts);
    for (std::uint32_t i = 0; i < nParts && r.ok(); ++i) {
        std::vector<Vec3> corners;
        const std::uint32_t nCorners = shared ? r.count("convexParts.corners.count", 24) : 0;
        corners.reserve(nCorners);
        for (std::uint32_t c = 0; c < nCorners && r.ok(); ++c)
            corners.push_back(vec(r, "convexParts.corners"));
        if (r.ok())
            if (const std::size_t twin = repeatedCorner(corners); twin < corners.size())
                r.fail(r.offset() - 24 * (corners.size() - twin), "convexParts.corners",
                       "corner " + std::to_string(twin) + " repeats an earlier one");
        const int bytes = indexBytes(nCorners);
        std::uint32_t used = 0; // corners come in the order the faces first use them
        const std::uint32_t nFaces = r.count("convexParts.faces.count", 40);
        std::vector<PolytopeFace> faces;
        faces.reserve(nFaces);
        for (std::uint32_t k = 0; k < nFaces && r.ok(); ++k) {
            PolytopeFace face;
            face.plane.normal = vec(r, "convexParts.plane.normal");
            face.plane.offset = real(r, "convexParts.plane.offset");
            face.tag = r.i32("convexParts.tag");
            if (!shared) {
                const std::uint32_t n = r.count("convexParts.corners.count", 24);
                face.corners.reserve(n);
                for (std::uint32_t c = 0; c < n && r.ok(); ++c)
                    face.corners.push_back(vec(r, "convexParts.corners"));
                faces.push_back(std::move(face));
                continue;
            }
            const std::uint32_t n =
                r.count("convexParts.face.corners.count", static_cast<std::size_t>(bytes));
            face.corners.reserve(n);
            for (std::uint32_t c = 0; c < n && r.ok(); ++c) {
                const std::size_t at = r.offset();
                const std::uint32_t index = bytes == 1   ? r.u8("convexParts.face.corners")
                                            : bytes == 2 ? r.u16("convexParts.face.corners")
                                                         : r.u32("convexParts.face.corners");
                if (r.ok() && (index >= nCorners || index > used))
                    r.fail(at, "convexParts.face.corners",
                           "corner " + std::to_string(index) +
                               (index >= nCorners ? " out of range (" : " before its turn (") +
                               std::to_string(index >= nCorners ? nCorners : used) + ")");
                if (!r.ok())
                    break;
                used += index == used;
                face.corners.push_back(corners[index]);
            }
            faces.push_back(std::move(face));
        }
        if (r.ok() && used != nCorners)
            r.fail(r.offset(), "convexParts.corners",
                   std::to_string(nCorners - used) + " corners are never used");
        parts.push_back(ConvexPolytope::fromFaces(std::move(faces)));
    }
    return parts;
}

// Versions 2 to 5: each mesh array with its count; attributes per corner, in double before version 5.
void readMeshBefore6(ByteReader& r, const std::uint8_t* data, std::uint16_t version, ObjectState& o) {
    Mesh& m = o.mesh;
    readPositions(r, m);
    const std::uint32_t nTri = r.count("mesh.triangles.count", 12);
    readTriangles(r, m, nTri);
    auto perCorner = [&](std::uint32_t n, const char* field, std::size_t where) {
        if (r.ok() && n != 0 && n != 3ull * nTri)
            r.fail(where, field, std::to_string(n) + " entries for " + std::to_string(nTri) + " triangles");
    };
    // Per-corner attributes: float from version 5, double before (rounded to float here).
    const bool floats = version >= 5;
    std::size_t pos = r.offset();
    const std::uint32_t nNormals = r.count("mesh.normals.count", floats ? 12 : 24);
    perCorner(nNormals, "mesh.normals.count", pos);
    std::size_t start = r.offset();
    if (floats) {
        readNormals(r, m.normals, nNormals, "mesh.normals");
    } else {
        std::vector<Vec3> wide;
        readArray(r, wide, r.ok() ? nNormals : 0, "mesh.normals", [&] { return vec(r, "mesh.normals"); });
        if (kBulk)
            checkFinite(r, wide, start, "mesh.normals");
        narrow(r, wide, m.normals, start, "mesh.normals");
    }
    pos = r.offset();
    const std::uint32_t nUvs = r.count("mesh.uvs.count", floats ? 8 : 16);
    perCorner(nUvs, "mesh.uvs.count", pos);
    start = r.offset();
    if (floats) {
        readUvs(r, m.uvs, nUvs, "mesh.uvs");
    } else {
        std::vector<Vec2> wide;
        readArray(r, wide, r.ok() ? nUvs : 0, "mesh.uvs", [&] {
            Vec2 u;
            u.x = real(r, "mesh.uvs", ".x");
            u.y = real(r, "mesh.uvs", ".y");
            return u;
        });
        if (kBulk)
            checkFinite(r, wide, start, "mesh.uvs");
        narrow(r, wide, m.uvs, start, "mesh.uvs");
    }
    readMaterials(r, data, m);
}

ObjectState readObject(ByteReader& r, const std::uint8_t* data, std::uint16_t version) {
    ObjectState o;
    o.id = r.u32("id");
    o.version = r.u32("version");
    const std::size_t hashAt = r.offset();
    o.meshHash = r.u64("meshHash");
    if (r.ok() && o.meshHash == 0)
        r.fail(hashAt, "meshHash", "is 0");
    o.destructible = flag(r, "destructible");
    o.density = real(r, "density");
    o.impulseThreshold = real(r, "impulseThreshold");
    o.crumbleAbove = r.u64("crumbleAbove");
    FractureParams& f = o.fracture;
    std::size_t pos = r.offset();
    const std::uint8_t pattern = r.u8("fracture.pattern");
    if (r.ok() && !validPatternByte(pattern))
        r.fail(pos, "fracture.pattern", "unknown pattern " + std::to_string(pattern));
    f.pattern = static_cast<CellPattern>(pattern & 15u);
    f.layout = static_cast<ShatterLayout>(pattern >> 4);
    f.seedPoints = r.i32("fracture.seedPoints");
    f.cells = r.i32("fracture.cells");
    f.sizeLaw.base = real(r, "fracture.sizeLaw.base");
    f.sizeLaw.scale = real(r, "fracture.sizeLaw.scale");
    f.sizeLaw.exponent = real(r, "fracture.sizeLaw.exponent");
    f.sizeLaw.minSize = real(r, "fracture.sizeLaw.minSize");
    f.sizeLaw.maxSize = real(r, "fracture.sizeLaw.maxSize");
    pos = r.offset();
    const std::uint8_t backend = r.u8("fracture.backend");
    if (r.ok() && backend > static_cast<std::uint8_t>(BooleanKind::Fast))
        r.fail(pos, "fracture.backend", "unknown backend " + std::to_string(backend));
    f.backend = static_cast<BooleanKind>(backend);
    f.minPieceVolumeFraction = real(r, "fracture.minPieceVolumeFraction");
    f.uvScale = real(r, "fracture.uvScale");
    f.simplifyPieces = flag(r, "fracture.simplifyPieces");
    if (version >= 4) { // version 3 and older cut flat
        Roughness& rough = f.roughness;
        pos = r.offset();
        rough.amplitude = real(r, "fracture.roughness.amplitude");
        rough.featureSize = real(r, "fracture.roughness.featureSize");
        rough.hurst = real(r, "fracture.roughness.hurst");
        rough.octaves = r.i32("fracture.roughness.octaves");
        rough.relative = flag(r, "fracture.roughness.relative");
        rough.seed = r.u64("fracture.roughness.seed");
        rough.grainStretch = real(r, "fracture.roughness.grainStretch");
        rough.grain = vec(r, "fracture.roughness.grain");
        rough.maxTrianglesPerPiece = r.i32("fracture.roughness.maxTrianglesPerPiece");
        if (Status valid = validateRoughness(rough); r.ok() && !valid)
            r.fail(pos, "fracture.roughness", valid.message());
    }
    o.mass.volume = real(r, "mass.volume");
    o.mass.centerOfMass = vec(r, "mass.centerOfMass");
    o.mass.inertia = mat(r, "mass.inertia");
    o.mass.principalMoments = vec(r, "mass.principalMoments");
    o.mass.principalAxes = mat(r, "mass.principalAxes");
    if (version >= 6)
        readMesh(r, data, o.mesh);
    else
        readMeshBefore6(r, data, version, o);
    if (version < 7 && r.ok())
        o.meshHash = o.mesh.hash(); // the saved hash is Mesh::hash's former one
    o.convexParts = readParts(r, version);
    o.warning = text(r, data, "warning.length", "warning");
    return o;
}

void writeStructure(ByteWriter& w, const StructureState& s) {
    w.u8(s.saved ? 1 : 0);
    w.u32(static_cast<std::uint32_t>(s.nodes.size()));
    for (const StructureNodeState& n : s.nodes) {
        w.u32(n.object);
        w.u32(n.solid);
        w.u8(n.material);
        w.u8(static_cast<std::uint8_t>((n.root ? 1 : 0) | (n.anchor ? 2 : 0) | (n.pending ? 4 : 0)));
    }
    w.u32(static_cast<std::uint32_t>(s.bonds.size()));
    for (const StructureBondState& b : s.bonds) {
        w.u64(b.a);
        w.u64(b.b);
        w.f64(b.health);
        w.u8(b.broken ? 1 : 0);
    }
}

// The structure section: nodes name static placements, ascending; bonds name nodes or ground and scenery
// keys, a < b, ascending; healths in [0, 1], above 0 unless broken.
StructureState readStructure(ByteReader& r, const std::vector<ObjectPlacement>& placements) {
    StructureState s;
    r.setContext("structure.");
    std::size_t at = r.offset();
    s.saved = flag(r, "saved");
    std::map<ObjectId, BodyMotionState> motion;
    for (const ObjectPlacement& p : placements)
        motion.emplace(p.object, p.motion);
    const std::uint32_t nNodes = r.count("nodes.count", 10);
    if (r.ok() && !s.saved && nNodes != 0)
        r.fail(at + 1, "nodes.count", "is " + std::to_string(nNodes) + ", expected 0 (not saved)");
    s.nodes.reserve(nNodes);
    for (std::uint32_t i = 0; i < nNodes && r.ok(); ++i) {
        r.setContext("structure.nodes[" + std::to_string(i) + "].");
        StructureNodeState n;
        at = r.offset();
        n.object = r.u32("object");
        const auto it = motion.find(n.object);
        if (r.ok() && (it == motion.end() || it->second != BodyMotionState::Static))
            r.fail(at, "object", std::to_string(n.object) + " is no static object");
        else if (r.ok() && i > 0 && n.object <= s.nodes.back().object)
            r.fail(at, "object", std::to_string(n.object) + " is not above the previous node's");
        n.solid = r.u32("solid");
        at = r.offset();
        n.material = r.u8("material");
        if (r.ok() && n.material >= materialPresets().size())
            r.fail(at, "material", "unknown material " + std::to_string(n.material));
        at = r.offset();
        const std::uint8_t flags = r.u8("flags");
        n.root = flags & 1;
        n.anchor = flags & 2;
        n.pending = flags & 4;
        if (r.ok() && (flags > 7 || (n.anchor && !n.root) || (n.pending && n.root)))
            r.fail(at, "flags",
                   "is " + std::to_string(flags) +
                       ", expected root 1, anchor 2 (with root), pending 4 (without)");
        s.nodes.push_back(n);
    }
    r.setContext("structure.");
    at = r.offset();
    const std::uint32_t nBonds = r.count("bonds.count", 25);
    if (r.ok() && !s.saved && nBonds != 0)
        r.fail(at, "bonds.count", "is " + std::to_string(nBonds) + ", expected 0 (not saved)");
    s.bonds.reserve(nBonds);
    auto node = [&](const char* field) {
        const std::size_t pos = r.offset();
        const std::uint64_t key = r.u64(field);
        const bool scenery = key >> 32 == kSceneryNodeKey >> 32;
        const auto it = std::lower_bound(
            s.nodes.begin(), s.nodes.end(), key,
            [](const StructureNodeState& n, std::uint64_t k) { return std::uint64_t{n.object} < k; });
        if (r.ok() && !scenery && (it == s.nodes.end() || it->object != key))
            r.fail(pos, field, std::to_string(key) + " is neither a node nor a ground or scenery key");
        return key;
    };
    for (std::uint32_t i = 0; i < nBonds && r.ok(); ++i) {
        r.setContext("structure.bonds[" + std::to_string(i) + "].");
        StructureBondState b;
        b.a = node("a");
        at = r.offset();
        b.b = node("b");
        if (r.ok() && b.a >= b.b)
            r.fail(at, "b", "is not above a");
        else if (r.ok() && i > 0 && std::pair{b.a, b.b} <= std::pair{s.bonds.back().a, s.bonds.back().b})
            r.fail(at, "b", "the pair is not above the previous bond's");
        at = r.offset();
        b.health = real(r, "health");
        b.broken = flag(r, "broken");
        if (r.ok() && !(b.health >= 0 && b.health <= 1 && (b.health > 0 || b.broken)))
            r.fail(at, "health", "is " + std::to_string(b.health) + ", expected 0 to 1 (0 only when broken)");
        s.bonds.push_back(b);
    }
    r.setContext("");
    return s;
}

} // namespace

Snapshot takeSnapshot(const DestructionWorld& world, std::vector<ObjectPlacement> placements) {
    Snapshot s;
    s.world = captureState(world);
    s.placements = std::move(placements);
    return s;
}

Status restoreSnapshot(DestructionWorld& world, Snapshot snapshot) {
    return restoreState(world, std::move(snapshot.world));
}

Snapshot takeSnapshot(const DestructionRuntime& runtime) {
    Snapshot s = takeSnapshot(runtime.world(), runtime.placements());
    s.volumes = runtime.volumes();
    s.volumes.live = 0;
    s.structure = captureStructure(runtime);
    return s;
}

Status restoreSnapshot(DestructionRuntime& runtime, Snapshot snapshot) {
    return restoreState(runtime, std::move(snapshot.world), snapshot.placements, snapshot.volumes,
                        snapshot.structure);
}

std::uint64_t objectStateHash(const ObjectState& object) {
    ByteWriter w;
    writeObject(w, object);
    std::uint64_t h = 0xcbf29ce484222325ULL; // FNV-1a, 64 bits
    for (std::uint8_t b : w.data())
        h = (h ^ b) * 0x100000001b3ULL;
    return h;
}

std::vector<std::uint8_t> encodeSnapshot(const Snapshot& s) {
    std::vector<const ObjectState*> objects;
    objects.reserve(s.world.objects.size());
    for (const ObjectState& o : s.world.objects)
        objects.push_back(&o);
    return detail::encodeSnapshotWith(s, objects);
}

std::vector<std::uint8_t> detail::encodeSnapshotWith(const Snapshot& s,
                                                     const std::vector<const ObjectState*>& objects) {
    ByteWriter w;
    std::size_t estimate = 64 + 10 * s.structure.nodes.size() + 25 * s.structure.bonds.size();
    for (const ObjectState* o : objects)
        estimate += 512 + 24 * o->mesh.positions.size() + 12 * o->mesh.triangles.size() +
                    12 * o->mesh.normals.size() + 8 * o->mesh.uvs.size() + 4 * o->mesh.materials.size() +
                    256 * o->convexParts.size();
    w.data().reserve(estimate);
    w.bytes(kMagic, 4);
    w.u16(kVersion);
    w.u16(0); // reserved
    w.u64(s.world.seed);
    w.i32(s.world.delayFrames);
    w.u64(s.world.crumbleTriangles);
    w.i32(s.world.crumbleCells);
    w.f64(s.world.minPieceVolume);
    const DecompositionParams& d = s.world.decomposition;
    w.i32(d.maxParts);
    w.f64(d.concavity);
    w.f64(d.minPartVolumeFraction);
    w.u64(d.proxyAboveTriangles);
    w.u64(d.maxPartFaces);
    w.u64(s.world.frame);
    w.u32(s.world.nextId);
    w.u64(s.world.journalPosition);
    w.u32(static_cast<std::uint32_t>(objects.size()));
    for (const ObjectState* o : objects)
        writeObject(w, *o);
    w.u32(static_cast<std::uint32_t>(s.placements.size()));
    for (const ObjectPlacement& p : s.placements) {
        w.u32(p.object);
        w.u8(static_cast<std::uint8_t>(p.role));
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
    writeStructure(w, s.structure);
    w.f64(s.volumes.retired);
    w.f64(s.volumes.dust);
    w.f64(s.volumes.dropped);
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
    if (r.ok() && (version < kOldestVersion || version > kVersion))
        r.fail(4, "version",
               "version " + std::to_string(version) + " is not supported (this build reads versions " +
                   std::to_string(kOldestVersion) + " to " + std::to_string(kVersion) +
                   (version < kVersion ? "; the file was saved by an older build: load it there, or replay "
                                         "its journal on the scene"
                                       : "; the file was saved by a newer build") +
                   ")");
    if (const std::uint16_t reserved = r.u16("reserved"); r.ok() && reserved != 0)
        r.fail(6, "reserved", "is " + std::to_string(reserved) + ", expected 0");
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
    s.world.seed = body.u64("seed");
    s.world.delayFrames = body.i32("delayFrames");
    s.world.crumbleTriangles = body.u64("crumbleTriangles");
    s.world.crumbleCells = body.i32("crumbleCells");
    s.world.minPieceVolume = real(body, "minPieceVolume");
    DecompositionParams& d = s.world.decomposition;
    d.maxParts = body.i32("decomposition.maxParts");
    d.concavity = real(body, "decomposition.concavity");
    d.minPartVolumeFraction = real(body, "decomposition.minPartVolumeFraction");
    d.proxyAboveTriangles = static_cast<std::size_t>(body.u64("decomposition.proxyAboveTriangles"));
    d.maxPartFaces = static_cast<std::size_t>(body.u64("decomposition.maxPartFaces"));
    s.world.frame = body.u64("frame");
    s.world.nextId = body.u32("nextId");
    s.world.journalPosition = body.u64("journalPosition");
    const std::uint32_t nObjects = body.count("objects.count", 64);
    s.world.objects.reserve(nObjects);
    for (std::uint32_t i = 0; i < nObjects && body.ok(); ++i) {
        body.setContext("objects[" + std::to_string(i) + "].");
        s.world.objects.push_back(readObject(body, data, version));
    }
    body.setContext("");
    const std::uint32_t nPlacements = body.count("placements.count", 150);
    s.placements.reserve(nPlacements);
    for (std::uint32_t i = 0; i < nPlacements && body.ok(); ++i) {
        body.setContext("placements[" + std::to_string(i) + "].");
        ObjectPlacement p;
        p.object = body.u32("object");
        const std::size_t rolePos = body.offset();
        const std::uint8_t role = body.u8("role");
        if (body.ok() && role != static_cast<std::uint8_t>(BodyRole::Object) &&
            role != static_cast<std::uint8_t>(BodyRole::Piece))
            body.fail(rolePos, "role",
                      "is " + std::to_string(role) + ", expected an object (2) or a piece (3)");
        p.role = static_cast<BodyRole>(role);
        const std::size_t pos = body.offset();
        const std::uint8_t motion = body.u8("motion");
        if (body.ok() && motion > static_cast<std::uint8_t>(BodyMotionState::Frozen))
            body.fail(pos, "motion", "unknown motion state " + std::to_string(motion));
        p.motion = static_cast<BodyMotionState>(motion);
        p.objectToWorld = frame(body, "objectToWorld.rotation", "objectToWorld.translation");
        p.linearVelocity = vec(body, "linearVelocity");
        p.angularVelocity = vec(body, "angularVelocity");
        s.placements.push_back(p);
    }
    body.setContext("");
    const std::uint32_t nWork = body.count("work.count", 21);
    for (std::uint32_t i = 0; i < nWork && body.ok(); ++i) {
        body.setContext("work[" + std::to_string(i) + "].");
        PendingWork p;
        p.object = body.u32("object");
        p.version = body.u32("version");
        p.inFlight = flag(body, "inFlight");
        p.readyFrame = body.u64("readyFrame");
        const std::uint32_t nImpacts = body.count("impacts.count", 64);
        for (std::uint32_t k = 0; k < nImpacts && body.ok(); ++k) {
            Impact im;
            im.point = vec(body, "impacts.point");
            im.normal = vec(body, "impacts.normal");
            im.impulse = real(body, "impacts.impulse");
            p.impacts.push_back(im);
            p.ticks.push_back(body.u64("impacts.tick"));
        }
        s.world.work.push_back(std::move(p));
    }
    body.setContext("");
    if (version >= 3) // version 2 has no structure: restored with fresh bonds
        s.structure = readStructure(body, s.placements);
    for (auto [field, v] : {std::pair{"volumes.retired", &s.volumes.retired},
                            {"volumes.dust", &s.volumes.dust},
                            {"volumes.dropped", &s.volumes.dropped}}) {
        const std::size_t at = body.offset();
        *v = real(body, field);
        if (body.ok() && *v < 0)
            body.fail(at, field, "is negative");
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
    // Regular files only (a device never ends, a FIFO blocks), mapped: no copy, pages populated in one go.
    // Snapshots are replaced by rename, never rewritten in place, so the mapped file does not change.
    auto file = io::openRegularFile(path);
    if (!file)
        return file.error();
    const auto size = static_cast<std::size_t>(file->size());
    if (size > 0) {
        void* map = ::mmap(nullptr, size, PROT_READ, MAP_PRIVATE | MAP_POPULATE, file->fd(), 0);
        if (map != MAP_FAILED) {
            Result<Snapshot> s = decodeSnapshot(static_cast<const std::uint8_t*>(map), size, path.string());
            ::munmap(map, size);
            return s;
        }
    }
    Result<std::vector<std::uint8_t>> bytes = readFileBinary(path);
    if (!bytes)
        return bytes.error();
    return decodeSnapshot(bytes->data(), bytes->size(), path.string());
}

} // namespace rubble
