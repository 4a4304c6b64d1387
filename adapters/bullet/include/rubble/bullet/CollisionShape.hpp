#pragma once
/// \file CollisionShape.hpp
/// A Bullet compound of convex hulls built from Rubble's convex parts, owning every child shape, with the
/// edges of its parts kept for debug drawing.

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include <btBulletCollisionCommon.h>

#include "rubble/geometry/ConvexPolytope.hpp"
#include "rubble/runtime/DestructionWorld.hpp"

namespace rubble::bullet {

/// Owns a btCompoundShape and its children (a single hull is used without the compound). Child hulls are
/// given in the body's frame (centre of mass, principal axes). Each hull is eroded by its collision margin,
/// so that hull + margin matches the part and neighbouring pieces do not start out overlapping.
class CollisionShape {
public:
    /// Compound of the convex parts (object coordinates); objectToBody maps body → object coordinates
    /// (p_object = rotation · p_body + translation). When parts is empty (or no part is usable) the convex
    /// hull of fallbackPoints (object coordinates, reduced to at most 42 points) is used; returns null when
    /// nothing usable remains. maxHullPoints > 0 caps each part's hull (cappedHullPoints).
    static std::unique_ptr<CollisionShape> fromParts(const std::vector<ConvexPolytope>& parts,
                                                     const std::vector<Vec3>& fallbackPoints,
                                                     const Frame& objectToBody, double margin,
                                                     int maxHullPoints = 0);
    /// At most maxPoints of the points (all when fewer, or maxPoints < 4), chosen so that the support of
    /// their hull stays closest to that of all the points: a subset, so the capped hull lies inside the full
    /// one.
    static std::vector<Vec3> cappedHullPoints(const std::vector<Vec3>& points, int maxPoints);
    /// The distinct corners of the part shrunk by margin along every face plane, sorted; empty when nothing
    /// is left.
    static std::vector<Vec3> coreCorners(const ConvexPolytope& part, double margin);
    /// A box of the given half extents centred on the body's origin.
    static std::unique_ptr<CollisionShape> box(const Vec3& halfExtents);
    /// A sphere of the given radius centred on the body's origin.
    static std::unique_ptr<CollisionShape> sphere(double radius);

    ~CollisionShape();
    CollisionShape(const CollisionShape&) = delete;
    CollisionShape& operator=(const CollisionShape&) = delete;

    /// The shape to give a btRigidBody.
    btCollisionShape* shape() const { return root_; }
    /// Number of convex hulls (0 for a plain box or sphere).
    int childCount() const;
    /// Edges of the parts in body coordinates (for debug drawing; kept in float).
    std::vector<std::array<Vec3, 2>> edges() const;
    /// Number of edges.
    std::size_t edgeCount() const { return edgeIndex_.size(); }

    /// Heap bytes held: the Bullet shapes (hull points included), the debug edges, and the hull points.
    struct Bytes {
        std::size_t shapes = 0; ///< Bullet shapes, their point arrays and the compound's tree
        std::size_t edges = 0;  ///< the debug edges
        std::size_t points = 0; ///< hull points (a count, not bytes)
    };
    /// What this shape holds on the heap.
    Bytes bytes() const;

private:
    CollisionShape() = default;
    btCollisionShape* root_ = nullptr;
    std::unique_ptr<btCompoundShape> compound_;
    std::vector<std::unique_ptr<btCollisionShape>> children_;
    void addEdge(const Vec3& a, const Vec3& b);
    std::vector<Vec3f> edgePoints_; // corners of the edges (a part's shared by its edges), in float
    std::vector<std::array<std::uint32_t, 2>> edgeIndex_; // edges as pairs of edgePoints_
};

} // namespace rubble::bullet
