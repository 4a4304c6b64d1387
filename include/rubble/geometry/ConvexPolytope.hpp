#pragma once
/// \file ConvexPolytope.hpp
/// A convex polytope kept both as planes and as face polygons, clipped by planes.

#include <cstdint>
#include <vector>

#include "rubble/core/Aabb.hpp"
#include "rubble/core/Export.hpp"
#include "rubble/core/Frame.hpp"
#include "rubble/geometry/Mesh.hpp"
#include "rubble/geometry/Plane.hpp"

namespace rubble {

/// One planar convex face: its outward plane, its corners counter-clockwise seen from outside, and a tag
/// (e.g. the id of the cutting plane that created it; -1 for faces of the original shape).
struct RUBBLE_API PolytopeFace {
    Plane plane;               ///< outward supporting plane
    std::vector<Vec3> corners; ///< counter-clockwise seen from outside
    std::int32_t tag = -1;     ///< caller-defined id of where the face came from
};

/// A bounded convex polytope. Value type; clipping returns a new polytope.
class RUBBLE_API ConvexPolytope {
public:
    /// An empty polytope.
    ConvexPolytope() = default;
    /// The polytope of an axis-aligned box.
    static ConvexPolytope fromAabb(const Aabb& box);
    /// The polytope bounded by the given faces (assumed convex and closed).
    static ConvexPolytope fromFaces(std::vector<PolytopeFace> faces);

    /// True when the polytope has no volume.
    bool empty() const { return faces_.size() < 4; }
    /// The faces.
    const std::vector<PolytopeFace>& faces() const { return faces_; }
    /// Distinct corner points (welded exactly).
    std::vector<Vec3> vertices() const;
    /// Bounding box.
    Aabb bounds() const;
    /// Volume.
    double volume() const;
    /// Centroid of the solid.
    Vec3 centroid() const;
    /// True when p is inside or within eps of every face plane.
    bool contains(const Vec3& p, double eps = 0) const;

    /// The part on the inner (negative) side of plane; the new face gets the given tag.
    /// Points within eps of the plane count as on it. The result may be empty.
    ConvexPolytope clipped(const Plane& plane, std::int32_t tag = -1, double eps = 1e-12) const;
    /// The part on the outer (positive) side of plane.
    ConvexPolytope clippedOutside(const Plane& plane, std::int32_t tag = -1, double eps = 1e-12) const {
        return clipped(plane.flipped(), tag, eps);
    }

    /// The polytope moved rigidly by f (each point p becomes f.apply(p)).
    ConvexPolytope transformed(const Frame& f) const;

    /// Closed triangle mesh of the boundary (faces fanned; material = face tag cast to unsigned when tagged).
    Mesh toMesh() const;

private:
    std::vector<PolytopeFace> faces_;
};

/// True when the two polytopes overlap or are at most `gap` apart along every separating axis (face normals
/// of both, and cross products of their edge directions): convex bodies that touch within a tolerance.
RUBBLE_API bool withinGap(const ConvexPolytope& a, const ConvexPolytope& b, double gap);

} // namespace rubble
