#include "ConvexCellClipper.hpp"

#include "CellComplex.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <ranges>
#include <unordered_map>
#include <unordered_set>

#include "geometry/PlanarTriangulation.hpp"
#include "geometry/RayParity.hpp"
#include "rubble/geometry/MassProperties.hpp"

namespace rubble::detail {

namespace {

constexpr std::uint32_t kNone = 0xFFFFFFFFu;

/// Key of a created point: which mesh edge / triangle and which cell planes or complex edge it lies on.
struct PointKey {
    // 1: mesh edge (a<b) ∩ face c; 2: triangle a ∩ complex edge (b<c); 3: complex vertex a;
    // 4: triangle a ∩ faces b<c that share no edge (never a corner of an output)
    std::uint32_t kind;
    std::uint32_t a, b, c;
    bool operator==(const PointKey&) const = default;
};
struct PointKeyHash {
    std::size_t operator()(const PointKey& k) const {
        std::uint64_t h = k.kind * 0x9E3779B97F4A7C15ull;
        h ^= (std::uint64_t(k.a) + 0x632BE59BD9B4E019ull) * 0xBF58476D1CE4E5B9ull;
        h = (h << 17) | (h >> 47);
        h ^= (std::uint64_t(k.b) << 32 | k.c) * 0x94D049BB133111EBull;
        return static_cast<std::size_t>(h ^ (h >> 29));
    }
};

/// What an edge of a clipped polygon lies on.
struct Support {
    bool onMeshEdge; // true: the mesh edge (a,b) with a<b; false: the cut line of complex face a
    std::uint32_t a, b;
};

/// A polygon corner and the support of the edge to the next corner.
struct Corner {
    std::uint32_t id;
    Support next;
};

/// Splits a mesh by a complex of convex cells in one pass: every point is computed once, from the input
/// mesh and the complex, and shared by every region that uses it.
class Clipper {
public:
    /// The cells' bounds and the clip's tolerance (relative to their size and distance from the origin).
    struct Scale {
        Aabb box;
        double eps = 0;
    };
    static Scale scaleOf(const std::vector<ConvexPolytope>& cells) {
        Scale s;
        for (const ConvexPolytope& c : cells)
            s.box.extend(c.bounds());
        double maxAbs = 0;
        for (int a = 0; a < 3; ++a)
            maxAbs = std::max({maxAbs, std::abs(s.box.lo[a]), std::abs(s.box.hi[a])});
        s.eps = std::max(1e-10 * s.box.diagonal(), 1e-14 * maxAbs);
        return s;
    }

    /// A clipper of mesh by the complex of cells built at scale (buildCellComplex(cells, scale.eps)).
    Clipper(const Mesh& mesh, const Scale& scale, CellComplex cx)
        : mesh_(mesh), cx_(std::move(cx)), box_(scale.box), eps_(scale.eps) {
        nV_ = static_cast<std::uint32_t>(mesh.positions.size());
        k_ = static_cast<std::uint32_t>(cx_.cells.size());
        nF_ = static_cast<std::uint32_t>(cx_.faces.size());
        cutEdges_.resize(nF_);
        untouched_.resize(k_ + 1);
        tris_.resize(k_ + 1);
        thread_local SlotArray threadSlots;
        slots_ = threadSlots.busy ? &ownSlots_ : &threadSlots;
        slots_->busy = true;
        if (slots_->slot.size() < nV_)
            slots_->slot.resize(nV_, -1);
        distSlot_ = slots_->slot.data();
    }
    ~Clipper() {
        for (std::uint32_t v : slots_->set)
            distSlot_[v] = -1;
        slots_->set.clear();
        slots_->busy = false;
    }
    Clipper(const Clipper&) = delete;
    Clipper& operator=(const Clipper&) = delete;

    /// Region k < K: mesh ∩ cell k; region K: the rest. With known (the mesh's integrals), outside gets the
    /// rest's integrals by difference.
    /// With edit (and known), the rest is not assembled but returned as an edit of the mesh (the last
    /// region of the result is then empty).
    /// GeometryFailure ("fast clip declined: ...") for a configuration it does not handle robustly.
    Result<std::vector<Mesh>> run(const VolumeIntegrals* known, std::optional<VolumeIntegrals>& restIntegrals,
                                  RemainderEdit* edit = nullptr);
    /// After run: the triangles region r kept whole (assemble puts them first).
    std::size_t keptWhole(std::uint32_t r) const { return untouched_[r].size(); }

private:
    const Mesh& mesh_;
    CellComplex cx_;
    const char* declined_ =
        nullptr; // why run declines, once a stage found a configuration it does not handle

    /// Records why the clip declines (the first reason); kNone for a stage that returns a point.
    std::uint32_t decline(const char* why) {
        if (!declined_)
            declined_ = why;
        return kNone;
    }
    Aabb box_;
    double eps_ = 0;
    std::uint32_t nV_ = 0, k_ = 0, nF_ = 0;

    std::vector<Vec3> extra_;   // created points, ids nV_ + i
    std::vector<bool> offEdge_; // per created point: kind 4 (may not end up in an output)
    std::unordered_map<PointKey, std::uint32_t, PointKeyHash> keyed_;
    // Per mesh vertex: offset into dist_ or -1; a per-thread array, reset only at the vertices it set.
    struct SlotArray {
        std::vector<std::int32_t> slot;
        std::vector<std::uint32_t> set; // the vertices whose slot is not -1
        bool busy = false;
    };
    SlotArray ownSlots_; // used when the thread's array is taken (a clip inside a clip)
    SlotArray* slots_ = nullptr;
    std::int32_t* distSlot_ = nullptr;
    std::vector<double> dist_; // distances to every complex face plane

    // Per complex face: the directed cut edges of its back cell's polygons on that face.
    std::vector<std::vector<std::pair<std::uint32_t, std::uint32_t>>> cutEdges_;
    // Per complex edge (a<b): points where it pierces the mesh surface.
    std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> pierce_;

    // Output triangles by point id, with the source triangle (kNone for cap faces) and cap face.
    struct OutTri {
        std::uint32_t v[3];
        std::uint32_t source; // mesh triangle it lies in, or kNone for a cap
        std::uint32_t face;   // complex face of a cap
        bool flipped;         // cap seen from the face's front
    };
    std::vector<std::vector<OutTri>> tris_;             // per region
    std::vector<std::vector<std::uint32_t>> untouched_; // per region: input triangles kept whole

    const Vec3& pos(std::uint32_t id) const { return id < nV_ ? mesh_.positions[id] : extra_[id - nV_]; }

    /// Signed distance to complex face f's plane (positive in front).
    double dist(std::uint32_t id, std::uint32_t f) const {
        if (id < nV_)
            return dist_[static_cast<std::size_t>(distSlot_[id]) + f];
        return cx_.faces[f].plane.signedDistance(extra_[id - nV_]);
    }
    /// Signed distance to the l-th plane of cell c (positive outside the cell).
    double cellDist(std::uint32_t id, std::uint32_t c, std::size_t l) const {
        const double d = dist(id, cx_.cells[c].faces[l]);
        return cx_.cells[c].flipped[l] ? -d : d;
    }

    void ensureDistances(std::uint32_t v) {
        if (distSlot_[v] >= 0)
            return;
        distSlot_[v] = static_cast<std::int32_t>(dist_.size());
        slots_->set.push_back(v);
        for (const CellComplex::Face& f : cx_.faces)
            dist_.push_back(f.plane.signedDistance(mesh_.positions[v]));
    }

    std::uint32_t addPoint(const PointKey& key, const Vec3& p, bool offEdge = false) {
        auto [it, inserted] = keyed_.emplace(key, nV_ + static_cast<std::uint32_t>(extra_.size()));
        if (inserted) {
            extra_.push_back(p);
            offEdge_.push_back(offEdge);
        }
        return it->second;
    }

    std::uint32_t crossing(std::uint32_t tri, std::uint32_t cell, const Support& s, std::uint32_t face,
                           std::uint32_t from, std::uint32_t to, double dFrom, double dTo);
    std::vector<Corner> clipTriangle(std::uint32_t t, std::uint32_t cell);
    void cutTriangle(std::uint32_t t, const std::vector<std::uint32_t>& cells);
    void emitConvex(const std::vector<std::uint32_t>& poly, const Vec3& normal, std::uint32_t source,
                    std::vector<OutTri>& out);
    void triangulateRegion(const std::vector<std::pair<std::uint32_t, std::uint32_t>>& edges,
                           std::size_t boundaryEdges, const Vec3& normal, std::uint32_t source,
                           std::uint32_t face, std::vector<OutTri>& out);
    void buildCaps();
    bool pointInsideMesh(const Vec3& p) const;
    void emitAttributes(const OutTri& o, std::vector<Vec3>* normals, std::vector<Vec2>& uvs,
                        std::vector<std::uint32_t>& materials) const;
    Mesh assemble(std::uint32_t region) const;
    RemainderEdit assembleEdit(std::vector<std::uint32_t> removed) const;
};

std::uint32_t Clipper::crossing(std::uint32_t tri, std::uint32_t cell, const Support& s, std::uint32_t face,
                                std::uint32_t from, std::uint32_t to, double dFrom, double dTo) {
    if (s.onMeshEdge) {
        const PointKey key{1, s.a, s.b, face};
        if (auto it = keyed_.find(key); it != keyed_.end())
            return it->second;
        // Canonical: from the lower vertex index to the higher, with their own distances (the same for both
        // cells of a shared face: the ratio does not depend on the sign).
        const double da = dist(s.a, face), db = dist(s.b, face);
        if (!((da < 0 && db > 0) || (da > 0 && db < 0)))
            return decline("edge crossing without sign change");
        const Vec3& pa = mesh_.positions[s.a];
        const Vec3& pb = mesh_.positions[s.b];
        return addPoint(key, pa + (pb - pa) * (da / (da - db)));
    }
    const std::uint32_t f = std::min(s.a, face), g = std::max(s.a, face);
    const Vec3& p = pos(from);
    const Vec3& q = pos(to);
    const Vec3 along = p + (q - p) * (dFrom / (dFrom - dTo));
    const auto& edges = cx_.cells[cell].edgeOfFaces;
    const auto edge = edges.find(pairKey(f, g));
    if (edge == edges.end()) // the faces meet at most in a vertex: this point cannot survive clipping
        return addPoint({4, tri, f, g}, along, true);
    // Where the triangle meets a complex edge: every cell around the edge gets the same point, computed
    // from the edge's (welded) end points and the triangle's plane.
    const auto a = static_cast<std::uint32_t>(edge->second >> 32);
    const auto b = static_cast<std::uint32_t>(edge->second & 0xFFFFFFFFu);
    const PointKey key{2, tri, a, b};
    if (auto it = keyed_.find(key); it != keyed_.end())
        return it->second;
    const auto c = mesh_.corners(tri);
    const Vec3 n = cross(c[1] - c[0], c[2] - c[0]);
    const Vec3 &pa = cx_.vertices[a], &pb = cx_.vertices[b];
    const double da = dot(n, pa - c[0]), db = dot(n, pb - c[0]);
    if (!(std::abs(da - db) > 1e-9 * length(n) * length(pb - pa)))
        return decline("triangle parallel to a cell edge");
    const Vec3 x = pa + (pb - pa) * (da / (da - db));
    if (length(x - along) > 10 * eps_)
        return decline("ill-conditioned cell edge crossing");
    return addPoint(key, x);
}

// Sutherland–Hodgman clipping of triangle t by all planes of a cell; corners carry the support of their
// next edge.
std::vector<Corner> Clipper::clipTriangle(std::uint32_t t, std::uint32_t cell) {
    const Triangle& tri = mesh_.triangles[t];
    std::vector<Corner> poly;
    for (int c = 0; c < 3; ++c) {
        const std::uint32_t a = tri[c], b = tri[(c + 1) % 3];
        poly.push_back({a, {true, std::min(a, b), std::max(a, b)}});
    }
    std::vector<Corner> next;
    std::vector<double> d;
    const std::vector<std::uint32_t>& faces = cx_.cells[cell].faces;
    for (std::size_t l = 0; l < faces.size() && !poly.empty(); ++l) {
        d.resize(poly.size());
        bool anyOut = false, anyIn = false;
        for (std::size_t c = 0; c < poly.size(); ++c) {
            d[c] = cellDist(poly[c].id, cell, l);
            if (std::abs(d[c]) <= eps_) {
                decline("point on a cell plane");
                return {};
            }
            anyOut |= d[c] > 0;
            anyIn |= d[c] < 0;
        }
        if (!anyOut)
            continue;
        if (!anyIn) {
            poly.clear();
            break;
        }
        next.clear();
        const std::size_t n = poly.size();
        for (std::size_t c = 0; c < n; ++c) {
            const Corner& cur = poly[c];
            const Corner& nxt = poly[(c + 1) % n];
            const bool curIn = d[c] < 0, nxtIn = d[(c + 1) % n] < 0;
            if (curIn) {
                next.push_back(cur);
                if (!nxtIn) {
                    const std::uint32_t x =
                        crossing(t, cell, cur.next, faces[l], cur.id, nxt.id, d[c], d[(c + 1) % n]);
                    if (declined_)
                        return {};
                    next.push_back({x, {false, faces[l], 0}});
                }
            } else if (nxtIn) {
                const std::uint32_t y =
                    crossing(t, cell, cur.next, faces[l], cur.id, nxt.id, d[c], d[(c + 1) % n]);
                if (declined_)
                    return {};
                next.push_back({y, cur.next});
            }
        }
        poly.swap(next);
    }
    return poly;
}

// Triangulates a convex polygon (possibly with collinear corners) by clipping strictly convex ears.
void Clipper::emitConvex(const std::vector<std::uint32_t>& polyIn, const Vec3& normal, std::uint32_t source,
                         std::vector<OutTri>& out) {
    std::vector<std::uint32_t> poly = polyIn;
    auto strictlyConvex = [&](std::size_t c) {
        const std::size_t n = poly.size();
        const Vec3& a = pos(poly[(c + n - 1) % n]);
        const Vec3& b = pos(poly[c]);
        const Vec3& e = pos(poly[(c + 1) % n]);
        const Vec3 cr = cross(b - a, e - b);
        return dot(cr, normal) > 1e-12 * length(b - a) * length(e - b);
    };
    while (poly.size() > 3) {
        std::size_t ear = poly.size();
        for (std::size_t c = 0; c < poly.size(); ++c)
            if (strictlyConvex(c)) {
                ear = c;
                break;
            }
        if (ear == poly.size()) {
            decline("flat polygon");
            return;
        }
        const std::size_t n = poly.size();
        out.push_back({{poly[(ear + n - 1) % n], poly[ear], poly[(ear + 1) % n]}, source, kNone, false});
        poly.erase(poly.begin() + static_cast<std::ptrdiff_t>(ear));
    }
    out.push_back({{poly[0], poly[1], poly[2]}, source, kNone, false});
}

// Triangulates (with a constrained Delaunay triangulation) the planar region bounded by the first
// `boundaryEdges` directed edges (counter-clockwise seen along normal), minus the polygons whose edges are
// the remaining ones (the holes). Inside and outside are found topologically: walking from the unbounded
// face, every crossed boundary edge toggles "inside the region" and every crossed hole edge toggles "inside
// the hole".
void Clipper::triangulateRegion(const std::vector<std::pair<std::uint32_t, std::uint32_t>>& edges,
                                std::size_t boundaryEdges, const Vec3& normal, std::uint32_t source,
                                std::uint32_t face, std::vector<OutTri>& out) {
    std::vector<RegionEdge> region;
    region.reserve(edges.size());
    for (std::size_t e = 0; e < edges.size(); ++e)
        region.push_back({edges[e].first, edges[e].second, e < boundaryEdges ? 1u : 2u});
    std::vector<std::array<std::uint32_t, 3>> tris;
    if (const char* why = triangulatePlanarRegion(
            region, normal, [&](std::uint32_t id) { return pos(id); }, tris)) {
        decline(why);
        return;
    }
    for (const auto& t : tris)
        out.push_back({{t[0], t[1], t[2]}, source, face, false});
}

void Clipper::cutTriangle(std::uint32_t t, const std::vector<std::uint32_t>& cells) {
    const Triangle& tri = mesh_.triangles[t];
    std::vector<std::pair<std::uint32_t, std::vector<Corner>>> polys;
    std::uint32_t wholeIn = kNone;
    for (std::uint32_t c : cells) {
        std::vector<Corner> poly = clipTriangle(t, c);
        if (declined_)
            return;
        if (poly.empty())
            continue;
        bool created = false;
        for (const Corner& k : poly) {
            created |= k.id >= nV_;
            if (k.id >= nV_ && offEdge_[k.id - nV_]) {
                decline("triangle through a cell vertex");
                return;
            }
        }
        if (created)
            polys.emplace_back(c, std::move(poly));
        else // wholly inside this cell (its distances said otherwise only within rounding)
            wholeIn = c;
    }
    if (wholeIn != kNone) {
        if (!polys.empty()) {
            decline("triangle inside a cell and cut by another");
            return;
        }
        untouched_[wholeIn].push_back(t);
        return;
    }
    if (polys.empty()) {
        untouched_[k_].push_back(t);
        return;
    }
    const Vec3 normal = mesh_.triangleNormal(t);
    // Each cell's part; cut edges (on faces whose back is that cell) and pierce points for the caps; contact
    // points on the triangle's edges.
    std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> contacts; // by mesh edge (a<b)
    std::vector<std::pair<std::uint32_t, std::uint32_t>> holes;
    for (const auto& [cell, poly] : polys) {
        std::vector<std::uint32_t> ids;
        for (const Corner& k : poly)
            ids.push_back(k.id);
        emitConvex(ids, normal, t, tris_[cell]);
        if (declined_)
            return;
        for (std::size_t c = 0; c < poly.size(); ++c) {
            const Corner& cur = poly[c];
            const Corner& nxt = poly[(c + 1) % poly.size()];
            holes.emplace_back(cur.id, nxt.id);
            if (!cur.next.onMeshEdge && cx_.faces[cur.next.a].back == cell)
                cutEdges_[cur.next.a].emplace_back(cur.id, nxt.id);
            if (cur.id < nV_)
                continue;
            // Which key made it: look at its supports.
            const Support& in = poly[(c + poly.size() - 1) % poly.size()].next;
            const Support& out = cur.next;
            if (!in.onMeshEdge && !out.onMeshEdge) {
                const std::uint32_t f = std::min(in.a, out.a), g = std::max(in.a, out.a);
                pierce_[cx_.cells[cell].edgeOfFaces.at(pairKey(f, g))].push_back(cur.id);
            } else {
                const Support& edge = in.onMeshEdge ? in : out;
                contacts[pairKey(edge.a, edge.b)].push_back(cur.id);
            }
        }
    }
    // The rest: the triangle minus the cells' convex polygons (edges two neighbouring polygons share cancel),
    // as a constrained triangulation.
    std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;
    for (int c = 0; c < 3; ++c) {
        const std::uint32_t a = tri[c], b = tri[(c + 1) % 3];
        std::vector<std::uint32_t> onEdge;
        if (auto it = contacts.find(pairKey(std::min(a, b), std::max(a, b))); it != contacts.end())
            onEdge = it->second;
        const Vec3 pa = pos(a), dir = pos(b) - pa;
        std::sort(onEdge.begin(), onEdge.end(), [&](std::uint32_t x, std::uint32_t y) {
            return dot(pos(x) - pa, dir) < dot(pos(y) - pa, dir);
        });
        onEdge.erase(std::unique(onEdge.begin(), onEdge.end()), onEdge.end());
        std::uint32_t prev = a;
        for (std::uint32_t x : onEdge) {
            edges.emplace_back(prev, x);
            prev = x;
        }
        edges.emplace_back(prev, b);
    }
    const std::size_t boundary = edges.size();
    edges.insert(edges.end(), holes.begin(), holes.end());
    triangulateRegion(edges, boundary, normal, t, kNone, tris_[k_]);
}

bool Clipper::pointInsideMesh(const Vec3& p) const {
    // All triangle indices; not std::views::iota, which clang 14 cannot compile with libstdc++ 12 (the
    // sanitizer and fuzzer builds use clang).
    struct AllTriangles {
        struct It {
            std::size_t i;
            std::size_t operator*() const { return i; }
            It& operator++() {
                ++i;
                return *this;
            }
            bool operator!=(const It& o) const { return i != o.i; }
        };
        std::size_t n;
        It begin() const { return {0}; }
        It end() const { return {n}; }
    };
    return insideByRayParity(mesh_, AllTriangles{mesh_.triangles.size()}, p);
}

void Clipper::buildCaps() {
    // Map: per face, point -> whether the back cell's polygon cut edge leaves it (true) or arrives at it
    // (false).
    std::vector<std::unordered_map<std::uint32_t, bool>> leaves(nF_);
    for (std::uint32_t f = 0; f < nF_; ++f)
        for (const auto& [a, b] : cutEdges_[f]) {
            leaves[f][b] = true;
            leaves[f][a] = false;
        }
    for (auto& [edge, points] : pierce_) { // every cell around a complex edge reports its pierce points
        std::sort(points.begin(), points.end());
        points.erase(std::unique(points.begin(), points.end()), points.end());
    }
    const std::size_t nCellVerts = cx_.vertices.size();
    std::vector<int> vertexInside(nCellVerts, -1);
    auto setStatus = [&](std::uint32_t v, int s) {
        if (vertexInside[v] >= 0 && vertexInside[v] != s) {
            decline("inconsistent cell vertex status");
            return false;
        }
        vertexInside[v] = s;
        return true;
    };
    // Per directed edge of face f: sorted pierce points and the inside status of each sub-edge.
    struct EdgeSplit {
        std::vector<std::uint32_t> points;
        std::vector<int> inside; // points.size() + 1 entries
    };
    std::vector<std::vector<EdgeSplit>> splits(nF_);
    for (std::uint32_t f = 0; f < nF_; ++f) {
        const auto& loop = cx_.faces[f].loop;
        splits[f].resize(loop.size());
        for (std::size_t e = 0; e < loop.size(); ++e) {
            const std::uint32_t A = loop[e], B = loop[(e + 1) % loop.size()];
            EdgeSplit& s = splits[f][e];
            if (auto it = pierce_.find(pairKey(std::min(A, B), std::max(A, B))); it != pierce_.end())
                s.points = it->second;
            const Vec3 pa = cx_.vertices[A], dir = cx_.vertices[B] - pa;
            std::sort(s.points.begin(), s.points.end(), [&](std::uint32_t x, std::uint32_t y) {
                return dot(pos(x) - pa, dir) < dot(pos(y) - pa, dir);
            });
            s.inside.assign(s.points.size() + 1, -1);
            for (std::size_t q = 0; q < s.points.size(); ++q) {
                auto it = leaves[f].find(s.points[q]);
                if (it == leaves[f].end()) {
                    decline("pierce point without cut edge");
                    return;
                }
                const int before =
                    it->second ? 1 : 0; // cap edge leaves the point: the sub-edge before is inside
                for (auto [slot, value] : {std::pair{q, before}, std::pair{q + 1, 1 - before}}) {
                    if (s.inside[slot] >= 0 && s.inside[slot] != value) {
                        decline("inconsistent cut along a cell edge");
                        return;
                    }
                    s.inside[slot] = value;
                }
            }
            if (!s.points.empty() && (!setStatus(A, s.inside.front()) || !setStatus(B, s.inside.back())))
                return;
        }
    }
    // Propagate vertex status along unpierced complex edges; with no information at all, cast a ray.
    bool changed = true;
    while (changed) {
        changed = false;
        for (std::uint32_t f = 0; f < nF_; ++f) {
            const auto& loop = cx_.faces[f].loop;
            for (std::size_t e = 0; e < loop.size(); ++e) {
                if (!splits[f][e].points.empty())
                    continue;
                const std::uint32_t A = loop[e], B = loop[(e + 1) % loop.size()];
                if (vertexInside[A] >= 0 && vertexInside[B] < 0) {
                    vertexInside[B] = vertexInside[A];
                    changed = true;
                } else if (vertexInside[B] >= 0 && vertexInside[A] < 0) {
                    vertexInside[A] = vertexInside[B];
                    changed = true;
                } else if (vertexInside[A] >= 0 && vertexInside[A] != vertexInside[B]) {
                    decline("inconsistent unpierced cell edge");
                    return;
                }
            }
        }
        if (!changed && std::find(vertexInside.begin(), vertexInside.end(), -1) != vertexInside.end()) {
            const auto it = std::find(vertexInside.begin(), vertexInside.end(), -1);
            *it = pointInsideMesh(cx_.vertices[static_cast<std::size_t>(it - vertexInside.begin())]) ? 1 : 0;
            changed = true;
        }
    }
    // Complex vertices become points (created lazily when a cap uses them). A cap goes to the face's back
    // cell as it is and to the region in front reversed.
    auto cellPoint = [&](std::uint32_t v) { return addPoint({3, v, 0, 0}, cx_.vertices[v]); };
    std::vector<OutTri> caps;
    for (std::uint32_t f = 0; f < nF_; ++f) {
        std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;
        for (const auto& [a, b] : cutEdges_[f])
            edges.emplace_back(b, a);
        const auto& loop = cx_.faces[f].loop;
        for (std::size_t e = 0; e < loop.size(); ++e) {
            const std::uint32_t A = loop[e], B = loop[(e + 1) % loop.size()];
            const EdgeSplit& s = splits[f][e];
            if (s.points.empty()) {
                if (vertexInside[A] == 1)
                    edges.emplace_back(cellPoint(A), cellPoint(B));
                continue;
            }
            for (std::size_t q = 0; q <= s.points.size(); ++q) {
                if (s.inside[q] != 1)
                    continue;
                const std::uint32_t from = q == 0 ? cellPoint(A) : s.points[q - 1];
                const std::uint32_t to = q == s.points.size() ? cellPoint(B) : s.points[q];
                edges.emplace_back(from, to);
            }
        }
        if (edges.empty())
            continue;
        caps.clear();
        triangulateRegion(edges, edges.size(), cx_.faces[f].plane.normal, kNone, f, caps);
        if (declined_)
            return;
        for (const OutTri& c : caps) {
            tris_[cx_.faces[f].back].push_back(c);
            tris_[cx_.faces[f].front].push_back({{c.v[0], c.v[2], c.v[1]}, kNone, f, true});
        }
    }
}

void Clipper::emitAttributes(const OutTri& o, std::vector<Vec3>* normals, std::vector<Vec2>& uvs,
                             std::vector<std::uint32_t>& materials) const {
    const bool hasUv = mesh_.hasUvs();
    if (o.source == kNone) {
        const Vec3& normal = cx_.faces[o.face].plane.normal;
        if (normals)
            normals->insert(normals->end(), 3, o.flipped ? -normal : normal);
        uvs.insert(uvs.end(), 3, Vec2{}); // interior UVs are generated by the fracture pipeline
        materials.push_back(kInteriorMaterial);
        return;
    }
    // Barycentric interpolation of the source triangle's corner attributes.
    const auto c = mesh_.corners(o.source);
    const Vec3 n = cross(c[1] - c[0], c[2] - c[0]);
    const double inv = 1.0 / dot(n, n);
    for (std::uint32_t v : o.v) {
        const Vec3 p = pos(v);
        const double w0 = dot(cross(c[1] - p, c[2] - p), n) * inv;
        const double w1 = dot(cross(c[2] - p, c[0] - p), n) * inv;
        const double w2 = 1 - w0 - w1;
        const std::size_t b = 3 * static_cast<std::size_t>(o.source);
        if (normals)
            normals->push_back(
                normalized(mesh_.normals[b] * w0 + mesh_.normals[b + 1] * w1 + mesh_.normals[b + 2] * w2));
        if (hasUv) {
            const Vec2 &u0 = mesh_.uvs[b], &u1 = mesh_.uvs[b + 1], &u2 = mesh_.uvs[b + 2];
            uvs.push_back({u0.x * w0 + u1.x * w1 + u2.x * w2, u0.y * w0 + u1.y * w1 + u2.y * w2});
        } else {
            uvs.push_back({});
        }
    }
    materials.push_back(mesh_.material(o.source));
}

Mesh Clipper::assemble(std::uint32_t region) const {
    const std::vector<std::uint32_t>& untouched = untouched_[region];
    const std::vector<OutTri>& tris = tris_[region];
    Mesh m;
    m.materialNames = mesh_.materialNames;
    std::vector<std::uint32_t> local(nV_ + extra_.size(), kNone);
    auto id = [&](std::uint32_t g) {
        if (local[g] == kNone) {
            local[g] = static_cast<std::uint32_t>(m.positions.size());
            m.positions.push_back(pos(g));
        }
        return local[g];
    };
    const bool hasN = mesh_.hasNormals(), hasUv = mesh_.hasUvs();
    const std::size_t total = untouched.size() + tris.size();
    m.positions.reserve(std::min<std::size_t>(nV_ + extra_.size(), 3 * total));
    m.triangles.reserve(total);
    m.materials.reserve(total);
    m.uvs.reserve(3 * total);
    if (hasN)
        m.normals.reserve(3 * total);
    for (std::uint32_t t : untouched) {
        const Triangle& tri = mesh_.triangles[t];
        m.triangles.push_back({id(tri[0]), id(tri[1]), id(tri[2])});
        if (hasN)
            m.normals.insert(m.normals.end(), mesh_.normals.begin() + 3 * t,
                             mesh_.normals.begin() + 3 * t + 3);
        if (hasUv)
            m.uvs.insert(m.uvs.end(), mesh_.uvs.begin() + 3 * t, mesh_.uvs.begin() + 3 * t + 3);
        m.materials.push_back(mesh_.material(t));
    }
    if (!hasUv)
        m.uvs.resize(3 * m.triangles.size()); // zeros, in one go
    for (const OutTri& o : tris) {
        m.triangles.push_back({id(o.v[0]), id(o.v[1]), id(o.v[2])});
        emitAttributes(o, hasN ? &m.normals : nullptr, m.uvs, m.materials);
    }
    return m;
}

RemainderEdit Clipper::assembleEdit(std::vector<std::uint32_t> removed) const {
    RemainderEdit e;
    e.removed = std::move(removed);
    std::unordered_map<std::uint32_t, std::uint32_t> local; // created point -> its new vertex
    const bool hasN = mesh_.hasNormals();
    for (const OutTri& o : tris_[k_]) {
        Triangle t;
        for (int c = 0; c < 3; ++c) {
            const std::uint32_t g = o.v[c];
            if (g < nV_) {
                t[static_cast<std::size_t>(c)] = g;
                continue;
            }
            auto [it, fresh] = local.emplace(g, nV_ + static_cast<std::uint32_t>(e.newPositions.size()));
            if (fresh)
                e.newPositions.push_back(pos(g));
            t[static_cast<std::size_t>(c)] = it->second;
        }
        e.added.triangles.push_back(t);
        emitAttributes(o, hasN ? &e.added.normals : nullptr, e.added.uvs, e.added.materials);
    }
    return e;
}

// Every directed edge of the new triangles that touches a created point has its twin among them: null, or
// why not.
const char* openNewEdges(const std::vector<std::array<std::uint32_t, 3>>& tris, std::uint32_t firstCreated) {
    std::unordered_set<std::uint64_t> directed;
    directed.reserve(tris.size() * 3);
    for (const auto& t : tris)
        for (int c = 0; c < 3; ++c)
            if (!directed.insert(pairKey(t[c], t[(c + 1) % 3])).second)
                return "edge used twice in one direction";
    for (const auto& t : tris)
        for (int c = 0; c < 3; ++c) {
            const std::uint32_t a = t[c], b = t[(c + 1) % 3];
            if ((a >= firstCreated || b >= firstCreated) && !directed.count(pairKey(b, a)))
                return "open edge at the cut";
        }
    return nullptr;
}

Result<std::vector<Mesh>> Clipper::run(const VolumeIntegrals* known,
                                       std::optional<VolumeIntegrals>& restIntegrals, RemainderEdit* edit) {
    const std::size_t nT = mesh_.triangles.size();
    // Per vertex, the sides of the cells' box (with eps) it lies beyond, 2 bits per axis: a triangle misses
    // the box exactly when its three corners share a bit.
    thread_local std::vector<std::uint8_t> beyond;
    beyond.resize(nV_);
    const Vec3 hi{box_.hi.x + eps_, box_.hi.y + eps_, box_.hi.z + eps_}, lo = box_.lo;
    const double e = eps_;
    const Vec3* at = mesh_.positions.data();
    std::uint8_t* out = beyond.data();
    for (std::uint32_t v = 0; v < nV_; ++v) { // branch-free, so that it vectorizes
        const Vec3 p = at[v];
        out[v] = static_cast<std::uint8_t>(unsigned{p.x > hi.x} | unsigned{p.x + e < lo.x} << 1 |
                                           unsigned{p.y > hi.y} << 2 | unsigned{p.y + e < lo.y} << 3 |
                                           unsigned{p.z > hi.z} << 4 | unsigned{p.z + e < lo.z} << 5);
    }
    std::vector<std::pair<std::uint32_t, std::vector<std::uint32_t>>> cut; // triangle, cells it may cross
    std::vector<std::uint32_t> candidates;
    auto keep = [&](std::uint32_t t) { // the rest keeps t whole (an edit keeps it where it is)
        if (!edit)
            untouched_[k_].push_back(t);
    };
    for (std::uint32_t t = 0; t < nT; ++t) {
        const Triangle& tri = mesh_.triangles[t];
        if (beyond[tri[0]] & beyond[tri[1]] & beyond[tri[2]]) {
            keep(t);
            continue;
        }
        Aabb box;
        for (std::uint32_t v : tri)
            box.extend(mesh_.positions[v]);
        candidates.clear();
        std::uint32_t insideOf = kNone;
        for (std::uint32_t c = 0; c < k_; ++c) {
            if (!box.overlaps(cx_.cells[c].box, eps_))
                continue;
            for (std::uint32_t v : tri)
                ensureDistances(v);
            bool outside = false, inside = true;
            for (std::size_t l = 0; l < cx_.cells[c].faces.size() && !outside; ++l) {
                int positive = 0;
                for (std::uint32_t v : tri)
                    positive += cellDist(v, c, l) > 0;
                outside = positive == 3;
                inside &= positive == 0;
            }
            if (outside)
                continue;
            candidates.push_back(c);
            if (inside)
                insideOf = c;
        }
        if (candidates.empty())
            keep(t);
        else if (insideOf != kNone && candidates.size() == 1)
            untouched_[insideOf].push_back(t);
        else
            cut.emplace_back(t, candidates);
    }
    std::vector<std::size_t> scanned; // per region, the triangles the scan kept whole
    for (const auto& kept : untouched_)
        scanned.push_back(kept.size());
    for (const auto& [t, cells] : cut) {
        cutTriangle(t, cells);
        if (declined_)
            return clipDeclined(declined_);
    }
    buildCaps();
    if (declined_)
        return clipDeclined(declined_);

    std::vector<Mesh> result;
    for (std::uint32_t r = 0; r < k_; ++r)
        result.push_back(assemble(r));
    result.push_back(edit ? Mesh{} : assemble(k_));
    // The triangles the rest lost: those inside a cell, and those cut (a candidate the cut left whole joined
    // the untouched triangles of its region after the scan).
    std::vector<std::uint32_t> lost;
    if (known || edit) {
        std::vector<std::uint32_t> leftWhole;
        for (std::uint32_t r = 0; r <= k_; ++r)
            leftWhole.insert(leftWhole.end(), untouched_[r].begin() + static_cast<std::ptrdiff_t>(scanned[r]),
                             untouched_[r].end());
        std::sort(leftWhole.begin(), leftWhole.end());
        for (const auto& [t, cells] : cut)
            if (!std::binary_search(leftWhole.begin(), leftWhole.end(), t))
                lost.push_back(t);
        for (std::uint32_t r = 0; r < k_; ++r)
            lost.insert(lost.end(), untouched_[r].begin(), untouched_[r].end());
    }
    // The rest's integrals: the input's minus the triangles it lost plus its new ones.
    if (known) {
        VolumeIntegrals rest = *known;
        for (std::uint32_t t : lost)
            rest.remove(mesh_, t);
        for (const OutTri& o : tris_[k_])
            rest.add(pos(o.v[0]), pos(o.v[1]), pos(o.v[2]));
        restIntegrals = rest;
    }
    // Verify: the new faces close up, and no volume is created or lost.
    double sum = 0;
    for (std::uint32_t r = 0; r <= k_; ++r) {
        std::vector<std::array<std::uint32_t, 3>> created;
        created.reserve(tris_[r].size());
        for (const OutTri& o : tris_[r])
            created.push_back({o.v[0], o.v[1], o.v[2]});
        if (const char* why = openNewEdges(created, nV_))
            return clipDeclined(why);
        const bool empty = r == k_ && edit ? lost.size() == nT && tris_[k_].empty() : result[r].empty();
        const double v = empty                        ? 0.0
                         : (r == k_ && restIntegrals) ? restIntegrals->volume
                                                      : signedVolume(result[r]);
        if (v < 0)
            return clipDeclined("negative volume");
        sum += v;
    }
    const double v0 = known ? known->volume : signedVolume(mesh_);
    if (std::abs(sum - v0) > 1e-9 * std::abs(v0))
        return clipDeclined("volume not conserved");
    if (edit) {
        std::sort(lost.begin(), lost.end());
        *edit = assembleEdit(std::move(lost));
    }
    return result;
}

} // namespace

Result<CellSplit> clipByConvexCell(const Mesh& mesh, const ConvexPolytope& cell) {
    if (cell.empty())
        return makeError(ErrorCode::InvalidInput, "empty cell");
    auto split = clipByConvexCells(mesh, {cell});
    if (!split)
        return split.error();
    return CellSplit{std::move(split->outside), std::move(split->inside.front())};
}

namespace {

/// f() with a failure (e.g. out of memory) as a GeometryFailure error; empty cells are InvalidInput.
template <class F>
auto guardedClip(const std::vector<ConvexPolytope>& cells, F f) -> decltype(f()) {
    if (cells.empty() ||
        std::any_of(cells.begin(), cells.end(), [](const ConvexPolytope& c) { return c.empty(); }))
        return makeError(ErrorCode::InvalidInput, "no cells, or an empty cell");
    try {
        return f();
    } catch (const std::exception& e) {
        return makeError(ErrorCode::GeometryFailure, std::string("fast clip failed: ") + e.what());
    }
}

} // namespace

Result<MultiCellEdit> clipByConvexCellsAsEdit(const Mesh& mesh, const std::vector<ConvexPolytope>& cells,
                                              const VolumeIntegrals& meshIntegrals) {
    return guardedClip(cells, [&]() -> Result<MultiCellEdit> {
        const Clipper::Scale scale = Clipper::scaleOf(cells);
        Result<CellComplex> cx = buildCellComplex(cells, scale.eps);
        if (!cx)
            return cx.error();
        Clipper clipper(mesh, scale, std::move(*cx));
        MultiCellEdit out;
        std::optional<VolumeIntegrals> rest;
        Result<std::vector<Mesh>> run = clipper.run(&meshIntegrals, rest, &out.outside);
        if (!run)
            return run.error();
        std::vector<Mesh>& regions = *run;
        regions.pop_back();
        out.inside = std::move(regions);
        for (std::uint32_t r = 0; r < out.inside.size(); ++r)
            out.insideKept.push_back(clipper.keptWhole(r));
        out.outsideIntegrals = *rest;
        return out;
    });
}

Result<MultiCellSplit> clipByConvexCells(const Mesh& mesh, const std::vector<ConvexPolytope>& cells,
                                         const VolumeIntegrals* meshIntegrals) {
    return guardedClip(cells, [&]() -> Result<MultiCellSplit> {
        const Clipper::Scale scale = Clipper::scaleOf(cells);
        Result<CellComplex> cx = buildCellComplex(cells, scale.eps);
        if (!cx)
            return cx.error();
        Clipper clipper(mesh, scale, std::move(*cx));
        MultiCellSplit out;
        Result<std::vector<Mesh>> run = clipper.run(meshIntegrals, out.outsideIntegrals);
        if (!run)
            return run.error();
        std::vector<Mesh>& regions = *run;
        out.outside = std::move(regions.back());
        regions.pop_back();
        out.inside = std::move(regions);
        return out;
    });
}

} // namespace rubble::detail
