#pragma once
/// \file BondGraph.hpp
/// Bonds between touching solids: the interface each pair shares (area, centroid, normal, section moments),
/// computed from their convex parts.

#include <cstdint>
#include <unordered_map>
#include <vector>

#include "rubble/core/Aabb.hpp"
#include "rubble/core/Export.hpp"
#include "rubble/core/Vec3.hpp"
#include "rubble/geometry/ConvexPolytope.hpp"
#include "rubble/structure/StructureSettings.hpp"

namespace rubble {

/// The contact patch two solids share, as a plane section.
struct RUBBLE_API BondInterface {
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
struct RUBBLE_API Bond {
    std::uint32_t a = 0;   ///< first node
    std::uint32_t b = 0;   ///< second node
    BondInterface section; ///< the shared interface, normal from a to b
    /// The node at the other end from node (one of a and b).
    std::uint32_t other(std::uint32_t node) const { return node == a ? b : a; }
};

/// The interface between two solids given as convex parts (same coordinates): the overlap of their
/// coplanar, facing faces. Area 0 when they do not touch.
RUBBLE_API BondInterface bondInterface(const std::vector<ConvexPolytope>& a,
                                       const std::vector<ConvexPolytope>& b, const BondSettings& settings);

/// Bonds between every pair of touching solids, ordered by (a, b).
RUBBLE_API std::vector<Bond> buildBonds(const std::vector<std::vector<ConvexPolytope>>& solids,
                                        const BondSettings& settings);

/// Bonds kept up to date as solids come and go, equal to buildBonds over the solids present: an added solid
/// bonds only to the solids whose bounds overlap its own (a uniform grid over the solids' boxes, kept across
/// calls), a removed one takes only its own bonds. Ids are the solids' indices in buildBonds' terms.
class RUBBLE_API BondGraph {
public:
    /// An empty graph; cellSize (m) is the grid's cell edge.
    explicit BondGraph(BondSettings settings = {}, double cellSize = 1);

    /// Adds solid `id` (not present; parts in world coordinates) and returns its new bonds, ordered by the
    /// other solid; each has a < b and its normal from a to b, as buildBonds.
    std::vector<Bond> add(std::uint32_t id, std::vector<ConvexPolytope> parts);
    /// Removes a solid with its bonds; returns the solids it was bonded to, ascending.
    std::vector<std::uint32_t> remove(std::uint32_t id);
    /// True when the solid is present.
    bool contains(std::uint32_t id) const { return solids_.count(id) > 0; }
    /// Solids present.
    std::size_t size() const { return solids_.size(); }
    /// Bonds present.
    std::size_t bondCount() const { return bonds_.size(); }
    /// Every bond, ordered by (a, b).
    std::vector<Bond> bonds() const;
    /// Solids whose grid cells were searched by the last add (a measure of the broad phase's work).
    std::size_t lastCandidates() const { return lastCandidates_; }

private:
    struct Solid {
        std::vector<ConvexPolytope> parts;
        Aabb box;
        bool large = false;            // in large_, not in the grid
        std::int64_t lo[3]{}, hi[3]{}; // cell range
        std::vector<std::uint32_t> adjacent;
    };
    static std::uint64_t key(std::uint32_t a, std::uint32_t b) { return (std::uint64_t{a} << 32) | b; }
    std::uint64_t cellKey(std::int64_t x, std::int64_t y, std::int64_t z) const;

    BondSettings settings_;
    double cellSize_;
    std::unordered_map<std::uint32_t, Solid> solids_;
    std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> cells_;
    std::vector<std::uint32_t> large_; // solids spanning too many cells: checked against every add
    std::unordered_map<std::uint64_t, BondInterface> bonds_; // key(a, b), a < b
    std::size_t lastCandidates_ = 0;
};

} // namespace rubble
