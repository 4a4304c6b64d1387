#pragma once
// Private helper of the collision module: keeps the convex parts of a piece too large for its exact hull
// within a distance of that hull, from its vertices in one pass (docs/collision.md, "Containment").

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "rubble/geometry/ConvexPolytope.hpp"
#include "rubble/geometry/Mesh.hpp"

namespace rubble::detail {

/// The share of kPartHullTolerance that a part's proven reach out of its piece's hull may take (the rest is
/// margin for rounding).
inline constexpr double kHullReachShare = 0.9;

/// Which vertices the mesh's triangles use (1 when used).
std::vector<std::uint8_t> usedVertices(const Mesh& mesh);

/// Witnesses that a point lies near a closed mesh's convex hull, from one pass over the mesh. The vertices
/// go on the rows of three grids, one per axis: each row (a square tube along the axis) keeps its vertices
/// least and greatest along the axis, and a point within reach of the segment between them (which lies in
/// the hull) lies within reach of the hull. Triangles longer than reach put the points where the rows' centre
/// lines cross them on the rows, and a point within reach of one of them is near too.
class HullWitness {
public:
    /// The mesh's referenced vertices, on rows half of reach across.
    HullWitness(const Mesh& mesh, double reach);
    /// True when p provably lies within reach of the mesh's convex hull.
    bool near(const Vec3& p) const;
    /// Which vertices the mesh's triangles use (1 when used).
    const std::vector<std::uint8_t>& used() const { return used_; }

private:
    struct Span { // the row's points least and greatest along its axis: their keys (that coordinate) and ids
        double loKey = std::numeric_limits<double>::infinity();
        double hiKey = -std::numeric_limits<double>::infinity();
        std::uint32_t lo = 0, hi = 0;
        bool set() const { return loKey <= hiKey; }
        void add(double key, std::uint32_t id) {
            if (key < loKey) {
                loKey = key;
                lo = id;
            }
            if (key > hiKey) {
                hiKey = key;
                hi = id;
            }
        }
    };
    // A row point's id: a vertex index, or the mesh's vertex count + an index into crossings_.
    const Vec3& pointOf(std::uint32_t id) const {
        return id < mesh_.positions.size() ? mesh_.positions[id] : crossings_[id - mesh_.positions.size()];
    }
    const Mesh& mesh_;
    double reach_;
    Aabb box_;
    int cells_[3] = {1, 1, 1};
    double cell_[3] = {1, 1, 1};
    std::vector<Span> rows_[3];   // rows_[a]: rows along axis a, indexed by the other two axes' cells
    std::vector<Vec3> crossings_; // points where long triangles cross rows' centre lines
    // Built on the first point that no row proves near (mutable: near() is the only use):
    mutable bool bucketsBuilt_ = false;
    mutable std::vector<std::size_t> large_;         // triangles longer than reach (by bucket once built)
    mutable std::vector<std::uint32_t> bucketStart_; // large_[bucketStart_[k], bucketStart_[k + 1]): bucket k
    mutable Aabb bucketBox_;                         // the buckets' grid: box_ grown by reach_
    mutable int buckets_ = 1;                        // along each axis
    void buildBuckets() const;
    // Puts the points where the centre lines of the rows along axis a cross triangle p0 p1 p2 on those rows.
    void crossRows(int a, const Vec3& p0, const Vec3& p1, const Vec3& p2);
    int bucketOf(int axis, double x) const;
    std::vector<std::uint8_t> used_;
    int cellOf(int axis, double x) const;
};

/// Replaces every part with a corner not proven within reach of the mesh's convex hull (by the hull's own
/// planes when given, else by a HullWitness) by the hull of its proven corners and the mesh's vertices inside
/// it, with at most maxFaces faces (the hull of their extremes when the exact one has more); parts left flat
/// are removed. Returns how many parts were replaced.
std::size_t keepNearHull(std::vector<ConvexPolytope>& parts, const Mesh& mesh, double reach,
                         std::size_t maxFaces, const ConvexPolytope* hull = nullptr);

} // namespace rubble::detail
