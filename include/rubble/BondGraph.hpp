#pragma once
/// \file BondGraph.hpp
/// Bonds between touching solids: the interface each pair shares (area, centroid, normal, section moments),
/// computed from their convex parts.

#include <cstdint>
#include <vector>

#include "rubble/ConvexPolytope.hpp"
#include "rubble/Vec3.hpp"

namespace rubble {

/// The contact patch two solids share, as a plane section.
struct BondInterface {
    double area = 0;        ///< m^2, the sum of the contact patches' areas
    double sectionArea = 0; ///< m^2, the patches projected on the plane normal to `normal` (the section that
                            ///< carries load; equal to area for a planar interface)
    Vec3 centroid;          ///< area centroid
    Vec3 normal;            ///< unit, from the first solid to the second: the patches' mean (area-weighted)
    Vec3 u, v;              ///< in-plane unit axes, u x v = normal
    double iuu = 0;         ///< integral of t^2 dA about the centroid (t along v): bending about u
    double ivv = 0;         ///< integral of s^2 dA about the centroid (s along u): bending about v
    double iuv = 0;         ///< integral of s*t dA about the centroid
    std::vector<Vec2> corners; ///< patch corners in (s, t) about the centroid (for the extreme fibres)
};

/// A bond between nodes a < b across their interface.
struct Bond {
    std::uint32_t a = 0;   ///< first node
    std::uint32_t b = 0;   ///< second node
    BondInterface section; ///< the shared interface, normal from a to b
};

/// How touching is decided.
struct BondSettings {
    double gap = 1e-3;         ///< faces at most this far apart (m) count as touching
    double angleTolerance = 1; ///< faces within this angle (degrees) of anti-parallel count as coplanar
    double minArea = 1e-6;     ///< patches below this area (m^2) make no bond
};

/// The interface between two solids given as convex parts (same coordinates): the overlap of their
/// coplanar, facing faces. Area 0 when they do not touch.
BondInterface bondInterface(const std::vector<ConvexPolytope>& a, const std::vector<ConvexPolytope>& b,
                            const BondSettings& settings);

/// Bonds between every pair of touching solids, ordered by (a, b).
std::vector<Bond> buildBonds(const std::vector<std::vector<ConvexPolytope>>& solids,
                             const BondSettings& settings);

} // namespace rubble
