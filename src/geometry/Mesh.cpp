#include "rubble/geometry/Mesh.hpp"

#include "geometry/ClosestPoint.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>

namespace rubble {

Aabb Mesh::bounds() const {
    Aabb b;
    for (const Vec3& p : positions)
        b.extend(p);
    return b;
}

Vec3 Mesh::triangleNormal(std::size_t t) const {
    const auto c = corners(t);
    return cross(c[1] - c[0], c[2] - c[0]);
}

Status Mesh::validate() const {
    for (std::size_t i = 0; i < positions.size(); ++i)
        if (!isFinite(positions[i]))
            return makeError(ErrorCode::InvalidInput,
                             "vertex " + std::to_string(i) + " has a non-finite coordinate");
    for (std::size_t t = 0; t < triangles.size(); ++t)
        for (std::uint32_t v : triangles[t])
            if (v >= positions.size())
                return makeError(ErrorCode::InvalidInput, "triangle " + std::to_string(t) +
                                                              " refers to vertex " + std::to_string(v) +
                                                              " of " + std::to_string(positions.size()));
    if (!normals.empty() && normals.size() != 3 * triangles.size())
        return makeError(ErrorCode::InvalidInput, "normals must have 3 entries per triangle");
    if (!uvs.empty() && uvs.size() != 3 * triangles.size())
        return makeError(ErrorCode::InvalidInput, "uvs must have 3 entries per triangle");
    if (!materials.empty() && materials.size() != triangles.size())
        return makeError(ErrorCode::InvalidInput, "materials must have 1 entry per triangle");
    return {};
}

void Mesh::append(const Mesh& other) {
    const auto base = static_cast<std::uint32_t>(positions.size());
    const std::size_t oldTris = triangles.size();
    positions.insert(positions.end(), other.positions.begin(), other.positions.end());
    for (const Triangle& t : other.triangles)
        triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
    // Keep attributes consistent: fill the side that lacks them with defaults.
    if (hasNormals() || other.hasNormals()) {
        normals.resize(3 * oldTris);
        if (other.hasNormals())
            normals.insert(normals.end(), other.normals.begin(), other.normals.end());
        else
            normals.resize(3 * triangles.size());
    }
    if (hasUvs() || other.hasUvs()) {
        uvs.resize(3 * oldTris);
        if (other.hasUvs())
            uvs.insert(uvs.end(), other.uvs.begin(), other.uvs.end());
        else
            uvs.resize(3 * triangles.size());
    }
    if (hasMaterials() || other.hasMaterials()) {
        materials.resize(oldTris, 0);
        if (other.hasMaterials())
            materials.insert(materials.end(), other.materials.begin(), other.materials.end());
        else
            materials.resize(triangles.size(), 0);
    }
    if (materialNames.size() < other.materialNames.size())
        materialNames = other.materialNames;
}

Mesh Mesh::transformed(const Mat3& rotation, const Vec3& scale, const Vec3& translation) const {
    Mesh out = *this;
    out.transform(rotation, scale, translation);
    return out;
}

void Mesh::transform(const Mat3& rotation, const Vec3& scale, const Vec3& translation) {
    for (Vec3& p : positions)
        p = rotation * Vec3{p.x * scale.x, p.y * scale.y, p.z * scale.z} + translation;
    // Normals transform by the inverse transpose of rotation*scale = rotation * scale^-1.
    for (Vec3f& n : normals)
        n = Vec3f(normalized(rotation * Vec3{n.x / scale.x, n.y / scale.y, n.z / scale.z}));
    // A mirroring scale flips orientation: swap two corners to stay outward.
    if (scale.x * scale.y * scale.z < 0) {
        for (std::size_t t = 0; t < triangles.size(); ++t) {
            std::swap(triangles[t][1], triangles[t][2]);
            if (!normals.empty())
                std::swap(normals[3 * t + 1], normals[3 * t + 2]);
            if (!uvs.empty())
                std::swap(uvs[3 * t + 1], uvs[3 * t + 2]);
        }
    }
}

Mesh Mesh::translated(const Vec3& t) const {
    Mesh out = *this;
    for (Vec3& p : out.positions)
        p += t;
    return out;
}

void Mesh::computeFlatNormals() {
    normals.resize(3 * triangles.size());
    for (std::size_t t = 0; t < triangles.size(); ++t) {
        const Vec3f n(normalized(triangleNormal(t)));
        normals[3 * t] = normals[3 * t + 1] = normals[3 * t + 2] = n;
    }
}

void Mesh::removeUnreferencedVertices() {
    std::vector<std::uint32_t> remap(positions.size(), UINT32_MAX);
    std::vector<Vec3> kept;
    kept.reserve(positions.size());
    for (Triangle& t : triangles)
        for (std::uint32_t& v : t) {
            if (remap[v] == UINT32_MAX) {
                remap[v] = static_cast<std::uint32_t>(kept.size());
                kept.push_back(positions[v]);
            }
            v = remap[v];
        }
    positions = std::move(kept);
}

namespace {
/// A 64-bit hash of 64-bit words in four interleaved lanes (xxHash64's round and avalanche).
class WordHasher {
public:
    void word(std::uint64_t w) {
        buffer_[held_++] = w;
        if (held_ == kBuffer)
            flush();
    }
    /// A double by its bits, with -0.0 folded into 0.0.
    void real(double d) { word(std::bit_cast<std::uint64_t>(d + 0.0)); }
    /// A 32-bit value: two make a word.
    void half(std::uint32_t v) {
        if (halfHeld_) {
            word(low_ | std::uint64_t{v} << 32);
            halfHeld_ = false;
        } else {
            low_ = v;
            halfHeld_ = true;
        }
    }
    /// A float by its bits, with -0.0 folded into 0.0.
    void real(float f) { half(std::bit_cast<std::uint32_t>(f + 0.0f)); }
    /// Ends a run of halves (an odd one out becomes a word).
    void endHalves() {
        if (halfHeld_)
            word(low_);
        halfHeld_ = false;
    }
    std::uint64_t finish() {
        const std::size_t whole = held_ & ~std::size_t{3};
        const std::size_t tail = held_ - whole;
        held_ = whole;
        flush();
        std::uint64_t h = rotl(lanes_[0], 1) + rotl(lanes_[1], 7) + rotl(lanes_[2], 12) + rotl(lanes_[3], 18);
        for (std::uint64_t lane : lanes_)
            h = (h ^ round(0, lane)) * kPrime1 + kPrime4;
        for (std::size_t i = 0; i < tail; ++i)
            h = rotl(h ^ round(0, buffer_[whole + i]), 27) * kPrime1 + kPrime4;
        h += words_ + tail;
        h ^= h >> 33;
        h *= kPrime2;
        h ^= h >> 29;
        h *= kPrime3;
        h ^= h >> 32;
        return h;
    }

private:
    static constexpr std::uint64_t kPrime1 = 0x9E3779B185EBCA87ull, kPrime2 = 0xC2B2AE3D27D4EB4Full,
                                   kPrime3 = 0x165667B19E3779F9ull, kPrime4 = 0x85EBCA77C2B2AE63ull;
    static constexpr std::size_t kBuffer = 64;
    static std::uint64_t rotl(std::uint64_t x, int r) { return (x << r) | (x >> (64 - r)); }
    static std::uint64_t round(std::uint64_t acc, std::uint64_t w) {
        return rotl(acc + w * kPrime2, 31) * kPrime1;
    }
    void flush() {
        std::uint64_t a = lanes_[0], b = lanes_[1], c = lanes_[2], d = lanes_[3];
        for (std::size_t i = 0; i < held_; i += 4) {
            a = round(a, buffer_[i]);
            b = round(b, buffer_[i + 1]);
            c = round(c, buffer_[i + 2]);
            d = round(d, buffer_[i + 3]);
        }
        lanes_[0] = a;
        lanes_[1] = b;
        lanes_[2] = c;
        lanes_[3] = d;
        words_ += held_;
        held_ = 0;
    }
    std::uint64_t lanes_[4] = {kPrime1 + kPrime2, kPrime2, 0, 0 - kPrime1};
    std::uint64_t buffer_[kBuffer] = {};
    std::size_t held_ = 0;
    std::uint64_t words_ = 0;
    std::uint64_t low_ = 0;
    bool halfHeld_ = false;
};
} // namespace

std::uint64_t Mesh::hash() const {
    WordHasher h;
    h.word(positions.size());
    for (const Vec3& p : positions) {
        h.real(p.x);
        h.real(p.y);
        h.real(p.z);
    }
    h.word(triangles.size());
    for (const Triangle& t : triangles)
        for (std::uint32_t v : t)
            h.half(v);
    h.endHalves();
    h.word(normals.size());
    for (const Vec3f& n : normals) {
        h.real(n.x);
        h.real(n.y);
        h.real(n.z);
    }
    h.endHalves();
    h.word(uvs.size());
    for (const Vec2f& u : uvs) {
        h.real(u.x);
        h.real(u.y);
    }
    h.endHalves();
    h.word(materials.size());
    for (std::uint32_t m : materials)
        h.half(m);
    h.endHalves();
    return h.finish();
}

double windingNumber(const Mesh& mesh, const Vec3& p) {
    // Van Oosterom and Strackee's solid angle of each triangle seen from p.
    double total = 0;
    for (const Triangle& t : mesh.triangles) {
        const Vec3 a = mesh.positions[t[0]] - p, b = mesh.positions[t[1]] - p, c = mesh.positions[t[2]] - p;
        const double la = length(a), lb = length(b), lc = length(c);
        const double num = dot(a, cross(b, c));
        const double den = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb;
        total += std::atan2(num, den);
    }
    return total / (2.0 * std::numbers::pi);
}

double distanceToSurface(const Mesh& mesh, const Vec3& p) {
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
        const auto [a, b, c] = mesh.corners(t);
        best = std::min(best, length(p - detail::closestOnTriangle(p, a, b, c)));
    }
    return best;
}

Mesh makeBox(const Vec3& lo, const Vec3& hi) {
    return makeSubdividedBox(lo, hi, 1);
}

Mesh makeSubdividedBox(const Vec3& lo, const Vec3& hi, int n) {
    Mesh m;
    if (n < 1)
        n = 1;
    // Shared vertex grid on the box surface: index by integer lattice coordinates.
    const int N = n + 1;
    std::vector<std::int64_t> index(static_cast<std::size_t>(N) * N * N, -1);
    auto vertex = [&](int i, int j, int k) {
        std::int64_t& slot = index[(static_cast<std::size_t>(i) * N + j) * N + k];
        if (slot < 0) {
            slot = static_cast<std::int64_t>(m.positions.size());
            m.positions.push_back(
                {lo.x + (hi.x - lo.x) * i / n, lo.y + (hi.y - lo.y) * j / n, lo.z + (hi.z - lo.z) * k / n});
        }
        return static_cast<std::uint32_t>(slot);
    };
    // For each face: axis a fixed at 0 or n, grid over the other two axes (u, v) with u × v = outward normal.
    struct Face {
        int axis;
        int side;
        int u;
        int v;
    };
    const Face faces[6] = {{0, 0, 2, 1}, {0, 1, 1, 2}, {1, 0, 0, 2},
                           {1, 1, 2, 0}, {2, 0, 1, 0}, {2, 1, 0, 1}};
    for (const Face& f : faces) {
        for (int a = 0; a < n; ++a)
            for (int b = 0; b < n; ++b) {
                auto at = [&](int da, int db) {
                    int c[3];
                    c[f.axis] = f.side * n;
                    c[f.u] = a + da;
                    c[f.v] = b + db;
                    return vertex(c[0], c[1], c[2]);
                };
                const std::uint32_t v00 = at(0, 0), v10 = at(1, 0), v11 = at(1, 1), v01 = at(0, 1);
                m.triangles.push_back({v00, v10, v11});
                m.triangles.push_back({v00, v11, v01});
            }
    }
    return m;
}

Mesh makeSphere(const Vec3& center, double r, int slices, int stacks) {
    Mesh m;
    slices = std::max(slices, 3);
    stacks = std::max(stacks, 2);
    m.positions.push_back(center + Vec3{0, r, 0});
    for (int i = 1; i < stacks; ++i) {
        const double phi = std::numbers::pi * i / stacks;
        for (int j = 0; j < slices; ++j) {
            const double th = 2 * std::numbers::pi * j / slices;
            m.positions.push_back(center + Vec3{r * std::sin(phi) * std::cos(th), r * std::cos(phi),
                                                r * std::sin(phi) * std::sin(th)});
        }
    }
    m.positions.push_back(center + Vec3{0, -r, 0});
    const auto ring = [&](int i, int j) {
        return static_cast<std::uint32_t>(1 + (i - 1) * slices + (j % slices));
    };
    const auto south = static_cast<std::uint32_t>(m.positions.size() - 1);
    for (int j = 0; j < slices; ++j)
        m.triangles.push_back({0, ring(1, j + 1), ring(1, j)});
    for (int i = 1; i < stacks - 1; ++i)
        for (int j = 0; j < slices; ++j) {
            m.triangles.push_back({ring(i, j), ring(i, j + 1), ring(i + 1, j + 1)});
            m.triangles.push_back({ring(i, j), ring(i + 1, j + 1), ring(i + 1, j)});
        }
    for (int j = 0; j < slices; ++j)
        m.triangles.push_back({south, ring(stacks - 1, j), ring(stacks - 1, j + 1)});
    return m;
}

Mesh makeTorus(const Vec3& center, double R, double r, int majorSegments, int minorSegments) {
    Mesh m;
    const int M = std::max(majorSegments, 3), K = std::max(minorSegments, 3);
    for (int i = 0; i < M; ++i) {
        const double u = 2 * std::numbers::pi * i / M;
        for (int j = 0; j < K; ++j) {
            const double v = 2 * std::numbers::pi * j / K;
            const double w = R + r * std::cos(v);
            m.positions.push_back(center + Vec3{w * std::cos(u), r * std::sin(v), w * std::sin(u)});
        }
    }
    const auto id = [&](int i, int j) { return static_cast<std::uint32_t>((i % M) * K + (j % K)); };
    for (int i = 0; i < M; ++i)
        for (int j = 0; j < K; ++j) {
            m.triangles.push_back({id(i, j), id(i, j + 1), id(i + 1, j + 1)});
            m.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i + 1, j)});
        }
    return m;
}

} // namespace rubble
