#pragma once
// Private helpers of the collision module: polygon clipping, point-in-mesh, and the convex hull of the part
// of a closed mesh inside a convex region.

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "rubble/core/Result.hpp"
#include "rubble/geometry/ConvexPolytope.hpp"
#include "rubble/geometry/Mesh.hpp"

namespace rubble::detail {

/// A planar convex polygon (a clipped mesh triangle).
using Polygon = std::vector<Vec3>;

/// Splits a convex polygon by a plane into its inner (signed distance <= 0) and outer parts; either may come
/// out with fewer than 3 corners (nothing on that side).
void splitPolygon(const Polygon& poly, const Plane& plane, Polygon& inside, Polygon& outside);

/// True when p lies inside the closed mesh (winding number above 1/2).
inline bool insideMesh(const Mesh& mesh, const Vec3& p) {
    return rubble::windingNumber(mesh, p) > 0.5;
}

/// The mesh's triangles clipped to a convex region (triangles whose bounds miss the region are skipped).
std::vector<Polygon> clipTrianglesToRegion(const Mesh& mesh, const ConvexPolytope& region);

/// The hull of (solid of mesh) ∩ region: hull of the clipped surface polygons' corners and the region's
/// corners that lie inside the mesh. Fails when that set is empty or flat.
Result<ConvexPolytope> hullOfMeshInRegion(const Mesh& mesh, const ConvexPolytope& region);

/// A bounded stand-in for a closed mesh: its vertices clustered on a grid of cellsPerAxis cells along each
/// axis of its bounding box (each cluster at its vertices' mean), triangles that collapse dropped and
/// pairs of opposite triangles cancelled. Closed (every edge used as often in both directions) but not
/// necessarily manifold; its winding number follows the mesh's away from the surface.
Mesh clusteredProxy(const Mesh& mesh, int cellsPerAxis);

/// The k-th of n directions spread evenly over the unit sphere (a Fibonacci lattice).
inline Vec3 sphereDirection(std::size_t k, std::size_t n) {
    const double z = 1 - (2 * static_cast<double>(k) + 1) / static_cast<double>(n);
    const double r = std::sqrt(std::max(0.0, 1 - z * z));
    const double phi = static_cast<double>(k) * std::numbers::pi * (3 - std::sqrt(5.0));
    return {r * std::cos(phi), r * std::sin(phi), z};
}

/// Most hull planes that keepInsideHull clips one part by.
constexpr std::size_t kMaxHullClips = 256;

/// Clips every part by the planes of hull that it reaches farthest out of, until it reaches at most margin
/// outside hull (or after kMaxHullClips planes); parts left empty are removed.
void keepInsideHull(std::vector<ConvexPolytope>& parts, const ConvexPolytope& hull, double margin);

/// The volume of the points' convex hull, computed by Qhull without building a polytope; 0 for fewer than 4,
/// non-finite or flat points.
double hullVolume(const std::vector<Vec3>& points);

/// Hull of polygons' corners plus extra points.
Result<ConvexPolytope> hullOfPolygons(const std::vector<Polygon>& polys, const std::vector<Vec3>& extra);

} // namespace rubble::detail
