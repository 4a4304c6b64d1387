#pragma once
// Private to the core: constrained Delaunay triangulation of a planar region given by its boundary edges,
// with inside and outside found topologically. Used for the caps of the convex-cell clipper and for the
// patches of simplifyPlanarRegions.

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "rubble/core/Vec3.hpp"

namespace rubble::detail {

/// An orthonormal basis (u, v) of the plane with unit normal n such that u × v = n.
void planeBasis(const Vec3& n, Vec3& u, Vec3& v);

/// A boundary edge of a planar region between two point ids, and what crossing it toggles (a bit mask: the
/// region's outline toggles 1, a hole's outline 2). Toggles of edges with the same two ends cancel out.
struct RegionEdge {
    std::uint32_t a = 0; ///< one end
    std::uint32_t b = 0; ///< the other end
    unsigned toggle = 1; ///< bits flipped when a walk crosses it
};

/// Triangulates the region bounded by edges in the plane with normal `normal` (points from `position`,
/// projected): the constrained Delaunay triangles whose state — the XOR of the toggles crossed on a walk from
/// the unbounded face — is exactly 1, counter-clockwise seen along the normal. Points are inserted in order
/// of first appearance in edges, so the result is deterministic. Returns null, or why it failed (coincident
/// points, crossing edges, a boundary that does not close, a flat triangle); `out` is then unspecified.
const char* triangulatePlanarRegion(const std::vector<RegionEdge>& edges, const Vec3& normal,
                                    const std::function<Vec3(std::uint32_t)>& position,
                                    std::vector<std::array<std::uint32_t, 3>>& out);

} // namespace rubble::detail
