#pragma once
/// \file ConvexPolytope.hpp
/// A convex polytope kept both as planes and as face polygons, clipped by planes.

#include <cstddef>
#include <cstdint>
#include <iterator>
#include <utility>
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

/// Items get(0) … get(n − 1) as a range: a view into a ConvexPolytope (its faces, a face's corners).
template <class Get>
class IndexRange {
public:
    using Ref = decltype(std::declval<const Get&>()(std::size_t{}));
    struct iterator {
        using iterator_category = std::forward_iterator_tag;
        using value_type = std::remove_cvref_t<Ref>;
        using difference_type = std::ptrdiff_t;
        using reference = Ref;
        Get get;
        std::size_t i = 0;
        Ref operator*() const { return get(i); }
        iterator& operator++() { return ++i, *this; }
        bool operator==(const iterator& o) const { return i == o.i; }
    };
    IndexRange(Get get, std::size_t n) : get_(get), n_(n) {}
    iterator begin() const { return {get_, 0}; }
    iterator end() const { return {get_, n_}; }
    std::size_t size() const { return n_; }
    bool empty() const { return n_ == 0; }
    Ref operator[](std::size_t i) const { return get_(i); }
    Ref front() const { return get_(0); }

private:
    Get get_;
    std::size_t n_;
};

/// A face's corners: the polytope keeps each corner once and a face as indices of them.
struct CornerAt {
    const Vec3* points;
    const std::uint32_t* index;
    const Vec3& operator()(std::size_t i) const { return points[index[i]]; }
};
using PolytopeCorners = IndexRange<CornerAt>;

/// A face of a ConvexPolytope as it keeps it: PolytopeFace with its corners viewed in place.
struct RUBBLE_API PolytopeFaceView {
    const Plane& plane;      ///< outward supporting plane (the polytope's own)
    PolytopeCorners corners; ///< counter-clockwise seen from outside
    std::int32_t tag = -1;   ///< caller-defined id of where the face came from
};

class ConvexPolytope;
/// Face i of a polytope.
struct FaceAt {
    const ConvexPolytope* polytope;
    PolytopeFaceView operator()(std::size_t i) const;
};
using PolytopeFaces = IndexRange<FaceAt>;

/// A bounded convex polytope. Value type; clipping returns a new polytope.
class RUBBLE_API ConvexPolytope {
public:
    /// An empty polytope.
    ConvexPolytope() = default;
    /// The polytope of an axis-aligned box.
    static ConvexPolytope fromAabb(const Aabb& box);
    /// The polytope bounded by the given faces (assumed convex and closed); bit-equal corners are shared.
    static ConvexPolytope fromFaces(std::vector<PolytopeFace> faces);

    /// True when the polytope has no volume.
    bool empty() const { return faces_.size() < 4; }
    /// The faces (views into this polytope).
    PolytopeFaces faces() const { return {FaceAt{this}, faces_.size()}; }
    /// The faces as values.
    std::vector<PolytopeFace> faceList() const;
    /// Distinct corner points (welded exactly).
    std::vector<Vec3> vertices() const;
    /// The corners as kept: each once, shared by its faces (in no particular order).
    const std::vector<Vec3>& corners() const { return corners_; }
    /// Heap bytes held.
    std::size_t heapBytes() const;
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
    friend FaceAt;
    struct Face {
        Plane plane;
        std::uint32_t first = 0; // its corners: index_[first, the next face's first)
        std::int32_t tag = -1;
    };
    std::vector<Face> faces_;
    std::vector<Vec3> corners_;        // each corner once (shared by its faces)
    std::vector<std::uint32_t> index_; // the faces' corners, face after face
};

inline PolytopeFaceView FaceAt::operator()(std::size_t i) const {
    const auto& p = *polytope;
    const std::size_t first = p.faces_[i].first,
                      end = i + 1 < p.faces_.size() ? p.faces_[i + 1].first : p.index_.size();
    return {p.faces_[i].plane,
            {CornerAt{p.corners_.data(), p.index_.data() + first}, end - first},
            p.faces_[i].tag};
}

/// True when the two polytopes overlap or are at most `gap` apart along every separating axis (face normals
/// of both, and cross products of their edge directions): convex bodies that touch within a tolerance.
RUBBLE_API bool withinGap(const ConvexPolytope& a, const ConvexPolytope& b, double gap);

} // namespace rubble
