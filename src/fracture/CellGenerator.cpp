// Cell generators: the thesis's single randomized Voronoi cell (Voro++) and a Mueller-2013-style shatter
// pattern (the dual of one exact-predicate Delaunay triangulation, so its cells form a complex by
// construction; docs/robustness.md). Cells are built in a local frame around the impact, then rotated
// randomly about it. Everything is a pure function of the inputs and the seed.

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numbers>

#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Exact_rational.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>
#include <voro++/voro++.hh>

#include "rubble/core/Random.hpp"
#include "rubble/fracture/Fracture.hpp"

namespace rubble {

namespace {

/// A cell's raw Voro++ output in world coordinates: vertex positions and outward CCW face loops.
struct RawCell {
    std::vector<Vec3> vertices;
    std::vector<std::vector<int>> faces;
};

/// The Voronoi cell of site `self` among `sites` (local coordinates) clipped by the cube [-h, h]^3, mapped
/// to world coordinates by p -> impact + rotation * (scale * p). Empty when Voro++ deletes the cell.
RawCell voronoiCell(const std::vector<Vec3>& sites, std::size_t self, double h, const Mat3& rotation,
                    double scale, const Vec3& impact) {
    const Vec3 c = sites[self];
    voro::voronoicell_neighbor cell;
    cell.init(-h - c.x, h - c.x, -h - c.y, h - c.y, -h - c.z, h - c.z);
    for (std::size_t k = 0; k < sites.size(); ++k) {
        if (k == self)
            continue;
        const Vec3 d = sites[k] - c;
        const double rsq = lengthSquared(d);
        if (rsq == 0)
            continue;
        if (!cell.nplane(d.x, d.y, d.z, rsq, static_cast<int>(k)))
            return {};
    }
    std::vector<double> v;
    std::vector<int> fv;
    cell.vertices(v);
    cell.face_vertices(fv);
    RawCell raw;
    for (std::size_t i = 0; i + 2 < v.size(); i += 3) {
        const Vec3 local{v[i] + c.x, v[i + 1] + c.y, v[i + 2] + c.z};
        raw.vertices.push_back(impact + rotation * (local * scale));
    }
    for (std::size_t i = 0; i < fv.size();) {
        const int n = fv[i];
        std::vector<int> face(fv.begin() + static_cast<std::ptrdiff_t>(i) + 1,
                              fv.begin() + static_cast<std::ptrdiff_t>(i) + 1 + n);
        // Voro++ lists face vertices clockwise seen from outside; Rubble wants counter-clockwise.
        std::reverse(face.begin(), face.end());
        raw.faces.push_back(std::move(face));
        i += static_cast<std::size_t>(n) + 1;
    }
    return raw;
}

/// Newell normal (unnormalised, length = twice the area) of a polygon.
Vec3 newell(const std::vector<Vec3>& p) {
    Vec3 n;
    for (std::size_t i = 0; i < p.size(); ++i) {
        const Vec3& a = p[i];
        const Vec3& b = p[(i + 1) % p.size()];
        n.x += (a.y - b.y) * (a.z + b.z);
        n.y += (a.z - b.z) * (a.x + b.x);
        n.z += (a.x - b.x) * (a.y + b.y);
    }
    return n * 0.5;
}

/// Turns a raw cell into a ConvexPolytope: faces tagged with their index, planes from the corners.
ConvexPolytope toPolytope(const RawCell& raw) {
    std::vector<PolytopeFace> faces;
    Vec3 centre;
    for (const Vec3& p : raw.vertices)
        centre += p;
    if (raw.vertices.empty())
        return {};
    centre = centre / static_cast<double>(raw.vertices.size());
    for (const auto& loop : raw.faces) {
        PolytopeFace f;
        for (int id : loop) {
            const Vec3& p = raw.vertices[static_cast<std::size_t>(id)];
            if (f.corners.empty() || !(f.corners.back() == p))
                f.corners.push_back(p);
        }
        while (f.corners.size() > 1 && f.corners.front() == f.corners.back())
            f.corners.pop_back();
        if (f.corners.size() < 3)
            continue;
        Vec3 n = newell(f.corners);
        if (lengthSquared(n) == 0)
            continue;
        n = normalized(n);
        double off = 0;
        Vec3 fc;
        for (const Vec3& p : f.corners) {
            off += dot(n, p);
            fc += p;
        }
        off /= static_cast<double>(f.corners.size());
        fc = fc / static_cast<double>(f.corners.size());
        if (dot(n, fc - centre) < 0) { // defensive: keep faces outward whatever the library's convention
            std::reverse(f.corners.begin(), f.corners.end());
            n = -n;
            off = -off;
        }
        f.plane = {n, off};
        f.tag = static_cast<std::int32_t>(faces.size());
        faces.push_back(std::move(f));
    }
    if (faces.size() < 4)
        return {};
    return ConvexPolytope::fromFaces(std::move(faces));
}

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using VertexBase = CGAL::Triangulation_vertex_base_with_info_3<int, Kernel>;
using Delaunay = CGAL::Delaunay_triangulation_3<
    Kernel,
    CGAL::Triangulation_data_structure_3<VertexBase, CGAL::Delaunay_triangulation_cell_base_3<Kernel>>>;

/// A tetrahedron's circumcentre, computed exactly and rounded: a flat tetrahedron (nearly cospherical sites)
/// makes the floating-point formula lose up to half its digits, and the Voronoi faces around it would bend.
Vec3 circumcentre(const Delaunay::Cell& tet) {
    using Exact = CGAL::Simple_cartesian<CGAL::Exact_rational>;
    std::array<Exact::Point_3, 4> p;
    for (int i = 0; i < 4; ++i) {
        const Kernel::Point_3& q = tet.vertex(i)->point();
        p[static_cast<std::size_t>(i)] = Exact::Point_3(q.x(), q.y(), q.z());
    }
    const Exact::Point_3 c = CGAL::circumcenter(p[0], p[1], p[2], p[3]);
    return {CGAL::to_double(c.x()), CGAL::to_double(c.y()), CGAL::to_double(c.z())};
}

/// The Voronoi cells of sites[wanted[i]] (local coordinates) as one complex: the dual of the Delaunay
/// triangulation of the sites and 26 ghost sites (ids -1 .. -26) at 2h{-1,0,1}^3 that bound every cell (the
/// cell of the origin among the ghosts alone is the cube [-h, h]^3). Every Voronoi vertex is the circumcentre
/// of one tetrahedron, computed once (exactly, then rounded) and shared by all cells around it; edges whose
/// ends round to the same point are contracted in every cell alike. Vertices are mapped to world coordinates
/// by p -> impact + rotation * (scale * p). A duplicated site gets an empty cell.
std::vector<RawCell> voronoiComplex(const std::vector<Vec3>& sites, const std::vector<std::size_t>& wanted,
                                    double h, const Mat3& rotation, double scale, const Vec3& impact) {
    std::vector<std::pair<Kernel::Point_3, int>> points;
    for (std::size_t i = 0; i < sites.size(); ++i)
        points.emplace_back(Kernel::Point_3(sites[i].x, sites[i].y, sites[i].z), static_cast<int>(i));
    int ghost = -1;
    for (int x = -1; x <= 1; ++x)
        for (int y = -1; y <= 1; ++y)
            for (int z = -1; z <= 1; ++z)
                if (x || y || z)
                    points.emplace_back(Kernel::Point_3(2 * h * x, 2 * h * y, 2 * h * z), ghost--);
    const Delaunay dt(points.begin(), points.end());
    std::vector<Delaunay::Vertex_handle> handle(sites.size());
    for (auto v = dt.finite_vertices_begin(); v != dt.finite_vertices_end(); ++v)
        if (v->info() >= 0)
            handle[static_cast<std::size_t>(v->info())] = v;

    // Voronoi vertices by tetrahedron, and the faces of every wanted cell as loops of them.
    std::map<Delaunay::Cell_handle, std::size_t> vertexOf;
    std::vector<Vec3> positions;
    std::vector<std::vector<std::vector<std::size_t>>> faces(wanted.size());
    for (std::size_t w = 0; w < wanted.size(); ++w) {
        const Delaunay::Vertex_handle v = handle[wanted[w]];
        if (v == Delaunay::Vertex_handle() || v->info() != static_cast<int>(wanted[w]))
            continue;
        std::vector<Delaunay::Edge> edges;
        dt.finite_incident_edges(v, std::back_inserter(edges));
        std::vector<std::pair<int, std::vector<std::size_t>>> byNeighbour;
        for (const Delaunay::Edge& e : edges) {
            const Delaunay::Vertex_handle a = e.first->vertex(e.second), b = e.first->vertex(e.third);
            const Delaunay::Vertex_handle other = a == v ? b : a;
            std::vector<std::size_t> loop;
            auto around = dt.incident_cells(e), start = around;
            do {
                auto [it, inserted] = vertexOf.emplace(around, positions.size());
                if (inserted)
                    positions.push_back(impact + rotation * (circumcentre(*around) * scale));
                loop.push_back(it->second);
            } while (++around != start);
            byNeighbour.emplace_back(other->info(), std::move(loop));
        }
        // Faces in a fixed order (by neighbour), so the output does not depend on traversal order.
        std::sort(byNeighbour.begin(), byNeighbour.end(),
                  [](const auto& x, const auto& y) { return x.first < y.first; });
        for (auto& [neighbour, loop] : byNeighbour)
            faces[w].push_back(std::move(loop));
    }

    // Contract the Voronoi edges of zero length (cospherical sites), the same way in every cell.
    std::vector<std::size_t> parent(positions.size());
    for (std::size_t i = 0; i < parent.size(); ++i)
        parent[i] = i;
    auto find = [&](std::size_t i) {
        while (parent[i] != i)
            i = parent[i] = parent[parent[i]];
        return i;
    };
    for (const auto& cell : faces)
        for (const auto& loop : cell)
            for (std::size_t i = 0; i < loop.size(); ++i) {
                const std::size_t a = loop[i], b = loop[(i + 1) % loop.size()];
                if (positions[a] == positions[b]) {
                    const std::size_t ra = find(a), rb = find(b);
                    parent[std::max(ra, rb)] = std::min(ra, rb);
                }
            }

    std::vector<RawCell> out(wanted.size());
    for (std::size_t w = 0; w < wanted.size(); ++w) {
        std::map<std::size_t, int> local;
        for (const auto& loop : faces[w]) {
            std::vector<int> face;
            for (std::size_t id : loop) {
                const std::size_t r = find(id);
                auto [it, inserted] = local.emplace(r, static_cast<int>(out[w].vertices.size()));
                if (inserted)
                    out[w].vertices.push_back(positions[r]);
                face.push_back(it->second);
            }
            out[w].faces.push_back(std::move(face));
        }
    }
    return out;
}

} // namespace

namespace {
constexpr double kSplinterAlong = 2.5;  // a splinter layout's cells: stretch along the grain
constexpr double kSplinterAcross = 0.6; // and squeeze across it

// A rotation whose local z is `axis` (any non-zero vector; else the world z), turned by `angle` about it.
Mat3 frameAround(const Vec3& axis, double angle) {
    const double len = length(axis);
    const Vec3 z = len > 0 && std::isfinite(len) ? axis / len : Vec3{0, 0, 1};
    const Vec3 helper = std::abs(z.x) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
    const Vec3 x0 = normalized(cross(helper, z));
    const Vec3 y0 = cross(z, x0);
    const Vec3 x = x0 * std::cos(angle) + y0 * std::sin(angle);
    const Vec3 y = cross(z, x);
    Mat3 r;
    for (int i = 0; i < 3; ++i) {
        r.m[i][0] = x[i];
        r.m[i][1] = y[i];
        r.m[i][2] = z[i];
    }
    return r;
}

// The longest edge direction of a box (x on ties; x for an empty box).
Vec3 longestAxis(const Aabb& b) {
    if (b.empty())
        return {1, 0, 0};
    const Vec3 d = b.size();
    if (d.x >= d.y && d.x >= d.z)
        return {1, 0, 0};
    return d.y >= d.z ? Vec3{0, 1, 0} : Vec3{0, 0, 1};
}

// Sites on jittered rings in the local xy plane, ring j holding 6j (docs/structure.md, radial layout).
void radialSites(std::vector<Vec3>& sites, int n, double h, Rng& rng) {
    int rings = 1;
    while (1 + 3 * rings * (rings + 1) < n + 1)
        ++rings;
    for (int j = 1; j <= rings; ++j) {
        const double radius = h * 0.98 * std::pow(static_cast<double>(j) / rings, 1.3);
        const double band = radius - h * 0.98 * std::pow(static_cast<double>(j - 1) / rings, 1.3);
        const int m = 6 * j;
        const double step = 2.0 * std::numbers::pi / m, offset = rng.uniform(0.0, step);
        for (int i = 0; i < m; ++i) {
            const double a = offset + step * (i + rng.uniform(-0.2, 0.2));
            const double r = radius - band * rng.uniform(0.0, 0.25);
            sites.push_back({r * std::cos(a), r * std::sin(a), h * rng.uniform(-0.002, 0.002)});
        }
    }
}
} // namespace

std::vector<ConvexPolytope> generateCells(const Aabb& meshBounds, const Impact& impact,
                                          const FractureParams& params, std::uint64_t seed) {
    std::vector<ConvexPolytope> out;
    if (!isFinite(impact.point))
        return out;
    Rng rng(seed);
    const ImpactCut cut = impactCut(params, meshBounds, impact.impulse);
    const double size = cut.size;
    if (!(size > 0) || !std::isfinite(size))
        return out;
    const Mat3 rotation = rng.rotation();

    if (cut.pattern == CellPattern::SingleCell) {
        // The thesis: the impact's Voronoi cell among random sites in a cube centred at the impact.
        const double h = size / 2;
        std::vector<Vec3> sites{{0, 0, 0}};
        const int n = std::clamp(params.seedPoints, 0, 10000);
        for (int i = 0; i < n; ++i)
            sites.push_back(rng.inBox({-h, -h, -h}, {h, h, h}));
        ConvexPolytope p = toPolytope(voronoiCell(sites, 0, h, rotation, 1.0, impact.point));
        if (!p.empty())
            out.push_back(std::move(p));
        return out;
    }

    // Shatter: the K sites nearest the impact cut; where the others lie shapes the cells (ShatterLayout).
    const double scale = rng.uniform(0.8, 1.25);
    const double h = size / 2;
    const int k = std::clamp(params.cells, 1, kMaxShatterCells);
    const int n = std::max(std::clamp(params.seedPoints, 0, 10000), 2 * k);
    std::vector<Vec3> sites{{0, 0, 0}};
    Mat3 frame = rotation;
    switch (params.layout) {
    case ShatterLayout::Clustered: // radius ~ sqrt(u): density ~ 1/r
    case ShatterLayout::Uniform:   // radius ~ cbrt(u): uniform in the ball
        for (int i = 0; i < n; ++i) {
            const double u = rng.uniform();
            const double r = params.layout == ShatterLayout::Clustered ? std::sqrt(u) : std::cbrt(u);
            sites.push_back(rng.unitVector() * (h * 0.98 * r));
        }
        break;
    case ShatterLayout::Radial:
        frame = frameAround(impact.normal, rng.uniform(0.0, 2.0 * std::numbers::pi));
        radialSites(sites, n, h, rng);
        break;
    case ShatterLayout::Splinter: { // clustered cells, stretched along the grain (local z), squeezed across
        frame = frameAround(longestAxis(meshBounds), rng.uniform(0.0, 2.0 * std::numbers::pi));
        for (int c = 0; c < 3; ++c)
            for (int r = 0; r < 3; ++r)
                frame.m[r][c] *= c == 2 ? kSplinterAlong : kSplinterAcross;
        for (int i = 0; i < n; ++i) {
            const double u = rng.uniform();
            sites.push_back(rng.unitVector() * (h * 0.98 * std::sqrt(u)));
        }
        break;
    }
    }
    std::vector<std::size_t> order(sites.size());
    for (std::size_t i = 0; i < order.size(); ++i)
        order[i] = i;
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
        return lengthSquared(sites[a]) < lengthSquared(sites[b]);
    });
    std::vector<std::size_t> wanted(order.begin(),
                                    order.begin() + std::min<std::ptrdiff_t>(k, std::ssize(order)));
    std::vector<RawCell> raws = voronoiComplex(sites, wanted, h, frame, scale, impact.point);
    for (const RawCell& r : raws) {
        ConvexPolytope p = toPolytope(r);
        if (!p.empty())
            out.push_back(std::move(p));
    }
    return out;
}

} // namespace rubble
