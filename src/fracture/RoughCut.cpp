// Rough cut faces: tessellation by edge bisection and a height field along each cut face's normal, both
// functions of data the two sides of a cut share (docs/roughness.md).

#include "RoughCut.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <tuple>
#include <unordered_map>

#include "geometry/PointBits.hpp"
#include "rubble/core/Random.hpp"

namespace rubble::detail {

void cutBasis(Vec3 n, Vec3& u, Vec3& v) {
    int big = 0;
    for (int a = 1; a < 3; ++a)
        if (std::abs(n[a]) > std::abs(n[big]))
            big = a;
    if (n[big] < 0)
        n = -n;
    int small = 0;
    for (int a = 1; a < 3; ++a)
        if (std::abs(n[a]) < std::abs(n[small]))
            small = a;
    Vec3 axis;
    axis[small] = 1;
    u = normalized(cross(axis, n));
    v = cross(n, u);
}

namespace {

/// A hash of an integer lattice point and a seed, as a value in [-1, 1).
double latticeValue(std::int64_t x, std::int64_t y, std::int64_t z, std::uint64_t seed) {
    std::uint64_t h = seed ^ (static_cast<std::uint64_t>(x) * 0x9E3779B97F4A7C15ull);
    h = (h ^ (h >> 31)) * 0xBF58476D1CE4E5B9ull ^ (static_cast<std::uint64_t>(y) * 0xC2B2AE3D27D4EB4Full);
    h = (h ^ (h >> 29)) * 0x94D049BB133111EBull ^ (static_cast<std::uint64_t>(z) * 0x165667B19E3779F9ull);
    h = (h ^ (h >> 32)) * 0xD6E8FEB86659FD93ull;
    h ^= h >> 32;
    return static_cast<double>(h >> 11) * 0x1.0p-52 - 1.0;
}

/// Quintic fade 6t^5 - 15t^4 + 10t^3 (its slope is at most 15/8).
double fade(double t) {
    return t * t * t * (t * (t * 6 - 15) + 10);
}

/// Value noise in [-1, 1]: lattice values blended by the quintic fade.
double valueNoise(const Vec3& p, std::uint64_t seed) {
    const double fx = std::floor(p.x), fy = std::floor(p.y), fz = std::floor(p.z);
    const auto ix = static_cast<std::int64_t>(fx), iy = static_cast<std::int64_t>(fy),
               iz = static_cast<std::int64_t>(fz);
    const double tx = fade(p.x - fx), ty = fade(p.y - fy), tz = fade(p.z - fz);
    double c[2][2];
    for (int dy = 0; dy < 2; ++dy)
        for (int dz = 0; dz < 2; ++dz) {
            const double a = latticeValue(ix, iy + dy, iz + dz, seed);
            const double b = latticeValue(ix + 1, iy + dy, iz + dz, seed);
            c[dy][dz] = a + (b - a) * tx;
        }
    const double c0 = c[0][0] + (c[1][0] - c[0][0]) * ty, c1 = c[0][1] + (c[1][1] - c[0][1]) * ty;
    return c0 + (c1 - c0) * tz;
}

/// The envelope slope along an outer-surface segment whose angle with the outer surface is unknown: tan 10°.
constexpr double kEnvelope = 0.17632698070846498;
/// The steepest envelope slope: tan 40°.
constexpr double kEdgeEnvelope = 0.83909963117728;
/// The least envelope slope (a cut grazing the outer surface): tan 0.5°.
constexpr double kLeastEnvelope = 0.0087268677907587893;

/// The envelope slope along a segment where a cut face meets the outer surface at the angle psi (radians, at
/// most 90°): tan(max(psi − 10°, 2 psi / 3)), between tan 0.5° and tan 40°.
double outerSlope(double psi) {
    const double alpha = std::max(psi - 10 * std::numbers::pi / 180, 2 * psi / 3);
    return std::clamp(std::tan(alpha), kLeastEnvelope, kEdgeEnvelope);
}

/// Squared distance from p to the segment ab.
double segmentDistance2(const Vec3& p, const Vec3& a, const Vec3& b) {
    const Vec3 ab = b - a;
    const double len2 = dot(ab, ab);
    double t = len2 > 0 ? dot(p - a, ab) / len2 : 0.0;
    t = std::clamp(t, 0.0, 1.0);
    const Vec3 d = p - (a + ab * t);
    return dot(d, d);
}

std::uint64_t edgeKey(std::uint32_t a, std::uint32_t b) {
    return a < b ? (std::uint64_t{a} << 32 | b) : (std::uint64_t{b} << 32 | a);
}

/// A new cut face: a face of a cell, with its plane's normal in the same direction for both sides.
struct CutFace {
    Vec3 normal; // the plane's normal, its largest component positive
    Vec3 u, v;   // cutBasis
};

/// The cells' faces and a lookup of the one a triangle lies on.
class CutFaces {
public:
    CutFaces(const std::vector<ConvexPolytope>& cells, double onPlane) : cells_(cells), onPlane_(onPlane) {
        for (const ConvexPolytope& c : cells) {
            first_.push_back(faces_.size());
            bounds_.push_back(c.bounds());
            for (const PolytopeFaceView& f : c.faces()) {
                CutFace cf{f.plane.normal, {}, {}};
                int big = 0;
                for (int a = 1; a < 3; ++a)
                    if (std::abs(cf.normal[a]) > std::abs(cf.normal[big]))
                        big = a;
                if (cf.normal[big] < 0)
                    cf.normal = -cf.normal;
                cutBasis(cf.normal, cf.u, cf.v);
                faces_.push_back(cf);
            }
        }
    }

    const CutFace& operator[](std::size_t i) const { return faces_[i]; }

    /// The envelope slope along the outline segment ab of face f: tan(max(θ/2 − 5°, θ/3)), at most tan 40°,
    /// θ the smallest angle between f's plane and the plane of another cell face holding the segment; 0 where
    /// none does (the segment is on the outer surface). A function of the segment and the cells: the same
    /// bits on both sides.
    double outlineSlope(std::size_t f, const Vec3& a, const Vec3& b) const {
        const Vec3 nf = faces_[f].normal;
        const Vec3 mid = (a + b) * 0.5;
        Aabb box;
        box.extend(a);
        box.extend(b);
        double largestCos = -1; // of the smallest angle
        for (std::size_t k = 0; k < cells_.size(); ++k) {
            if (cells_[k].empty() || !bounds_[k].overlaps(box, onPlane_))
                continue;
            for (const PolytopeFaceView& g : cells_[k].faces()) {
                const double c = std::abs(dot(g.plane.normal, nf));
                if (c > 0.99985 || std::abs(g.plane.signedDistance(a)) > onPlane_ || // coplanar: 1°
                    std::abs(g.plane.signedDistance(b)) > onPlane_ || !insidePolygon(g, mid))
                    continue;
                largestCos = std::max(largestCos, c);
            }
        }
        if (largestCos < 0)
            return 0;
        const double theta = std::acos(largestCos);
        return std::min(kEdgeEnvelope, std::tan(std::max(theta / 2 - 5 * std::numbers::pi / 180, theta / 3)));
    }

    /// The first face (in the order of the cells) that the triangle lies on, or -1. A function of the
    /// corners as a set, so both sides of a cut find the same face.
    std::int32_t find(std::array<Vec3, 3> c) const {
        std::sort(c.begin(), c.end(), lexLess);
        Aabb box;
        for (const Vec3& p : c)
            box.extend(p);
        const Vec3 centroid = (c[0] + c[1] + c[2]) * (1.0 / 3.0);
        const Vec3 tn = cross(c[1] - c[0], c[2] - c[0]);
        const double tl = length(tn);
        for (std::size_t k = 0; k < cells_.size(); ++k) {
            if (cells_[k].empty() || !bounds_[k].overlaps(box, onPlane_))
                continue;
            const PolytopeFaces faces = cells_[k].faces();
            for (std::size_t j = 0; j < faces.size(); ++j) {
                const PolytopeFaceView f = faces[j];
                if (std::abs(dot(f.plane.normal, tn)) < 0.5 * tl)
                    continue;
                bool on = true;
                for (const Vec3& p : c)
                    on &= std::abs(f.plane.signedDistance(p)) <= onPlane_;
                if (!on || !insidePolygon(f, centroid))
                    continue;
                return static_cast<std::int32_t>(first_[k] + j);
            }
        }
        return -1;
    }

private:
    bool insidePolygon(const PolytopeFaceView& f, const Vec3& p) const {
        const std::size_t n = f.corners.size();
        for (std::size_t i = 0; i < n; ++i) {
            const Vec3& a = f.corners[i];
            const Vec3 e = f.corners[(i + 1) % n] - a;
            const double el = length(e);
            if (dot(cross(e, p - a), f.plane.normal) < -onPlane_ * el)
                return false;
        }
        return true;
    }

    const std::vector<ConvexPolytope>& cells_;
    double onPlane_;
    std::vector<std::size_t> first_;
    std::vector<Aabb> bounds_; // of each cell
    std::vector<CutFace> faces_;
};

/// A triangle being refined, with its corner attributes; face -1: not a cut face (it is only split).
struct WorkTriangle {
    std::array<std::uint32_t, 3> v;
    std::array<Vec3, 3> n;
    std::array<Vec2, 3> uv;
    std::uint32_t material = 0;
    std::int32_t face = -1;
};

/// A uniform hash grid of segments (ids), cell size = the reach of the distance.
class SegmentGrid {
public:
    explicit SegmentGrid(double cell) : inv_(1.0 / cell) {}
    void add(std::uint32_t id, const Vec3& a, const Vec3& b) {
        const auto lo = cellOf(min(a, b)), hi = cellOf(max(a, b));
        for (std::int64_t x = lo[0]; x <= hi[0]; ++x)
            for (std::int64_t y = lo[1]; y <= hi[1]; ++y)
                for (std::int64_t z = lo[2]; z <= hi[2]; ++z)
                    cells_[key(x, y, z)].push_back(id);
    }
    /// Calls visit(id) for every segment with a point within one cell size of p (some more than once).
    template <class Visit>
    void near(const Vec3& p, Visit visit) const {
        const auto c = cellOf(p);
        for (std::int64_t x = c[0] - 1; x <= c[0] + 1; ++x)
            for (std::int64_t y = c[1] - 1; y <= c[1] + 1; ++y)
                for (std::int64_t z = c[2] - 1; z <= c[2] + 1; ++z)
                    if (auto it = cells_.find(key(x, y, z)); it != cells_.end())
                        for (std::uint32_t id : it->second)
                            visit(id);
    }

private:
    std::array<std::int64_t, 3> cellOf(const Vec3& p) const {
        return {static_cast<std::int64_t>(std::floor(p.x * inv_)),
                static_cast<std::int64_t>(std::floor(p.y * inv_)),
                static_cast<std::int64_t>(std::floor(p.z * inv_))};
    }
    static std::uint64_t key(std::int64_t x, std::int64_t y, std::int64_t z) {
        const auto u = [](std::int64_t a) { return static_cast<std::uint64_t>(a) & 0x1FFFFFull; };
        return u(x) << 42 | u(y) << 21 | u(z);
    }
    double inv_;
    std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> cells_;
};

/// The shared settings of one rough split.
struct RoughSettings {
    double amplitude = 0;
    double edge = 0; // longest cut-face edge after tessellation
    const RoughField* field = nullptr;
    double uvScale = 1;
};

/// The passes of tessellate's bisection at most.
constexpr int kBisectionPasses = 40;

/// The red-green template of a triangle whose edges (k, k + 1) marked in split are bisected: calls
/// emit(a, b, c) for each child, its corners numbered 0..2 and the midpoint of edge k 3 + k; p holds those
/// six points (the midpoints of edges not split unused). The two-edge template takes the shorter diagonal
/// (ties by the diagonals' corners).
template <class Emit>
void bisectionTemplate(const std::array<bool, 3>& split, const std::array<Vec3, 6>& p, Emit emit) {
    const int count = int{split[0]} + int{split[1]} + int{split[2]};
    if (count == 3) {
        emit(0, 3, 5);
        emit(3, 1, 4);
        emit(5, 4, 2);
        emit(3, 4, 5);
    } else if (count == 1) {
        const int k = split[0] ? 0 : split[1] ? 1 : 2; // split edge (k, k+1)
        const int j = (k + 1) % 3, l = (k + 2) % 3;
        emit(k, 3 + k, l);
        emit(3 + k, j, l);
    } else if (count == 2) {
        const int z = !split[0] ? 0 : !split[1] ? 1 : 2;   // the edge (z, z+1) is whole
        const int a = (z + 1) % 3, b = (z + 2) % 3, c = z; // split edges (a, b) and (b, c)
        const int m1 = 3 + a, m2 = 3 + b;
        emit(m1, b, m2);
        // Quad (a, m1, m2, c): diagonal a-m2 or m1-c, the shorter; ties by the diagonals' corners.
        const Vec3 &pa = p[a], &pc = p[c], &p1 = p[m1], &p2 = p[m2];
        const double d1 = dot(pa - p2, pa - p2), d2 = dot(p1 - pc, p1 - pc);
        bool first = d1 < d2;
        if (d1 == d2) {
            const Vec3 k1 = lexLess(pa, p2) ? pa : p2, k2 = lexLess(p1, pc) ? p1 : pc;
            first = lexLess(k1, k2);
        }
        if (first) {
            emit(a, m1, m2);
            emit(a, m2, c);
        } else {
            emit(a, m1, c);
            emit(m1, m2, c);
        }
    }
}

/// Splits the working triangles' marked edges (edge key -> midpoint vertex) by bisectionTemplate.
void splitTriangles(std::vector<WorkTriangle>& work,
                    const std::unordered_map<std::uint64_t, std::uint32_t>& mid, const std::vector<Vec3>& pos,
                    bool normals) {
    std::vector<WorkTriangle> out;
    out.reserve(work.size() * 2);
    for (const WorkTriangle& t : work) {
        std::array<std::int64_t, 3> m{-1, -1, -1}; // midpoint of edge (k, k+1)
        std::array<bool, 3> split{};
        for (int k = 0; k < 3; ++k)
            if (auto it = mid.find(edgeKey(t.v[k], t.v[(k + 1) % 3])); it != mid.end()) {
                m[k] = it->second;
                split[k] = true;
            }
        if (!split[0] && !split[1] && !split[2]) {
            out.push_back(t);
            continue;
        }
        // Corner attributes of the triangle's corners (0..2) and midpoints (3..5: of edge 0..2).
        std::array<std::uint32_t, 6> vid{};
        std::array<Vec3, 6> nn{};
        std::array<Vec2, 6> uu{};
        std::array<Vec3, 6> pp{};
        for (int k = 0; k < 3; ++k) {
            vid[k] = t.v[k];
            nn[k] = t.n[k];
            uu[k] = t.uv[k];
            pp[k] = pos[t.v[k]];
            const int j = (k + 1) % 3;
            if (m[k] >= 0) {
                vid[3 + k] = static_cast<std::uint32_t>(m[k]);
                if (normals)
                    nn[3 + k] = normalized(t.n[k] + t.n[j]);
                uu[3 + k] = {(t.uv[k].x + t.uv[j].x) * 0.5, (t.uv[k].y + t.uv[j].y) * 0.5};
                pp[3 + k] = pos[vid[3 + k]];
            }
        }
        bisectionTemplate(split, pp, [&](int a, int b, int c) {
            WorkTriangle s = t;
            s.v = {vid[a], vid[b], vid[c]};
            s.n = {nn[a], nn[b], nn[c]};
            s.uv = {uu[a], uu[b], uu[c]};
            out.push_back(s);
        });
    }
    work = std::move(out);
}

/// Adds to count the triangles that tessellate's bisection to edges of squared length at most edge2 makes
/// of the cut triangle p from this pass on (an edge splits by its length alone, so a cut triangle's share is
/// its own); stops once count exceeds limit.
void countBisected(const std::array<Vec3, 3>& p, double edge2, int pass, std::size_t limit,
                   std::size_t& count) {
    if (count > limit)
        return;
    std::array<bool, 3> split{};
    std::array<Vec3, 6> q{p[0], p[1], p[2]};
    for (int k = 0; k < 3 && pass < kBisectionPasses; ++k) {
        const Vec3& a = p[k];
        const Vec3& b = p[(k + 1) % 3];
        const Vec3 d = a - b;
        split[k] = dot(d, d) > edge2;
        if (split[k])
            q[3 + k] = (a + b) * 0.5;
    }
    if (!split[0] && !split[1] && !split[2]) {
        ++count;
        return;
    }
    bisectionTemplate(split, q, [&](int a, int b, int c) {
        countBisected({q[a], q[b], q[c]}, edge2, pass + 1, limit, count);
    });
}

/// The target edge: the estimate (from the cut area), or the least longer edge at which the bisection gives
/// no output more than budget cut triangles, counted (a fine outline adds slivers the estimate misses); the
/// longest cut edge (no bisection) when even that does not fit. cut: each output's cut triangles.
double edgeWithinBudget(const std::vector<std::vector<std::array<Vec3, 3>>>& cut, double estimate,
                        std::size_t budget) {
    const auto fits = [&](double e) {
        for (const auto& triangles : cut) {
            std::size_t count = 0;
            for (const auto& t : triangles)
                countBisected(t, e * e, 0, budget, count);
            if (count > budget)
                return false;
        }
        return true;
    };
    if (fits(estimate))
        return estimate;
    double longest = 0;
    for (const auto& triangles : cut)
        for (const auto& t : triangles)
            for (int k = 0; k < 3; ++k)
                longest = std::max(longest, length(t[k] - t[(k + 1) % 3]));
    double over = estimate, fit = estimate;
    bool ok = false;
    do {
        over = fit;
        fit = std::min(longest, fit * 1.25);
        ok = fits(fit);
    } while (!ok && fit < longest);
    if (!ok) // the cut as it is: no edge is longer than the longest
        return fit;
    for (int step = 0; step < 4; ++step) {
        const double e = 0.5 * (over + fit);
        if (fits(e))
            fit = e;
        else
            over = e;
    }
    return fit;
}

/// A face's edges in an output's sorted edge list.
struct FaceRange {
    std::int32_t face;
    std::size_t begin, end;
};

/// An outline segment of a cut face: the face and its ends' positions in lexicographic order (the same bits
/// in both outputs that hold the face).
using SegmentKey = std::tuple<std::int32_t, double, double, double, double, double, double>;

SegmentKey segmentKey(std::int32_t face, Vec3 a, Vec3 b) {
    if (lexLess(b, a))
        std::swap(a, b);
    return {face, a.x, a.y, a.z, b.x, b.y, b.z};
}

/// One output being roughened: its triangles around the cut, tessellated, and its cut faces' outlines.
struct RoughOutput {
    Mesh* mesh = nullptr;
    VolumeIntegrals* integrals = nullptr;
    std::size_t inputTriangles = 0;
    std::vector<std::uint8_t> taken; // input triangles that work replaces
    std::vector<WorkTriangle> work;
    std::vector<std::tuple<std::int32_t, std::uint64_t, std::uint32_t>> edges; // face, edge, triangle; sorted
    std::vector<FaceRange> ranges;                                             // per cut face, in edges
    std::vector<std::uint8_t> fixed;                                           // outline vertices

    /// True when edges[i] (of the face range r) is on the face's outline: used by one of its triangles.
    bool isOutline(std::size_t i, const FaceRange& r) const {
        const std::uint64_t e = std::get<1>(edges[i]);
        return !((i > r.begin && std::get<1>(edges[i - 1]) == e) ||
                 (i + 1 < r.end && std::get<1>(edges[i + 1]) == e));
    }
};

/// Takes an output's cut triangles (faceOf >= 0) and the triangles along their edges, bisects every cut-face
/// edge longer than the target until none is, finds each cut face's outline and gives the cut faces the UVs
/// of their flat positions.
void tessellate(RoughOutput& o, Mesh& m, const std::vector<std::int32_t>& faceOf, const CutFaces& faces,
                const RoughSettings& s) {
    o.mesh = &m;
    const std::size_t nT = m.triangles.size();
    o.inputTriangles = nT;
    const bool normals = m.hasNormals();
    std::vector<std::uint8_t> cutVertex(m.positions.size(), 0);
    for (std::size_t t = 0; t < nT; ++t)
        if (faceOf[t] >= 0)
            for (std::uint32_t v : m.triangles[t])
                cutVertex[v] = 1;
    o.taken.assign(nT, 0);
    for (std::size_t t = 0; t < nT; ++t) {
        const Triangle& tri = m.triangles[t];
        const int onCut = cutVertex[tri[0]] + cutVertex[tri[1]] + cutVertex[tri[2]];
        if (faceOf[t] < 0 && onCut < 2)
            continue;
        o.taken[t] = 1;
        WorkTriangle w;
        w.v = {tri[0], tri[1], tri[2]};
        for (std::size_t k = 0; k < 3; ++k) {
            if (normals)
                w.n[k] = m.normals[3 * t + k];
            w.uv[k] = m.uvs[3 * t + k];
        }
        w.material = m.materials[t];
        w.face = faceOf[t];
        o.work.push_back(w);
        if (o.integrals)
            o.integrals->remove(m, t);
    }
    std::vector<WorkTriangle>& work = o.work;
    // Bisect every cut-face edge longer than the target until none is.
    const double edge2 = s.edge * s.edge;
    for (int pass = 0; pass < kBisectionPasses; ++pass) {
        std::unordered_map<std::uint64_t, std::uint32_t> mid;
        for (const WorkTriangle& t : work) {
            if (t.face < 0)
                continue;
            for (int k = 0; k < 3; ++k) {
                const std::uint32_t a = t.v[k], b = t.v[(k + 1) % 3];
                const Vec3 d = m.positions[a] - m.positions[b];
                if (dot(d, d) <= edge2)
                    continue;
                if (auto [it, fresh] = mid.emplace(edgeKey(a, b), 0u); fresh) {
                    it->second = static_cast<std::uint32_t>(m.positions.size());
                    const std::uint32_t lo = std::min(a, b), hi = std::max(a, b);
                    m.positions.push_back((m.positions[lo] + m.positions[hi]) * 0.5);
                }
            }
        }
        if (mid.empty())
            break;
        splitTriangles(work, mid, m.positions, normals);
    }
    // Per cut face: its outline (edges of one of its triangles only); outline vertices stay.
    for (std::uint32_t i = 0; i < work.size(); ++i)
        if (work[i].face >= 0)
            for (int k = 0; k < 3; ++k)
                o.edges.emplace_back(work[i].face, edgeKey(work[i].v[k], work[i].v[(k + 1) % 3]), i);
    std::sort(o.edges.begin(), o.edges.end());
    o.fixed.assign(m.positions.size(), 0);
    for (std::size_t i = 0; i < o.edges.size();) {
        std::size_t j = i;
        while (j < o.edges.size() && std::get<0>(o.edges[j]) == std::get<0>(o.edges[i]))
            ++j;
        o.ranges.push_back({std::get<0>(o.edges[i]), i, j});
        i = j;
    }
    for (const FaceRange& r : o.ranges)
        for (std::size_t i = r.begin; i < r.end; ++i)
            if (o.isOutline(i, r)) {
                const std::uint64_t e = std::get<1>(o.edges[i]);
                o.fixed[e >> 32] = 1;
                o.fixed[e & 0xFFFFFFFFu] = 1;
            }
    // UVs of the flat cut (continuous across the displaced surface).
    for (WorkTriangle& t : work)
        if (t.face >= 0) {
            const CutFace& f = faces[static_cast<std::size_t>(t.face)];
            for (int k = 0; k < 3; ++k) {
                const Vec3& p = m.positions[t.v[k]];
                t.uv[k] = {dot(p, f.u) * s.uvScale, dot(p, f.v) * s.uvScale};
            }
        }
}

/// Records, for every outline segment of a cut face that a triangle not of a cut face (the outer surface)
/// borders in this output, the largest |cos| of the angle between that triangle's plane and the face's.
void recordOuterAngles(const RoughOutput& o, const CutFaces& faces, std::map<SegmentKey, double>& cosines) {
    const std::vector<Vec3>& pos = o.mesh->positions;
    std::unordered_map<std::uint64_t, std::uint32_t> outer; // edge -> a triangle not of a cut face
    for (std::uint32_t i = 0; i < o.work.size(); ++i)
        if (o.work[i].face < 0)
            for (int k = 0; k < 3; ++k)
                outer[edgeKey(o.work[i].v[k], o.work[i].v[(k + 1) % 3])] = i;
    for (const FaceRange& r : o.ranges)
        for (std::size_t i = r.begin; i < r.end; ++i) {
            if (!o.isOutline(i, r))
                continue;
            const std::uint64_t e = std::get<1>(o.edges[i]);
            const auto it = outer.find(e);
            if (it == outer.end())
                continue;
            const WorkTriangle& t = o.work[it->second];
            const Vec3 n = cross(pos[t.v[1]] - pos[t.v[0]], pos[t.v[2]] - pos[t.v[0]]);
            const double l = length(n);
            if (!(l > 0))
                continue;
            const double c = std::abs(dot(n, faces[static_cast<std::size_t>(r.face)].normal)) / l;
            auto [slot, fresh] = cosines.emplace(
                segmentKey(r.face, pos[static_cast<std::uint32_t>(e >> 32)], pos[e & 0xFFFFFFFFu]), c);
            if (!fresh)
                slot->second = std::max(slot->second, c);
        }
}

/// Moves every vertex inside a cut face along the face's normal by the enveloped height field, then sets the
/// cut faces' normals and writes the output back: its untouched triangles in their order, then the worked
/// ones.
void displace(RoughOutput& o, const CutFaces& faces, const RoughSettings& s,
              const std::map<SegmentKey, double>& cosines) {
    Mesh& m = *o.mesh;
    const bool normals = m.hasNormals();
    std::vector<std::uint32_t> inner;
    for (const FaceRange& r : o.ranges) {
        std::vector<std::pair<std::uint32_t, std::uint32_t>> outline;
        std::vector<double> slope2; // squared envelope slope of each outline segment
        inner.clear();
        Aabb box;
        double least = kEdgeEnvelope;
        for (std::size_t i = r.begin; i < r.end; ++i) {
            const std::uint64_t e = std::get<1>(o.edges[i]);
            const auto a = static_cast<std::uint32_t>(e >> 32),
                       b = static_cast<std::uint32_t>(e & 0xFFFFFFFFu);
            box.extend(m.positions[a]);
            box.extend(m.positions[b]);
            if (o.isOutline(i, r)) { // ends in the order of their positions: the same bits both sides
                const bool swap = lexLess(m.positions[b], m.positions[a]);
                outline.emplace_back(swap ? b : a, swap ? a : b);
                const Vec3 &p = m.positions[outline.back().first], &q = m.positions[outline.back().second];
                double k = faces.outlineSlope(static_cast<std::size_t>(r.face), p, q);
                if (k == 0) { // on the outer surface: its angle, as both sides recorded it
                    const auto it = cosines.find(segmentKey(r.face, p, q));
                    k = it == cosines.end() ? kEnvelope : outerSlope(std::acos(std::min(1.0, it->second)));
                }
                least = std::min(least, k);
                slope2.push_back(k * k);
            }
            for (std::uint32_t v : {a, b})
                if (!o.fixed[v])
                    inner.push_back(v);
        }
        std::sort(inner.begin(), inner.end());
        inner.erase(std::unique(inner.begin(), inner.end()), inner.end());
        // The envelope: the least over the outline's segments of slope × distance, at most 2 amplitudes; a
        // segment farther than the reach cannot lower it.
        const double cap2 = 4 * s.amplitude * s.amplitude;
        const double reach = std::min(2 * s.amplitude / least, box.diagonal());
        if (!(reach > 0))
            continue;
        SegmentGrid grid(reach);
        for (std::uint32_t id = 0; id < outline.size(); ++id)
            grid.add(id, m.positions[outline[id].first], m.positions[outline[id].second]);
        const Vec3 n = faces[static_cast<std::size_t>(r.face)].normal;
        for (const std::uint32_t v : inner) {
            Vec3& p = m.positions[v];
            double bound2 = cap2;
            grid.near(p, [&](std::uint32_t id) {
                bound2 = std::min(bound2, slope2[id] * segmentDistance2(p, m.positions[outline[id].first],
                                                                        m.positions[outline[id].second]));
            });
            const double bound = std::sqrt(bound2);
            p = p + n * (bound * std::tanh(s.amplitude * (*s.field)(p) / bound));
        }
    }
    std::vector<WorkTriangle>& work = o.work;
    const std::size_t nT = o.inputTriangles;
    const std::vector<std::uint8_t>& taken = o.taken;
    VolumeIntegrals* integrals = o.integrals;
    // Normals of the displaced surface: smooth across a cut face, its own at the outline.
    if (normals) {
        std::unordered_map<std::uint64_t, Vec3> sum; // (face, vertex) -> area-weighted normal
        auto key = [](std::int32_t face, std::uint32_t v) {
            return static_cast<std::uint64_t>(static_cast<std::uint32_t>(face)) << 32 | v;
        };
        for (const WorkTriangle& t : work)
            if (t.face >= 0) {
                const Vec3 tn = cross(m.positions[t.v[1]] - m.positions[t.v[0]],
                                      m.positions[t.v[2]] - m.positions[t.v[0]]);
                for (std::uint32_t v : t.v)
                    sum[key(t.face, v)] += tn;
            }
        for (WorkTriangle& t : work)
            if (t.face >= 0)
                for (int k = 0; k < 3; ++k)
                    t.n[k] = normalized(sum[key(t.face, t.v[k])]);
    }
    // The untouched triangles in their order, then the worked ones.
    Mesh out;
    out.positions = std::move(m.positions);
    out.materialNames = std::move(m.materialNames);
    const std::size_t kept = nT - static_cast<std::size_t>(std::count(taken.begin(), taken.end(), 1));
    out.triangles.reserve(kept + work.size());
    out.uvs.reserve(3 * (kept + work.size()));
    out.materials.reserve(kept + work.size());
    if (normals)
        out.normals.reserve(3 * (kept + work.size()));
    for (std::size_t t = 0; t < nT; ++t) {
        if (taken[t])
            continue;
        out.triangles.push_back(m.triangles[t]);
        out.materials.push_back(m.materials[t]);
        out.uvs.insert(out.uvs.end(), m.uvs.begin() + 3 * t, m.uvs.begin() + 3 * t + 3);
        if (normals)
            out.normals.insert(out.normals.end(), m.normals.begin() + 3 * t, m.normals.begin() + 3 * t + 3);
    }
    for (const WorkTriangle& t : work) {
        out.triangles.push_back({t.v[0], t.v[1], t.v[2]});
        out.materials.push_back(t.material);
        for (int k = 0; k < 3; ++k) { // refined in double, stored in float
            out.uvs.emplace_back(t.uv[k]);
            if (normals)
                out.normals.emplace_back(t.n[k]);
        }
        if (integrals)
            integrals->add(out.positions[t.v[0]], out.positions[t.v[1]], out.positions[t.v[2]]);
    }
    m = std::move(out);
}
} // namespace

RoughField::RoughField(const Roughness& r, double featureSize, int octavesUsed, const Vec3& grain)
    : seed_(r.seed), frequency_(1.0 / featureSize), gain_(std::pow(2.0, -r.hurst)), norm_(0),
      octaves_(octavesUsed), squash_(1.0 / r.grainStretch - 1.0), grain_(normalized(grain)) {
    double sum = 0, weight = 1;
    for (int k = 0; k < octavesUsed; ++k, weight *= gain_)
        sum += weight;
    norm_ = 1.0 / sum;
}

double RoughField::operator()(const Vec3& p) const {
    Vec3 q = p * frequency_;
    if (squash_ != 0)
        q = q + grain_ * (squash_ * dot(q, grain_));
    double value = 0, weight = 1;
    for (int k = 0; k < octaves_; ++k, weight *= gain_, q = q * 2.0)
        value += weight * valueNoise(q, mixSeed(seed_, static_cast<std::uint64_t>(k)));
    return value * norm_;
}

namespace {

/// roughenSplit on these outputs; the first one's integrals (or null) are kept exact.
RoughCutReport roughenOutputs(const std::vector<Mesh*>& outputs, VolumeIntegrals* firstIntegrals,
                              const std::vector<ConvexPolytope>& cells, const Roughness& r, double uvScale,
                              const Aabb& meshBox, double onPlane) {
    RoughCutReport report;
    // The cell size: the cube root of the cells' mean volume.
    double volume = 0;
    int count = 0;
    for (const ConvexPolytope& c : cells)
        if (!c.empty()) {
            volume += c.volume();
            ++count;
        }
    if (count == 0 || !(volume > 0))
        return report;
    const double cellSize = std::cbrt(volume / count);
    const double scale = r.relative ? cellSize : 1.0;
    report.amplitude = r.amplitude * scale;
    report.featureSize = r.featureSize > 0 ? r.featureSize * scale : 8 * report.amplitude;
    if (!(report.amplitude > 0))
        return report;

    const CutFaces faces(cells, onPlane);
    std::vector<std::vector<std::int32_t>> faceOf(outputs.size());
    std::vector<std::vector<std::array<Vec3, 3>>> cut(outputs.size()); // each output's cut triangles
    Aabb focus;
    for (const ConvexPolytope& c : cells)
        focus.extend(c.bounds());
    focus = {focus.lo - Vec3{1, 1, 1} * onPlane, focus.hi + Vec3{1, 1, 1} * onPlane};
    double largestCut = 0; // the largest cut area of one output
    for (std::size_t o = 0; o < outputs.size(); ++o) {
        const Mesh& m = *outputs[o];
        faceOf[o].assign(m.triangles.size(), -1);
        if (!m.hasMaterials() || m.uvs.size() != 3 * m.triangles.size())
            continue;
        double area = 0;
        for (std::size_t t = 0; t < m.triangles.size(); ++t) {
            if (m.materials[t] != kInteriorMaterial)
                continue;
            const auto c = m.corners(t);
            if (!focus.contains(c[0]) || !focus.contains(c[1]) || !focus.contains(c[2]))
                continue;
            faceOf[o][t] = faces.find(c);
            if (faceOf[o][t] < 0)
                continue;
            area += 0.5 * length(cross(c[1] - c[0], c[2] - c[0]));
            cut[o].push_back(c);
        }
        largestCut = std::max(largestCut, area);
    }
    // Edges resolve the finest octave by three; the budget coarsens them (estimated from the cut area, then
    // counted) and drops the octaves they miss.
    const double finest = report.featureSize / std::ldexp(1.0, r.octaves - 1);
    const double budgetEdge = std::sqrt(largestCut / (0.07 * r.maxTrianglesPerPiece));
    report.edge = edgeWithinBudget(cut, std::max(finest / 3, budgetEdge),
                                   static_cast<std::size_t>(r.maxTrianglesPerPiece));
    report.octaves = 1;
    while (report.octaves < r.octaves &&
           report.featureSize / std::ldexp(1.0, report.octaves) >= 3 * report.edge)
        ++report.octaves;
    Vec3 grain = r.grain;
    if (length(grain) == 0) {
        const Vec3 ext = meshBox.hi - meshBox.lo;
        grain = ext.x >= ext.y && ext.x >= ext.z ? Vec3{1, 0, 0}
                : ext.y >= ext.z                 ? Vec3{0, 1, 0}
                                                 : Vec3{0, 0, 1};
    }
    const RoughField field(r, report.featureSize, report.octaves, grain);
    const RoughSettings s{report.amplitude, report.edge, &field, uvScale};
    // Tessellate every output, record the outer surface's angle along each cut face's outline from both
    // sides, then displace: the two sides of a segment read the same recorded angle.
    std::vector<RoughOutput> rough;
    for (std::size_t o = 0; o < outputs.size(); ++o) {
        if (std::none_of(faceOf[o].begin(), faceOf[o].end(), [](std::int32_t f) { return f >= 0; }))
            continue;
        rough.emplace_back();
        rough.back().integrals = o == 0 ? firstIntegrals : nullptr;
        tessellate(rough.back(), *outputs[o], faceOf[o], faces, s);
    }
    std::map<SegmentKey, double> cosines;
    for (const RoughOutput& o : rough)
        recordOuterAngles(o, faces, cosines);
    for (RoughOutput& o : rough) {
        displace(o, faces, s, cosines);
        for (std::uint32_t mat : o.mesh->materials)
            report.faces += mat == kInteriorMaterial ? 1 : 0;
    }
    return report;
}

} // namespace

RoughCutReport roughenSplit(SplitResult& split, const std::vector<ConvexPolytope>& cells, const Roughness& r,
                            double uvScale, const Aabb& meshBox, double onPlane) {
    std::vector<Mesh*> outputs{&split.remainder};
    for (Mesh& m : split.inside)
        outputs.push_back(&m);
    return roughenOutputs(outputs, split.remainderIntegrals ? &*split.remainderIntegrals : nullptr, cells, r,
                          uvScale, meshBox, onPlane);
}

RoughCutReport roughenEdit(SplitEdit& split, const Mesh& mesh, const std::vector<ConvexPolytope>& cells,
                           const Roughness& r, double uvScale, const Aabb& meshBox, double onPlane) {
    // The remainder's new triangles as a mesh of their own, numbered in order of first use.
    RemainderEdit& edit = split.remainder;
    const auto nV = static_cast<std::uint32_t>(mesh.positions.size());
    Mesh local;
    std::unordered_map<std::uint32_t, std::uint32_t> toLocal;
    std::vector<std::uint32_t> toGlobal;
    local.triangles = std::move(edit.added.triangles);
    for (Triangle& tri : local.triangles)
        for (std::uint32_t& v : tri) {
            auto [it, fresh] = toLocal.emplace(v, static_cast<std::uint32_t>(toGlobal.size()));
            if (fresh) {
                toGlobal.push_back(v);
                local.positions.push_back(v < nV ? mesh.positions[v] : edit.newPositions[v - nV]);
            }
            v = it->second;
        }
    local.normals = std::move(edit.added.normals);
    local.uvs = std::move(edit.added.uvs);
    local.materials = std::move(edit.added.materials);
    std::vector<Mesh*> outputs{&local};
    for (Mesh& m : split.inside)
        outputs.push_back(&m);
    const RoughCutReport report =
        roughenOutputs(outputs, &split.remainderIntegrals, cells, r, uvScale, meshBox, onPlane);
    // Back into the edit: moved points in place, the bisections' points after the edit's own.
    for (std::size_t v = 0; v < toGlobal.size(); ++v)
        if (toGlobal[v] >= nV)
            edit.newPositions[toGlobal[v] - nV] = local.positions[v];
    for (std::size_t v = toGlobal.size(); v < local.positions.size(); ++v) {
        toGlobal.push_back(nV + static_cast<std::uint32_t>(edit.newPositions.size()));
        edit.newPositions.push_back(local.positions[v]);
    }
    for (Triangle& tri : local.triangles)
        for (std::uint32_t& v : tri)
            v = toGlobal[v];
    edit.added = {std::move(local.triangles), std::move(local.normals), std::move(local.uvs),
                  std::move(local.materials)};
    return report;
}

} // namespace rubble::detail
