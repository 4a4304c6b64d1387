#include "ConvexCellClipper.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <ranges>
#include <unordered_map>
#include <unordered_set>

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include "geometry/RayParity.hpp"
#include "rubble/MassProperties.hpp"

namespace rubble::detail {

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb = CGAL::Triangulation_vertex_base_with_info_2<std::uint32_t, K>;
using Fbi = CGAL::Triangulation_face_base_with_info_2<int, K>;
using Fb = CGAL::Constrained_triangulation_face_base_2<K, Fbi>;
using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
using CDT = CGAL::Constrained_Delaunay_triangulation_2<K, Tds, CGAL::Exact_predicates_tag>;

/// Internal signal: this configuration is not handled robustly here; the caller uses an exact backend.
struct Degenerate {
    const char* why;
};

constexpr std::uint32_t kNone = 0xFFFFFFFFu;

std::uint64_t pairKey(std::uint32_t a, std::uint32_t b) {
    return (std::uint64_t(a) << 32) | b;
}

/// Key of a created point: which mesh edge / triangle and which cell planes it lies on.
struct PointKey {
    std::uint32_t kind; // 1: mesh edge (a<b) ∩ plane c; 2: triangle a ∩ planes b<c; 3: cell vertex a
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
    bool onMeshEdge; // true: the mesh edge (a,b) with a<b; false: the cut line of plane a
    std::uint32_t a, b;
};

/// A polygon corner and the support of the edge to the next corner.
struct Corner {
    std::uint32_t id;
    Support next;
};

/// Convex cell as vertices, CCW face loops and planes.
struct CellTopology {
    std::vector<Vec3> vertices;
    std::vector<std::vector<std::uint32_t>> loops;
    std::vector<Plane> planes;
    std::unordered_map<std::uint64_t, std::uint32_t> faceOfDirectedEdge;
};

CellTopology buildTopology(const ConvexPolytope& cell) {
    CellTopology t;
    std::map<std::tuple<double, double, double>, std::uint32_t> index;
    for (const PolytopeFace& f : cell.faces()) {
        std::vector<std::uint32_t> loop;
        for (const Vec3& c : f.corners) {
            auto [it, inserted] =
                index.emplace(std::make_tuple(c.x, c.y, c.z), static_cast<std::uint32_t>(t.vertices.size()));
            if (inserted)
                t.vertices.push_back(c);
            if (loop.empty() || loop.back() != it->second)
                loop.push_back(it->second);
        }
        while (loop.size() > 1 && loop.front() == loop.back())
            loop.pop_back();
        if (loop.size() < 3)
            continue;
        const auto face = static_cast<std::uint32_t>(t.loops.size());
        for (std::size_t i = 0; i < loop.size(); ++i)
            if (!t.faceOfDirectedEdge.emplace(pairKey(loop[i], loop[(i + 1) % loop.size()]), face).second)
                throw Degenerate{"cell edge used twice"};
        t.loops.push_back(std::move(loop));
        t.planes.push_back(f.plane);
    }
    for (const auto& [key, face] : t.faceOfDirectedEdge)
        if (!t.faceOfDirectedEdge.count(pairKey(static_cast<std::uint32_t>(key & 0xFFFFFFFFu),
                                                static_cast<std::uint32_t>(key >> 32))))
            throw Degenerate{"cell is not closed"};
    if (t.loops.size() < 4)
        throw Degenerate{"cell has fewer than 4 faces"};
    return t;
}

/// An orthonormal basis (u, v) of a plane with normal n such that u × v = n.
void planeBasis(const Vec3& n, Vec3& u, Vec3& v) {
    u = normalized(std::abs(n.x) < 0.6 ? cross(Vec3{1, 0, 0}, n) : cross(Vec3{0, 1, 0}, n));
    v = cross(n, u);
}

class Clipper {
public:
    Clipper(const Mesh& mesh, const ConvexPolytope& cell) : mesh_(mesh), topo_(buildTopology(cell)) {
        nV_ = static_cast<std::uint32_t>(mesh.positions.size());
        k_ = static_cast<std::uint32_t>(topo_.planes.size());
        cellBox_ = cell.bounds();
        double maxAbs = 0;
        for (int a = 0; a < 3; ++a)
            maxAbs = std::max({maxAbs, std::abs(cellBox_.lo[a]), std::abs(cellBox_.hi[a])});
        eps_ = std::max(1e-10 * cellBox_.diagonal(), 1e-14 * maxAbs);
        cutEdges_.resize(k_);
    }

    CellSplit run();

private:
    const Mesh& mesh_;
    CellTopology topo_;
    std::uint32_t nV_ = 0, k_ = 0;
    Aabb cellBox_;
    double eps_ = 0;

    std::vector<Vec3> extra_; // created points, ids nV_ + i
    std::unordered_map<PointKey, std::uint32_t, PointKeyHash> keyed_;
    std::vector<std::int32_t> distSlot_; // per mesh vertex: offset into dist_ or -1
    std::vector<double> dist_;

    // Per plane: the directed cut edges of the inside polygons on that plane.
    std::vector<std::vector<std::pair<std::uint32_t, std::uint32_t>>> cutEdges_;
    // Per cell edge (i<j): points where it pierces the mesh surface.
    std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> pierce_;

    // Output triangles by point id, with the source triangle (kNone for cap faces) and cap plane.
    struct OutTri {
        std::uint32_t v[3];
        std::uint32_t source; // mesh triangle it lies in, or kNone for a cap
        std::uint32_t plane;  // cap plane when source == kNone
    };
    std::vector<OutTri> inTris_, outTris_;
    std::vector<std::uint32_t> untouchedIn_, untouchedOut_;

    const Vec3& pos(std::uint32_t id) const { return id < nV_ ? mesh_.positions[id] : extra_[id - nV_]; }

    double dist(std::uint32_t id, std::uint32_t plane) const {
        if (id < nV_)
            return dist_[static_cast<std::size_t>(distSlot_[id]) + plane];
        return topo_.planes[plane].signedDistance(extra_[id - nV_]);
    }

    void ensureDistances(std::uint32_t v) {
        if (distSlot_[v] >= 0)
            return;
        distSlot_[v] = static_cast<std::int32_t>(dist_.size());
        for (std::uint32_t i = 0; i < k_; ++i)
            dist_.push_back(topo_.planes[i].signedDistance(mesh_.positions[v]));
    }

    std::uint32_t addPoint(const PointKey& key, const Vec3& p) {
        auto [it, inserted] = keyed_.emplace(key, nV_ + static_cast<std::uint32_t>(extra_.size()));
        if (inserted)
            extra_.push_back(p);
        return it->second;
    }

    std::uint32_t crossing(std::uint32_t tri, const Support& s, std::uint32_t plane, std::uint32_t from,
                           std::uint32_t to, double dFrom, double dTo);
    std::vector<Corner> clipTriangle(std::uint32_t t);
    void cutTriangle(std::uint32_t t);
    void emitConvex(const std::vector<std::uint32_t>& poly, const Vec3& normal, std::uint32_t source);
    void triangulateRegion(const std::vector<std::pair<std::uint32_t, std::uint32_t>>& edges,
                           std::size_t boundaryEdges, const Vec3& normal, std::uint32_t source,
                           std::uint32_t plane, std::vector<OutTri>& out);
    void buildCaps();
    bool pointInsideMesh(const Vec3& p) const;
    Mesh assemble(const std::vector<std::uint32_t>& untouched, const std::vector<OutTri>& tris,
                  bool reverseCaps) const;
};

std::uint32_t Clipper::crossing(std::uint32_t tri, const Support& s, std::uint32_t plane, std::uint32_t from,
                                std::uint32_t to, double dFrom, double dTo) {
    if (s.onMeshEdge) {
        const PointKey key{1, s.a, s.b, plane};
        if (auto it = keyed_.find(key); it != keyed_.end())
            return it->second;
        // Canonical: from the lower vertex index to the higher, with their own distances.
        const double da = dist(s.a, plane), db = dist(s.b, plane);
        if (!((da < 0 && db > 0) || (da > 0 && db < 0)))
            throw Degenerate{"edge crossing without sign change"};
        const Vec3& pa = mesh_.positions[s.a];
        const Vec3& pb = mesh_.positions[s.b];
        return addPoint(key, pa + (pb - pa) * (da / (da - db)));
    }
    const std::uint32_t i = std::min(s.a, plane), j = std::max(s.a, plane);
    const PointKey key{2, tri, i, j};
    if (auto it = keyed_.find(key); it != keyed_.end())
        return it->second;
    const Vec3& p = pos(from);
    const Vec3& q = pos(to);
    return addPoint(key, p + (q - p) * (dFrom / (dFrom - dTo)));
}

// Sutherland–Hodgman clipping of triangle t by all cell planes; corners carry the support of their next edge.
std::vector<Corner> Clipper::clipTriangle(std::uint32_t t) {
    const Triangle& tri = mesh_.triangles[t];
    std::vector<Corner> poly;
    for (int c = 0; c < 3; ++c) {
        const std::uint32_t a = tri[c], b = tri[(c + 1) % 3];
        poly.push_back({a, {true, std::min(a, b), std::max(a, b)}});
    }
    std::vector<Corner> next;
    std::vector<double> d;
    for (std::uint32_t i = 0; i < k_ && !poly.empty(); ++i) {
        d.resize(poly.size());
        bool anyOut = false, anyIn = false;
        for (std::size_t c = 0; c < poly.size(); ++c) {
            d[c] = dist(poly[c].id, i);
            if (std::abs(d[c]) <= eps_) {
                throw Degenerate{"point on a cell plane"};
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
                    const std::uint32_t x = crossing(t, cur.next, i, cur.id, nxt.id, d[c], d[(c + 1) % n]);
                    next.push_back({x, {false, i, 0}});
                }
            } else if (nxtIn) {
                const std::uint32_t y = crossing(t, cur.next, i, cur.id, nxt.id, d[c], d[(c + 1) % n]);
                next.push_back({y, cur.next});
            }
        }
        poly.swap(next);
    }
    return poly;
}

// Triangulates a convex polygon (possibly with collinear corners) by clipping strictly convex ears.
void Clipper::emitConvex(const std::vector<std::uint32_t>& polyIn, const Vec3& normal, std::uint32_t source) {
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
        if (ear == poly.size())
            throw Degenerate{"flat polygon"};
        const std::size_t n = poly.size();
        inTris_.push_back({{poly[(ear + n - 1) % n], poly[ear], poly[(ear + 1) % n]}, source, kNone});
        poly.erase(poly.begin() + static_cast<std::ptrdiff_t>(ear));
    }
    inTris_.push_back({{poly[0], poly[1], poly[2]}, source, kNone});
}

// Triangulates (with a constrained Delaunay triangulation) the planar region bounded by the first
// `boundaryEdges` directed edges (counter-clockwise seen along normal), minus the polygon whose edges are the
// remaining ones (the hole). Inside and outside are found topologically: walking from the unbounded face,
// every crossed boundary edge toggles "inside the region" and every crossed hole edge toggles "inside the
// hole".
void Clipper::triangulateRegion(const std::vector<std::pair<std::uint32_t, std::uint32_t>>& edges,
                                std::size_t boundaryEdges, const Vec3& normal, std::uint32_t source,
                                std::uint32_t plane, std::vector<OutTri>& out) {
    Vec3 u, v;
    planeBasis(normalized(normal), u, v);
    auto to2 = [&](std::uint32_t id) {
        const Vec3& p = pos(id);
        return K::Point_2(dot(p, u), dot(p, v));
    };
    CDT cdt;
    std::unordered_map<std::uint32_t, CDT::Vertex_handle> handle;
    auto vertex = [&](std::uint32_t id) {
        auto it = handle.find(id);
        if (it != handle.end())
            return it->second;
        const std::size_t before = cdt.number_of_vertices();
        CDT::Vertex_handle h = cdt.insert(to2(id));
        if (cdt.number_of_vertices() != before + 1)
            throw Degenerate{"coincident points in a cut face"};
        h->info() = id;
        handle.emplace(id, h);
        return h;
    };
    std::unordered_map<std::uint64_t, int> flags;
    for (std::size_t e = 0; e < edges.size(); ++e) {
        const auto [a, b] = edges[e];
        cdt.insert_constraint(vertex(a), vertex(b));
        flags[pairKey(std::min(a, b), std::max(a, b))] ^= e < boundaryEdges ? 1 : 2;
    }
    if (cdt.number_of_vertices() != handle.size())
        throw Degenerate{"cut face constraints intersect"};

    for (auto f = cdt.all_faces_begin(); f != cdt.all_faces_end(); ++f)
        f->info() = -1;
    std::vector<CDT::Face_handle> queue;
    for (auto f = cdt.all_faces_begin(); f != cdt.all_faces_end(); ++f)
        if (cdt.is_infinite(f)) {
            f->info() = 0;
            queue.push_back(f);
        }
    while (!queue.empty()) {
        const CDT::Face_handle f = queue.back();
        queue.pop_back();
        for (int i = 0; i < 3; ++i) {
            const CDT::Face_handle n = f->neighbor(i);
            const CDT::Vertex_handle a = f->vertex(CDT::cw(i)), b = f->vertex(CDT::ccw(i));
            int toggle = 0;
            if (!cdt.is_infinite(a) && !cdt.is_infinite(b)) {
                auto it = flags.find(pairKey(std::min(a->info(), b->info()), std::max(a->info(), b->info())));
                if (it != flags.end())
                    toggle = it->second;
            }
            const int state = f->info() ^ toggle;
            if (n->info() < 0) {
                n->info() = state;
                queue.push_back(n);
            } else if (n->info() != state) {
                throw Degenerate{"cut face boundary is not closed"};
            }
        }
    }
    for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
        if (f->info() != 1)
            continue;
        if (CGAL::orientation(f->vertex(0)->point(), f->vertex(1)->point(), f->vertex(2)->point()) !=
            CGAL::LEFT_TURN)
            throw Degenerate{"flat triangle in a cut face"};
        out.push_back({{f->vertex(0)->info(), f->vertex(1)->info(), f->vertex(2)->info()}, source, plane});
    }
}

void Clipper::cutTriangle(std::uint32_t t) {
    const std::vector<Corner> poly = clipTriangle(t);
    const Triangle& tri = mesh_.triangles[t];
    if (poly.empty()) {
        untouchedOut_.push_back(t);
        return;
    }
    bool created = false;
    for (const Corner& c : poly)
        created |= c.id >= nV_;
    if (!created) { // wholly inside
        untouchedIn_.push_back(t);
        return;
    }
    const Vec3 normal = mesh_.triangleNormal(t);
    std::vector<std::uint32_t> ids;
    for (const Corner& c : poly)
        ids.push_back(c.id);
    emitConvex(ids, normal, t);

    // Record cut edges and pierce points for the caps; contact points on the triangle's edges.
    std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> contacts; // by mesh edge (a<b)
    for (std::size_t c = 0; c < poly.size(); ++c) {
        const Corner& cur = poly[c];
        const Corner& nxt = poly[(c + 1) % poly.size()];
        if (!cur.next.onMeshEdge) {
            cutEdges_[cur.next.a].emplace_back(cur.id, nxt.id);
        }
        if (cur.id >= nV_) {
            // Which key made it: look at its supports.
            const Support& in = poly[(c + poly.size() - 1) % poly.size()].next;
            const Support& out = cur.next;
            if (!in.onMeshEdge && !out.onMeshEdge) {
                const std::uint32_t i = std::min(in.a, out.a), j = std::max(in.a, out.a);
                pierce_[pairKey(i, j)].push_back(cur.id);
            } else {
                const Support& edge = in.onMeshEdge ? in : out;
                contacts[pairKey(edge.a, edge.b)].push_back(cur.id);
            }
        }
    }
    // Remainder: the triangle minus the convex inside polygon, as a constrained triangulation.
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
    for (std::size_t c = 0; c < ids.size(); ++c)
        edges.emplace_back(ids[c], ids[(c + 1) % ids.size()]);
    triangulateRegion(edges, boundary, normal, t, kNone, outTris_);
}

bool Clipper::pointInsideMesh(const Vec3& p) const {
    return insideByRayParity(mesh_, std::views::iota(std::size_t{0}, mesh_.triangles.size()), p);
}

void Clipper::buildCaps() {
    // Map: per plane, point -> whether the inside polygon's cut edge leaves it (true) or arrives at it
    // (false).
    std::vector<std::unordered_map<std::uint32_t, bool>> leaves(k_);
    for (std::uint32_t i = 0; i < k_; ++i)
        for (const auto& [a, b] : cutEdges_[i]) {
            leaves[i][b] = true;
            leaves[i][a] = false;
        }
    const std::size_t nCellVerts = topo_.vertices.size();
    std::vector<int> vertexInside(nCellVerts, -1);
    auto setStatus = [&](std::uint32_t v, int s) {
        if (vertexInside[v] >= 0 && vertexInside[v] != s)
            throw Degenerate{"inconsistent cell vertex status"};
        vertexInside[v] = s;
    };
    // Per directed cell edge of face i: sorted pierce points and the inside status of each sub-edge.
    struct EdgeSplit {
        std::vector<std::uint32_t> points;
        std::vector<int> inside; // points.size() + 1 entries
    };
    std::vector<std::vector<EdgeSplit>> splits(k_);
    for (std::uint32_t i = 0; i < k_; ++i) {
        const auto& loop = topo_.loops[i];
        splits[i].resize(loop.size());
        for (std::size_t e = 0; e < loop.size(); ++e) {
            const std::uint32_t A = loop[e], B = loop[(e + 1) % loop.size()];
            const std::uint32_t j = topo_.faceOfDirectedEdge.at(pairKey(B, A));
            EdgeSplit& s = splits[i][e];
            if (auto it = pierce_.find(pairKey(std::min(i, j), std::max(i, j))); it != pierce_.end())
                s.points = it->second;
            const Vec3 pa = topo_.vertices[A], dir = topo_.vertices[B] - pa;
            std::sort(s.points.begin(), s.points.end(), [&](std::uint32_t x, std::uint32_t y) {
                return dot(pos(x) - pa, dir) < dot(pos(y) - pa, dir);
            });
            if (std::adjacent_find(s.points.begin(), s.points.end()) != s.points.end())
                throw Degenerate{"duplicate pierce point"};
            s.inside.assign(s.points.size() + 1, -1);
            for (std::size_t q = 0; q < s.points.size(); ++q) {
                auto it = leaves[i].find(s.points[q]);
                if (it == leaves[i].end())
                    throw Degenerate{"pierce point without cut edge"};
                const int before =
                    it->second ? 1 : 0; // cap edge leaves the point: the sub-edge before is inside
                for (auto [slot, value] : {std::pair{q, before}, std::pair{q + 1, 1 - before}}) {
                    if (s.inside[slot] >= 0 && s.inside[slot] != value)
                        throw Degenerate{"inconsistent cut along a cell edge"};
                    s.inside[slot] = value;
                }
            }
            if (!s.points.empty()) {
                setStatus(A, s.inside.front());
                setStatus(B, s.inside.back());
            }
        }
    }
    // Propagate vertex status along unpierced cell edges; with no information at all, cast a ray.
    bool changed = true;
    while (changed) {
        changed = false;
        for (std::uint32_t i = 0; i < k_; ++i) {
            const auto& loop = topo_.loops[i];
            for (std::size_t e = 0; e < loop.size(); ++e) {
                if (!splits[i][e].points.empty())
                    continue;
                const std::uint32_t A = loop[e], B = loop[(e + 1) % loop.size()];
                if (vertexInside[A] >= 0 && vertexInside[B] < 0) {
                    vertexInside[B] = vertexInside[A];
                    changed = true;
                } else if (vertexInside[B] >= 0 && vertexInside[A] < 0) {
                    vertexInside[A] = vertexInside[B];
                    changed = true;
                } else if (vertexInside[A] >= 0 && vertexInside[A] != vertexInside[B]) {
                    throw Degenerate{"inconsistent unpierced cell edge"};
                }
            }
        }
        if (!changed && std::find(vertexInside.begin(), vertexInside.end(), -1) != vertexInside.end()) {
            const auto it = std::find(vertexInside.begin(), vertexInside.end(), -1);
            *it =
                pointInsideMesh(topo_.vertices[static_cast<std::size_t>(it - vertexInside.begin())]) ? 1 : 0;
            changed = true;
        }
    }
    // Cell vertices become points (created lazily when a cap uses them).
    auto cellPoint = [&](std::uint32_t v) { return addPoint({3, v, 0, 0}, topo_.vertices[v]); };
    std::vector<OutTri> caps;
    for (std::uint32_t i = 0; i < k_; ++i) {
        std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;
        for (const auto& [a, b] : cutEdges_[i])
            edges.emplace_back(b, a);
        const auto& loop = topo_.loops[i];
        for (std::size_t e = 0; e < loop.size(); ++e) {
            const std::uint32_t A = loop[e], B = loop[(e + 1) % loop.size()];
            const EdgeSplit& s = splits[i][e];
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
        triangulateRegion(edges, edges.size(), topo_.planes[i].normal, kNone, i, caps);
    }
    for (const OutTri& c : caps) {
        inTris_.push_back(c);
        outTris_.push_back({{c.v[0], c.v[2], c.v[1]}, kNone, c.plane});
    }
}

Mesh Clipper::assemble(const std::vector<std::uint32_t>& untouched, const std::vector<OutTri>& tris,
                       bool reverseCaps) const {
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
        if (o.source == kNone) {
            const Vec3 n = reverseCaps ? -topo_.planes[o.plane].normal : topo_.planes[o.plane].normal;
            if (hasN)
                m.normals.insert(m.normals.end(), 3, n);
            m.uvs.insert(m.uvs.end(), 3, Vec2{}); // interior UVs are generated by the fracture pipeline
            m.materials.push_back(kInteriorMaterial);
            continue;
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
            if (hasN)
                m.normals.push_back(normalized(mesh_.normals[b] * w0 + mesh_.normals[b + 1] * w1 +
                                               mesh_.normals[b + 2] * w2));
            if (hasUv) {
                const Vec2 &u0 = mesh_.uvs[b], &u1 = mesh_.uvs[b + 1], &u2 = mesh_.uvs[b + 2];
                m.uvs.push_back({u0.x * w0 + u1.x * w1 + u2.x * w2, u0.y * w0 + u1.y * w1 + u2.y * w2});
            } else {
                m.uvs.push_back({});
            }
        }
        m.materials.push_back(mesh_.material(o.source));
    }
    return m;
}

// Every directed edge of the new triangles that touches a created point has its twin among them.
void checkNewEdgesClosed(const std::vector<std::array<std::uint32_t, 3>>& tris, std::uint32_t firstCreated) {
    std::unordered_set<std::uint64_t> directed;
    directed.reserve(tris.size() * 3);
    for (const auto& t : tris)
        for (int c = 0; c < 3; ++c)
            if (!directed.insert(pairKey(t[c], t[(c + 1) % 3])).second) {
                throw Degenerate{"edge used twice in one direction"};
            }
    for (const auto& t : tris)
        for (int c = 0; c < 3; ++c) {
            const std::uint32_t a = t[c], b = t[(c + 1) % 3];
            if ((a >= firstCreated || b >= firstCreated) && !directed.count(pairKey(b, a)))
                throw Degenerate{"open edge at the cut"};
        }
}

CellSplit Clipper::run() {
    distSlot_.assign(nV_, -1);
    const std::size_t nT = mesh_.triangles.size();
    std::vector<std::uint32_t> cut;
    for (std::uint32_t t = 0; t < nT; ++t) {
        const Triangle& tri = mesh_.triangles[t];
        Aabb box;
        for (std::uint32_t v : tri)
            box.extend(mesh_.positions[v]);
        if (!box.overlaps(cellBox_, eps_)) {
            untouchedOut_.push_back(t);
            continue;
        }
        for (std::uint32_t v : tri)
            ensureDistances(v);
        bool outside = false, inside = true;
        for (std::uint32_t i = 0; i < k_ && !outside; ++i) {
            int positive = 0;
            for (std::uint32_t v : tri)
                positive += dist(v, i) > 0;
            outside = positive == 3;
            inside &= positive == 0;
        }
        if (outside)
            untouchedOut_.push_back(t);
        else if (inside)
            untouchedIn_.push_back(t);
        else
            cut.push_back(t);
    }
    for (std::uint32_t t : cut)
        cutTriangle(t);
    buildCaps();

    CellSplit result;
    result.inside = assemble(untouchedIn_, inTris_, false);
    result.outside = assemble(untouchedOut_, outTris_, true);
    // Verify: the new faces close up, and no volume is created or lost.
    std::vector<std::array<std::uint32_t, 3>> newIn, newOut;
    for (const OutTri& o : inTris_) {
        newIn.push_back({o.v[0], o.v[1], o.v[2]});
    }
    for (const OutTri& o : outTris_) {
        newOut.push_back({o.v[0], o.v[1], o.v[2]});
    }
    checkNewEdgesClosed(newIn, nV_);
    checkNewEdgesClosed(newOut, nV_);
    const double v0 = signedVolume(mesh_);
    const double vi = result.inside.empty() ? 0.0 : signedVolume(result.inside);
    const double vo = result.outside.empty() ? 0.0 : signedVolume(result.outside);
    if (vi < 0 || vo < 0 || std::abs(vi + vo - v0) > 1e-9 * std::abs(v0))
        throw Degenerate{"volume not conserved"};
    return result;
}

} // namespace

Result<CellSplit> clipByConvexCell(const Mesh& mesh, const ConvexPolytope& cell) {
    if (cell.empty())
        return makeError(ErrorCode::InvalidInput, "empty cell");
    try {
        Clipper clipper(mesh, cell);
        return clipper.run();
    } catch (const Degenerate& d) {
        return makeError(ErrorCode::GeometryFailure, std::string("fast clip declined: ") + d.why);
    } catch (const std::exception& e) {
        return makeError(ErrorCode::GeometryFailure, std::string("fast clip failed: ") + e.what());
    }
}

} // namespace rubble::detail
