#include "collision/MeshRegion.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "rubble/ConvexDecomposition.hpp"

namespace rubble::detail {

void splitPolygon(const Polygon& poly, const Plane& plane, Polygon& inside, Polygon& outside) {
    inside.clear();
    outside.clear();
    const std::size_t n = poly.size();
    double dist[64];
    std::vector<double> big;
    double* d = dist;
    if (n > 64) {
        big.resize(n);
        d = big.data();
    }
    bool anyIn = false, anyOut = false;
    for (std::size_t i = 0; i < n; ++i) {
        d[i] = plane.signedDistance(poly[i]);
        anyIn |= d[i] < 0;
        anyOut |= d[i] > 0;
    }
    if (!anyOut) {
        inside = poly;
        return;
    }
    if (!anyIn) {
        outside = poly;
        return;
    }
    for (std::size_t i = 0; i < n; ++i) {
        const std::size_t j = (i + 1) % n;
        if (d[i] <= 0)
            inside.push_back(poly[i]);
        if (d[i] >= 0)
            outside.push_back(poly[i]);
        if ((d[i] < 0 && d[j] > 0) || (d[i] > 0 && d[j] < 0)) {
            const double t = d[i] / (d[i] - d[j]);
            const Vec3 x = poly[i] + (poly[j] - poly[i]) * t;
            inside.push_back(x);
            outside.push_back(x);
        }
    }
}

std::vector<Polygon> clipTrianglesToRegion(const Mesh& mesh, const ConvexPolytope& region) {
    std::vector<Polygon> out;
    const Aabb rb = region.bounds();
    Polygon in, outside;
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
        const auto c = mesh.corners(t);
        Aabb tb;
        tb.extend(c[0]);
        tb.extend(c[1]);
        tb.extend(c[2]);
        if (!tb.overlaps(rb))
            continue;
        Polygon poly{c[0], c[1], c[2]};
        for (const PolytopeFace& f : region.faces()) {
            splitPolygon(poly, f.plane, in, outside);
            poly.swap(in);
            if (poly.size() < 3)
                break;
        }
        if (poly.size() >= 3)
            out.push_back(std::move(poly));
    }
    return out;
}

Result<ConvexPolytope> hullOfPolygons(const std::vector<Polygon>& polys, const std::vector<Vec3>& extra) {
    std::vector<Vec3> pts = extra;
    for (const Polygon& p : polys)
        pts.insert(pts.end(), p.begin(), p.end());
    std::sort(pts.begin(), pts.end(),
              [](const Vec3& a, const Vec3& b) { return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z); });
    pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
    return convexHull(pts);
}

Result<ConvexPolytope> hullOfMeshInRegion(const Mesh& mesh, const ConvexPolytope& region) {
    const std::vector<Polygon> polys = clipTrianglesToRegion(mesh, region);
    std::vector<Vec3> extra;
    for (const Vec3& v : region.vertices())
        if (insideMesh(mesh, v))
            extra.push_back(v);
    return hullOfPolygons(polys, extra);
}

} // namespace rubble::detail
