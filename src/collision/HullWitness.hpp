#pragma once
// Private helper of the collision module: keeps the convex parts of a piece too large for its exact hull
// within a distance of that hull, from its vertices in one pass (docs/collision.md, "Containment").

#include <cstddef>
#include <cstdint>
#include <vector>

#include "rubble/geometry/ConvexPolytope.hpp"
#include "rubble/geometry/Mesh.hpp"

namespace rubble::detail {

/// The share of kPartHullTolerance that a part's proven reach out of its piece's hull may take (the rest is
/// margin for rounding).
inline constexpr double kHullReachShare = 0.9;

/// Which vertices the mesh's triangles use.
std::vector<bool> usedVertices(const Mesh& mesh);

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
    /// Which vertices the mesh's triangles use.
    const std::vector<bool>& used() const { return used_; }

private:
    struct Span {
        Vec3 lo, hi; // the row's points least and greatest along its axis
        bool set = false;
        void add(const Vec3& p, int axis) {
            if (!set || p[axis] < lo[axis])
                lo = p;
            if (!set || p[axis] > hi[axis])
                hi = p;
            set = true;
        }
    };
    const Mesh& mesh_;
    double reach_;
    Aabb box_;
    int cells_[3] = {1, 1, 1};
    double cell_[3] = {1, 1, 1};
    std::vector<Span> rows_[3]; // rows_[a]: rows along axis a, indexed by the other two axes' cells
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
    std::vector<bool> used_;
    int cellOf(int axis, double x) const;
};

/// Replaces every part with a corner not proven within reach of the mesh's convex hull (by the hull's own
/// planes when given, else by a HullWitness) by the hull of its proven corners and the mesh's vertices inside
/// it, with at most maxFaces faces (the hull of their extremes when the exact one has more); parts left flat
/// are removed. Returns how many parts were replaced.
std::size_t keepNearHull(std::vector<ConvexPolytope>& parts, const Mesh& mesh, double reach,
                         std::size_t maxFaces, const ConvexPolytope* hull = nullptr);

} // namespace rubble::detail
