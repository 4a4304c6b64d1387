// Lossless simplification of flat regions (see MeshSimplify.hpp). Everything is local to the focus box: the
// cost follows the part of the surface a fracture changed, not the size of the piece.
//
// 1. Local triangles: those with a corner in the focus; a directed-edge map over them finds twins.
// 2. A vertex in the focus is removable when its triangles form one closed fan that is either one flat arc
//    (compatible neighbours: same material, plane, normals and affine texture map; the arc checked against
//    one plane and one least-squares texture map) or two flat arcs split by two collinear edges (a vertex in
//    the middle of a straight crease; both sides lose it).
// 3. The triangles around removed vertices form patches; each patch (split by incompatible edges) is
//    triangulated anew from its boundary chains, from kept vertex to kept vertex (constrained Delaunay in its
//    plane, inside = odd number of boundary crossings from outside). The new triangles must be
//    counter-clockwise, cover the same area and close up exactly with the chains. A patch that fails keeps
//    its vertices (and so do its neighbours: everything is redone until no patch fails).
//    Each patch and its replacement must also enclose no volume together (they share their boundary).

#include "rubble/geometry/MeshSimplify.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "geometry/PlanarTriangulation.hpp"
#include "geometry/TopologyEdit.hpp"

namespace rubble {

namespace {

using Tri = std::array<std::uint32_t, 3>;

constexpr std::uint32_t kNone = 0xFFFFFFFFu;

std::uint64_t directed(std::uint32_t a, std::uint32_t b) {
    return (static_cast<std::uint64_t>(a) << 32) | b;
}

class Simplifier {
public:
    Simplifier(const Mesh& mesh, const PlanarSimplifyParams& params) : m_(mesh), params_(params) {}

    /// The simplified mesh, or false when the input is to be returned as it is. With inPlace (the input
    /// itself), the result is written over the input when it fits (editedInPlace()), else into out.
    bool run(Mesh& out, PlanarSimplifyReport& report, Mesh* inPlace = nullptr);
    /// run() wrote the result over the input.
    bool editedInPlace() const { return editedInPlace_; }

private:
    const Mesh& m_;
    PlanarSimplifyParams params_;
    double planeTol_ = 0, diag_ = 0;
    // Per local triangle t and edge k (3t + k): the triangle across, or kNone.
    std::vector<std::uint32_t> twin_;
    std::vector<char> inFocus_;             // per vertex: a focus vertex of a local triangle (it has a star)
    std::vector<std::uint32_t> starVertex_; // those vertices, in order of first use
    detail::CornersByVertex corners_;       // the local triangles' corners by vertex, in triangle order
    std::vector<Vec3> normal_;              // per local triangle: triangleNormal, computed once
    std::vector<char> isRemoved_;           // per vertex
    mutable std::vector<std::uint32_t> patchStamp_; // per triangle: the stamp of the last patch it was in
    mutable std::uint32_t stamp_ = 0;
    std::vector<std::uint32_t> group_;       // per triangle: its patch (while patches are formed)
    mutable std::vector<std::uint32_t> fan_; // removable()'s buffers, reused
    mutable std::vector<bool> crease_;
    std::vector<std::uint32_t> removed_; // the removed vertices, in the order found
    bool wasRemoved(std::uint32_t v) const { return isRemoved_[v] != 0; }
    /// The star of focus vertex v as its corners (triangle c / 3), in triangle order; empty for another.
    std::span<const std::uint32_t> trianglesAt(std::uint32_t v) const {
        if (!inFocus_[v])
            return {};
        return corners_.at(v);
    }
    bool editedInPlace_ = false;

    std::uint32_t twinTri(std::uint32_t t, int k) const { // triangle across edge k of t, or kNone
        return twin_[3 * static_cast<std::size_t>(t) + static_cast<std::size_t>(k)];
    }
    bool compatible(std::uint32_t t, std::uint32_t s) const;
    bool flat(const std::vector<std::uint32_t>& tris) const;
    bool removable(std::uint32_t v) const;
    bool retriangulate(const std::vector<std::uint32_t>& patch, std::vector<Tri>& out) const;
    using PatchOf = std::vector<std::pair<std::uint32_t, std::uint32_t>>; // (triangle, patch), by triangle
    void assemble(Mesh& m, bool inPlace, const PatchOf& patchOf,
                  const std::vector<std::vector<std::uint32_t>>& patches,
                  const std::vector<std::vector<Tri>>& fresh, PlanarSimplifyReport& report) const;
};

/// Whether each patch's new triangles fit, front to back, into the slots of the triangles already passed
/// when its first triangle is reached (then the output can be written over the input).
bool fitsInPlace(const std::vector<std::pair<std::uint32_t, std::uint32_t>>& patchOf,
                 const std::vector<std::vector<std::uint32_t>>& patches,
                 const std::vector<std::vector<Tri>>& fresh) {
    std::size_t written = 0, next = 0;
    for (const auto& [t, p] : patchOf) {
        written += t - next;
        next = t + 1;
        if (patches[p].front() == t && (written += fresh[p].size()) > next)
            return false;
    }
    return true;
}

/// Can triangles t and s (sharing an edge) be one flat region? The plane is the larger triangle's.
bool Simplifier::compatible(std::uint32_t t, std::uint32_t s) const {
    const Vec3 nt = normal_[t], ns = normal_[s];
    if (m_.material(t) != m_.material(s) || dot(nt, ns) <= 0)
        return false;
    const bool tBig = lengthSquared(nt) >= lengthSquared(ns);
    const std::uint32_t r = tBig ? t : s, o = tBig ? s : t;
    const Vec3 n = normalized(tBig ? nt : ns);
    const auto rc = m_.corners(r), oc = m_.corners(o);
    for (const Vec3& p : oc)
        if (!(std::abs(dot(n, p - rc[0])) <= planeTol_))
            return false;
    if (m_.hasNormals())
        for (std::size_t k = 0; k < 3; ++k)
            for (std::uint32_t x : {t, s}) {
                const Vec3 d = Vec3(m_.normals[3 * x + k]) - m_.normals[3 * t];
                if (!(std::max({std::abs(d.x), std::abs(d.y), std::abs(d.z)}) <= 1e-6))
                    return false;
            }
    if (m_.hasUvs()) {
        // r's affine texture map at o's corners (barycentric coordinates in r's plane).
        const Vec3 e1 = rc[1] - rc[0], e2 = rc[2] - rc[0];
        const double a11 = dot(e1, e1), a12 = dot(e1, e2), a22 = dot(e2, e2), det = a11 * a22 - a12 * a12;
        if (!(det > 0))
            return false;
        const Vec2f* ru = &m_.uvs[3 * r];
        for (std::size_t k = 0; k < 3; ++k) {
            const Vec3 d = oc[k] - rc[0];
            const double b1 = dot(d, e1), b2 = dot(d, e2);
            const double l1 = (a22 * b1 - a12 * b2) / det, l2 = (a11 * b2 - a12 * b1) / det, l0 = 1 - l1 - l2;
            const Vec2 want{l0 * ru[0].x + l1 * ru[1].x + l2 * ru[2].x,
                            l0 * ru[0].y + l1 * ru[1].y + l2 * ru[2].y};
            const Vec2 have = m_.uvs[3 * o + k];
            const double tol = params_.uvTolerance * std::max({1.0, std::abs(have.x), std::abs(have.y)});
            if (!(std::abs(want.x - have.x) <= tol) || !(std::abs(want.y - have.y) <= tol))
                return false;
        }
    }
    return true;
}

/// Every corner on the plane of the largest triangle and the texture coordinates one affine map (least
/// squares), so tolerances cannot drift along a chain of compatible neighbours.
bool Simplifier::flat(const std::vector<std::uint32_t>& tris) const {
    std::uint32_t best = tris.front();
    for (std::uint32_t t : tris)
        if (lengthSquared(normal_[t]) > lengthSquared(normal_[best]))
            best = t;
    const Vec3 n = normalized(normal_[best]), o = m_.positions[m_.triangles[best][0]];
    Vec3 u, v;
    detail::planeBasis(n, u, v);
    double s[3][3] = {}, su[3] = {}, sv[3] = {};
    double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
    for (std::uint32_t t : tris)
        for (std::size_t k = 0; k < 3; ++k) {
            const Vec3 d = m_.positions[m_.triangles[t][k]] - o;
            if (!(std::abs(dot(n, d)) <= planeTol_))
                return false;
            if (!m_.hasUvs())
                continue;
            const double q[3] = {dot(d, u), dot(d, v), 1};
            const Vec2 uv = m_.uvs[3 * t + k];
            for (int a = 0; a < 3; ++a) {
                for (int b = 0; b < 3; ++b)
                    s[a][b] += q[a] * q[b];
                su[a] += q[a] * uv.x;
                sv[a] += q[a] * uv.y;
            }
            lo[0] = std::min(lo[0], uv.x), hi[0] = std::max(hi[0], uv.x);
            lo[1] = std::min(lo[1], uv.y), hi[1] = std::max(hi[1], uv.y);
        }
    if (!m_.hasUvs())
        return true;
    auto det3 = [](const double a[3][3]) {
        return a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
               a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
               a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    };
    const double d = det3(s);
    if (!(std::abs(d) > 0))
        return false;
    auto solve = [&](const double rhs[3], double c[3]) { // Cramer's rule
        for (int col = 0; col < 3; ++col) {
            double a[3][3];
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j)
                    a[i][j] = j == col ? rhs[i] : s[i][j];
            c[col] = det3(a) / d;
        }
    };
    double cu[3], cv[3];
    solve(su, cu);
    solve(sv, cv);
    // the fit's own tolerance, and the float rounding of the stored coordinates
    const double stored = 4 * std::numeric_limits<float>::epsilon() *
                          std::max({std::abs(lo[0]), std::abs(hi[0]), std::abs(lo[1]), std::abs(hi[1])});
    const double tol = params_.uvTolerance * std::max({1.0, hi[0] - lo[0], hi[1] - lo[1]}) + stored;
    for (std::uint32_t t : tris)
        for (std::size_t k = 0; k < 3; ++k) {
            const Vec3 dd = m_.positions[m_.triangles[t][k]] - o;
            const double x = dot(dd, u), y = dot(dd, v);
            const Vec2 uv = m_.uvs[3 * t + k];
            if (!(std::abs(cu[0] * x + cu[1] * y + cu[2] - uv.x) <= tol) ||
                !(std::abs(cv[0] * x + cv[1] * y + cv[2] - uv.y) <= tol))
                return false;
        }
    return true;
}

bool Simplifier::removable(std::uint32_t v) const {
    const std::span<const std::uint32_t> star = trianglesAt(v);
    if (star.empty())
        return false;
    // Walk the fan: from triangle t (corner k at v) to the triangle across its edge (previous corner → v).
    std::vector<std::uint32_t>& fan = fan_;
    std::vector<bool>& crease =
        crease_; // crease[i]: the edge between fan[i] and fan[i + 1] separates two regions
    fan.clear();
    crease.clear();
    const std::uint32_t start = star.front() / 3;
    std::uint32_t t = start;
    do {
        const Tri& tri = m_.triangles[t];
        const int k = tri[0] == v ? 0 : tri[1] == v ? 1 : 2;
        const std::uint32_t next = twinTri(t, (k + 2) % 3);
        if (next == kNone || fan.size() >= star.size())
            return false;
        fan.push_back(t);
        crease.push_back(!compatible(t, next));
        t = next;
    } while (t != start);
    if (fan.size() != star.size())
        return false; // more than one fan: the surface touches itself here
    const auto creases = std::count(crease.begin(), crease.end(), true);
    if (creases == 0)
        return flat(fan);
    if (creases != 2)
        return false;
    // Two arcs; the vertex must lie between the far ends of the two crease edges.
    std::vector<std::uint32_t> arcs[2], ends;
    int arc = 0;
    for (std::size_t i = 0; i < fan.size(); ++i) {
        arcs[arc].push_back(fan[i]);
        if (crease[i]) {
            const Tri& tri = m_.triangles[fan[i]];
            const int k = tri[0] == v ? 0 : tri[1] == v ? 1 : 2;
            ends.push_back(tri[static_cast<std::size_t>((k + 2) % 3)]);
            arc ^= 1;
        }
    }
    const Vec3 &p = m_.positions[v], &a = m_.positions[ends[0]], &b = m_.positions[ends[1]];
    const Vec3 d = b - a;
    const double len2 = lengthSquared(d);
    if (!(len2 > 0))
        return false;
    const double s = dot(p - a, d) / len2;
    if (!(s > 0 && s < 1) || !(length(cross(p - a, d)) <= planeTol_ * std::sqrt(len2)))
        return false;
    // The first arc may continue at the end of the fan (it wrapped around).
    return flat(arcs[0]) && flat(arcs[1]);
}

/// Triangulates a patch (compatible triangles around removed vertices) without those vertices.
bool Simplifier::retriangulate(const std::vector<std::uint32_t>& patch, std::vector<Tri>& tris) const {
    const std::uint32_t stamp = ++stamp_;
    for (std::uint32_t t : patch)
        patchStamp_[t] = stamp;
    auto inPatch = [&](std::uint32_t t) { return patchStamp_[t] == stamp; };
    auto outside = [&](std::uint32_t t, int k) {
        const std::uint32_t o = twinTri(t, k);
        return o == kNone || !inPatch(o);
    };
    // Boundary chains, from kept vertex to kept vertex.
    std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;
    std::unordered_set<std::uint64_t> constraint;
    std::vector<std::uint32_t> ends;
    for (std::uint32_t t : patch)
        for (int k = 0; k < 3; ++k) {
            const Tri& tri = m_.triangles[t];
            const std::uint32_t a = tri[static_cast<std::size_t>(k)];
            if (!outside(t, k) || wasRemoved(a))
                continue;
            std::uint32_t x = tri[static_cast<std::size_t>((k + 1) % 3)];
            std::size_t steps = 0;
            while (wasRemoved(x)) { // the one boundary edge of the patch leaving x
                std::uint32_t next = kNone;
                for (std::uint32_t corner : trianglesAt(x)) {
                    const std::uint32_t s = corner / 3;
                    if (!inPatch(s))
                        continue;
                    const Tri& st = m_.triangles[s];
                    const int j = st[0] == x ? 0 : st[1] == x ? 1 : 2;
                    if (outside(s, j)) {
                        if (next != kNone)
                            return false;
                        next = st[static_cast<std::size_t>((j + 1) % 3)];
                    }
                }
                if (next == kNone || ++steps > 3 * patch.size())
                    return false;
                x = next;
            }
            if (a == x || !constraint.insert(directed(a, x)).second || constraint.count(directed(x, a)))
                return false;
            edges.emplace_back(a, x);
            ends.push_back(a);
            ends.push_back(x);
        }
    if (edges.size() < 3)
        return false;
    std::sort(ends.begin(), ends.end());
    ends.erase(std::unique(ends.begin(), ends.end()), ends.end());
    for (std::uint32_t t : patch) // nothing kept inside
        for (std::uint32_t v : m_.triangles[t])
            if (!wasRemoved(v) && !std::binary_search(ends.begin(), ends.end(), v))
                return false;

    std::uint32_t best = patch.front();
    double before = 0;
    for (std::uint32_t t : patch) {
        before += length(normal_[t]);
        if (lengthSquared(normal_[t]) > lengthSquared(normal_[best]))
            best = t;
    }
    std::vector<detail::RegionEdge> region;
    region.reserve(edges.size());
    for (const auto& [a, b] : edges)
        region.push_back({a, b, 1u});
    const std::size_t first = tris.size();
    if (detail::triangulatePlanarRegion(
            region, normal_[best], [&](std::uint32_t id) { return m_.positions[id]; }, tris))
        return false;
    // The new triangles: counter-clockwise, the same area, and every directed edge either inside (its reverse
    // is there too) or one of the chains, each exactly once — so the patch closes up with its surroundings.
    double area = 0;
    std::unordered_map<std::uint64_t, int> used;
    for (std::size_t i = first; i < tris.size(); ++i) {
        const Tri& t = tris[i];
        area +=
            length(cross(m_.positions[t[1]] - m_.positions[t[0]], m_.positions[t[2]] - m_.positions[t[0]]));
        for (std::size_t k = 0; k < 3; ++k)
            ++used[directed(t[k], t[(k + 1) % 3])];
    }
    for (const auto& [e, n] : used) {
        const bool chain = constraint.count(e) != 0;
        const auto rev = used.find((e << 32) | (e >> 32));
        if (n != 1 || chain == (rev != used.end()))
            return false;
    }
    for (std::uint64_t e : constraint)
        if (!used.count(e))
            return false;
    if (!(std::abs(area - before) <= 1e-7 * before) || tris.size() == first)
        return false;
    // The patch and its replacement share their boundary, so together they enclose a volume that must be nil.
    const Vec3 o = m_.positions[ends.front()];
    auto volume = [&](const Tri& t) {
        return dot(m_.positions[t[0]] - o, cross(m_.positions[t[1]] - o, m_.positions[t[2]] - o));
    };
    double change = 0;
    for (std::size_t i = first; i < tris.size(); ++i)
        change += volume(tris[i]);
    for (std::uint32_t t : patch)
        change -= volume(m_.triangles[t]);
    return std::abs(change) <= 1e-9 * before * diag_;
}

/// The output triangles in order into m: the input's other triangles in runs, each patch's new triangles
/// where its first triangle was (their attributes taken from the patch's corners first). In place (m is m_,
/// which needs fitsInPlace), runs move towards the front and new triangles overwrite passed slots; else m is
/// empty and everything is appended.
void Simplifier::assemble(Mesh& m, bool inPlace, const PatchOf& patchOf,
                          const std::vector<std::vector<std::uint32_t>>& patches,
                          const std::vector<std::vector<Tri>>& fresh, PlanarSimplifyReport& report) const {
    const bool hasMat = m_.hasMaterials(), hasUv = m_.hasUvs(), hasN = m_.hasNormals();
    std::size_t w = 0, next = 0; // output triangles, first input triangle not yet passed
    // Writes n entries per triangle of src at triangle w of dst (appending when not in place).
    auto put = [&](auto& dst, auto first, auto last, std::size_t per) {
        if (inPlace)
            std::copy(first, last, dst.begin() + static_cast<std::ptrdiff_t>(per * w));
        else
            dst.insert(dst.end(), first, last);
    };
    auto run = [&](std::size_t from, std::size_t to) { // input triangles [from, to) as they are
        auto at = [](const auto& v, std::size_t i) { return v.begin() + static_cast<std::ptrdiff_t>(i); };
        if (from == to || (inPlace && from == w)) { // nothing to write, or already where it belongs
            w += to - from;
            return;
        }
        put(m.triangles, at(m_.triangles, from), at(m_.triangles, to), 1);
        if (hasMat)
            put(m.materials, at(m_.materials, from), at(m_.materials, to), 1);
        if (hasUv)
            put(m.uvs, at(m_.uvs, 3 * from), at(m_.uvs, 3 * to), 3);
        if (hasN)
            put(m.normals, at(m_.normals, 3 * from), at(m_.normals, 3 * to), 3);
        w += to - from;
    };
    std::unordered_map<std::uint32_t, std::uint32_t> cornerOf; // a corner of the patch at each vertex
    std::vector<std::uint32_t> mats;
    std::vector<Vec2f> uvs;
    std::vector<Vec3f> normals;
    for (const auto& [t, p] : patchOf) {
        run(next, t);
        next = t + 1;
        report.integralsChange.remove(m_, t);
        if (patches[p].front() != t)
            continue;
        cornerOf.clear();
        for (auto it = patches[p].rbegin(); it != patches[p].rend(); ++it) // the first corner wins
            for (std::uint32_t k = 0; k < 3; ++k)
                cornerOf[m_.triangles[*it][k]] = 3 * *it + k;
        mats.clear();
        uvs.clear();
        normals.clear();
        for (const Tri& tri : fresh[p]) {
            if (hasMat)
                mats.push_back(m_.materials[t]);
            for (std::uint32_t v : tri) {
                const std::uint32_t c = cornerOf.at(v);
                if (hasUv)
                    uvs.push_back(m_.uvs[c]);
                if (hasN)
                    normals.push_back(m_.normals[c]);
            }
            report.integralsChange.add(m_.positions[tri[0]], m_.positions[tri[1]], m_.positions[tri[2]]);
        }
        put(m.triangles, fresh[p].begin(), fresh[p].end(), 1);
        if (hasMat)
            put(m.materials, mats.begin(), mats.end(), 1);
        if (hasUv)
            put(m.uvs, uvs.begin(), uvs.end(), 3);
        if (hasN)
            put(m.normals, normals.begin(), normals.end(), 3);
        w += fresh[p].size();
        ++report.regionsRetriangulated;
    }
    run(next, m_.triangles.size());
    if (inPlace) {
        m.triangles.resize(w);
        m.materials.resize(hasMat ? w : 0);
        m.uvs.resize(hasUv ? 3 * w : 0);
        m.normals.resize(hasN ? 3 * w : 0);
    }
}

bool Simplifier::run(Mesh& result, PlanarSimplifyReport& report, Mesh* inPlace) {
    const std::size_t nv = m_.positions.size(), nt = m_.triangles.size();
    if (nt == 0 || (m_.hasUvs() && m_.uvs.size() != 3 * nt) ||
        (m_.hasNormals() && m_.normals.size() != 3 * nt) || (m_.hasMaterials() && m_.materials.size() != nt))
        return false;
    for (const Tri& t : m_.triangles)
        for (std::uint32_t v : t)
            if (v >= nv)
                return false;
    diag_ = m_.bounds().diagonal();
    planeTol_ = params_.planeTolerance * diag_;
    const Aabb& focus = params_.focus;
    const bool everywhere = focus.empty();

    // Local triangles (a corner in the focus), their directed edges and the stars of focus vertices.
    std::vector<std::uint32_t> local;
    inFocus_.assign(nv, 0);
    isRemoved_.assign(nv, 0);
    normal_.resize(nt);
    patchStamp_.assign(nt, 0);
    for (std::uint32_t t = 0; t < nt; ++t) {
        const Tri& tri = m_.triangles[t];
        bool any = everywhere;
        for (std::size_t k = 0; k < 3 && !any; ++k)
            any = focus.contains(m_.positions[tri[k]]);
        if (!any)
            continue;
        local.push_back(t);
        normal_[t] = m_.triangleNormal(t);
        for (std::size_t k = 0; k < 3; ++k) {
            if (tri[k] == tri[(k + 1) % 3])
                return false; // a repeated corner: not a clean surface
            if (everywhere || focus.contains(m_.positions[tri[k]])) {
                if (!inFocus_[tri[k]]) {
                    inFocus_[tri[k]] = 1;
                    starVertex_.push_back(tri[k]);
                }
            }
        }
    }

    // Twins from the local corners listed by vertex.
    if (!corners_.build(m_, local))
        return false;
    // The end of corner c's edge.
    auto next = [&](std::uint32_t c) { return m_.triangles[c / 3][(c % 3 + 1) % 3]; };
    twin_.assign(3 * nt, kNone);
    for (std::uint32_t t : local)
        for (std::uint32_t k = 0; k < 3; ++k) {
            const std::uint32_t a = m_.triangles[t][k], b = m_.triangles[t][(k + 1) % 3];
            for (std::uint32_t c : corners_.at(a))
                if (c != 3 * t + k && next(c) == b)
                    return false; // a repeated directed edge: not a clean surface
            for (std::uint32_t c : corners_.at(b))
                if (next(c) == a)
                    twin_[3 * t + k] = c / 3;
        }

    // Removable vertices, then patches; a patch that fails keeps its vertices and everything is redone.
    std::vector<std::uint32_t> candidates = starVertex_;
    std::sort(candidates.begin(), candidates.end());
    std::unordered_set<std::uint32_t> kept; // vertices a failed patch needs
    std::vector<std::vector<std::uint32_t>> patches;
    std::vector<std::vector<Tri>> fresh;
    for (int round = 0;; ++round) {
        for (std::uint32_t v : removed_)
            isRemoved_[v] = 0;
        removed_.clear();
        for (std::uint32_t v : candidates)
            if (!kept.count(v) && removable(v))
                removed_.push_back(v);
        for (std::uint32_t v : removed_)
            isRemoved_[v] = 1;
        if (removed_.empty())
            return false;
        // Patches: the stars of removed vertices, split into edge-connected compatible groups.
        // The union of their stars, in order: the local triangles with a removed corner (no sort needed).
        std::vector<std::uint32_t> inPatch;
        for (std::uint32_t t : local)
            if (wasRemoved(m_.triangles[t][0]) || wasRemoved(m_.triangles[t][1]) ||
                wasRemoved(m_.triangles[t][2]))
                inPatch.push_back(t);
        constexpr std::uint32_t kOut = kNone - 1; // not in a removed vertex's star
        group_.assign(nt, kOut);                  // per triangle: its patch, kNone before it has one
        std::vector<std::uint32_t>& group = group_;
        for (std::uint32_t t : inPatch)
            group[t] = kNone;
        patches.clear();
        for (std::uint32_t t : inPatch) {
            if (group[t] != kNone)
                continue;
            const std::uint32_t id = static_cast<std::uint32_t>(patches.size());
            patches.emplace_back(1, t);
            group[t] = id;
            for (std::size_t i = 0; i < patches[id].size(); ++i)
                for (int k = 0; k < 3; ++k) {
                    const std::uint32_t c = patches[id][i], o = twinTri(c, k);
                    if (o != kNone && group[o] == kNone && compatible(c, o)) {
                        group[o] = id;
                        patches[id].push_back(o);
                    }
                }
            std::sort(patches[id].begin(), patches[id].end());
        }
        fresh.assign(patches.size(), {});
        bool failed = false;
        for (std::size_t p = 0; p < patches.size(); ++p)
            if (!retriangulate(patches[p], fresh[p])) {
                failed = true;
                ++report.regionsKept;
                for (std::uint32_t t : patches[p])
                    for (std::uint32_t v : m_.triangles[t])
                        kept.insert(v);
            }
        if (!failed)
            break;
        if (round == 8)
            return false;
    }

    // Assemble: other triangles in input order; each patch's new triangles where its first triangle was.
    // The triangles between patch triangles are copied in runs.
    PatchOf patchOf;
    for (std::size_t p = 0; p < patches.size(); ++p)
        for (std::uint32_t t : patches[p])
            patchOf.emplace_back(t, static_cast<std::uint32_t>(p));
    std::sort(patchOf.begin(), patchOf.end());
    report.integralsChange = {};
    report.integralsChange.reference = params_.integralsReference;
    editedInPlace_ = inPlace && fitsInPlace(patchOf, patches, fresh);
    Mesh out;
    Mesh& target = editedInPlace_ ? *inPlace : out;
    if (!editedInPlace_) {
        out.materialNames = m_.materialNames;
        out.triangles.reserve(nt);
        out.materials.reserve(m_.materials.size());
        out.uvs.reserve(m_.uvs.size());
        out.normals.reserve(m_.normals.size());
    }
    assemble(target, editedInPlace_, patchOf, patches, fresh, report);
    // Drop the removed vertices (only those: the input's own unreferenced vertices stay), in place.
    std::vector<std::uint32_t> gone(removed_.begin(), removed_.end());
    std::sort(gone.begin(), gone.end());
    std::vector<std::uint32_t> remap(nv);
    if (!editedInPlace_)
        target.positions = m_.positions;
    std::size_t stay = 0;
    for (std::uint32_t v = 0, g = 0; v < nv; ++v) {
        if (g < gone.size() && gone[g] == v) {
            ++g;
            remap[v] = kNone;
            continue;
        }
        remap[v] = static_cast<std::uint32_t>(stay);
        target.positions[stay++] = target.positions[v];
    }
    target.positions.resize(stay);
    for (Tri& tri : target.triangles)
        for (std::uint32_t& v : tri)
            v = remap[v];
    report.verticesRemoved = removed_.size();
    report.removedVertices = std::move(gone);
    if (!editedInPlace_)
        result = std::move(out);
    return true;
}

} // namespace

namespace {

/// Simplifies mesh into out, or over *inPlace (mesh itself) when that fits; false (and a report saying so)
/// when it stays as it is.
bool simplifyInto(const Mesh& mesh, const PlanarSimplifyParams& params, PlanarSimplifyReport* report,
                  Mesh& out, Mesh* inPlace) {
    PlanarSimplifyReport local;
    PlanarSimplifyReport& rep = report ? *report : local;
    rep = {};
    rep.trianglesBefore = mesh.triangles.size();
    Simplifier simplifier(mesh, params);
    if (!simplifier.run(out, rep, inPlace)) {
        rep = {};
        rep.trianglesBefore = rep.trianglesAfter = mesh.triangles.size();
        rep.unchanged = true;
        return false;
    }
    if (simplifier.editedInPlace())
        out = std::move(*inPlace);
    rep.trianglesAfter = out.triangles.size();
    return true;
}

} // namespace

Mesh simplifyPlanarRegions(const Mesh& mesh, const PlanarSimplifyParams& params,
                           PlanarSimplifyReport* report) {
    Mesh out;
    if (!simplifyInto(mesh, params, report, out, nullptr))
        return mesh;
    return out;
}

Mesh simplifyPlanarRegions(Mesh&& mesh, const PlanarSimplifyParams& params, PlanarSimplifyReport* report) {
    Mesh out;
    if (!simplifyInto(mesh, params, report, out, &mesh))
        return std::move(mesh);
    return out;
}

} // namespace rubble
