#include "Clipper.hpp"

#include "geometry/PlanarTriangulation.hpp"

namespace rubble::detail::clip {

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

} // namespace rubble::detail::clip
