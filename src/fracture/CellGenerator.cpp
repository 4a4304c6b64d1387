// Cell generators: the thesis's single randomized Voronoi cell and a Mueller-2013-style shatter pattern.
// Cells are computed with Voro++ in a local frame (an axis-aligned cubic domain around the impact), then
// rotated randomly about the impact. Everything is a pure function of the inputs and the seed.

#include <algorithm>
#include <cmath>
#include <numbers>

#include <voro++/voro++.hh>

#include "rubble/Fracture.hpp"
#include "rubble/Random.hpp"

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

/// Makes vertices that several cells share bit-identical (each cell computes them separately, so they
/// differ in the last bits) so that neighbouring cells neither overlap nor leave gaps.
void weldAcrossCells(std::vector<RawCell>& cells, double tolerance) {
    std::vector<Vec3> canonical;
    for (RawCell& cell : cells)
        for (Vec3& p : cell.vertices) {
            bool found = false;
            for (const Vec3& q : canonical)
                if (std::abs(p.x - q.x) <= tolerance && std::abs(p.y - q.y) <= tolerance &&
                    std::abs(p.z - q.z) <= tolerance) {
                    p = q;
                    found = true;
                    break;
                }
            if (!found)
                canonical.push_back(p);
        }
}

} // namespace

std::vector<ConvexPolytope> generateCells(const Aabb& meshBounds, const Impact& impact,
                                          const FractureParams& params, std::uint64_t seed) {
    (void)meshBounds;
    std::vector<ConvexPolytope> out;
    if (!isFinite(impact.point))
        return out;
    Rng rng(seed);
    const double size = params.sizeLaw.sizeFor(impact.impulse);
    if (!(size > 0) || !std::isfinite(size))
        return out;
    const Mat3 rotation = rng.rotation();

    if (params.pattern == CellPattern::SingleCell) {
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

    // Shatter: sites concentrated at the impact (radius ~ u^2), the K sites nearest the impact cut.
    const double scale = rng.uniform(0.8, 1.25);
    const double h = size / 2;
    const int k = std::clamp(params.cells, 1, 256);
    const int n = std::max(std::clamp(params.seedPoints, 0, 10000), 2 * k);
    std::vector<Vec3> sites{{0, 0, 0}};
    for (int i = 0; i < n; ++i) {
        const double u = rng.uniform();
        sites.push_back(rng.unitVector() * (h * 0.98 * u * u));
    }
    std::vector<std::size_t> order(sites.size());
    for (std::size_t i = 0; i < order.size(); ++i)
        order[i] = i;
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
        return lengthSquared(sites[a]) < lengthSquared(sites[b]);
    });
    std::vector<RawCell> raws;
    for (int i = 0; i < k && i < static_cast<int>(order.size()); ++i) {
        RawCell r = voronoiCell(sites, order[static_cast<std::size_t>(i)], h, rotation, scale, impact.point);
        if (!r.vertices.empty())
            raws.push_back(std::move(r));
    }
    double maxAbs = 0;
    for (int a = 0; a < 3; ++a)
        maxAbs = std::max(maxAbs, std::abs(impact.point[a]));
    weldAcrossCells(raws, std::max(1e-9 * size * scale, 4e-16 * maxAbs));
    for (const RawCell& r : raws) {
        ConvexPolytope p = toPolytope(r);
        if (!p.empty())
            out.push_back(std::move(p));
    }
    return out;
}

} // namespace rubble
