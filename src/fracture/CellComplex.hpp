#pragma once
// The first stage of the fast clipper: convex cells welded into one complex (shared vertices, and the faces
// two cells share stored once), checked to have disjoint interiors.

#include "rubble/core/Result.hpp"
#include "rubble/geometry/ConvexPolytope.hpp"

#include <cstdint>
#include <unordered_map>
#include <vector>

namespace rubble::detail {

/// An ordered pair of 32-bit ids as one key.
inline std::uint64_t pairKey(std::uint32_t a, std::uint32_t b) {
    return (std::uint64_t(a) << 32) | b;
}

/// The cells as one complex: welded vertices, and faces shared by two cells stored once. A face's plane is
/// outward for its `back` cell; `front` is the cell on the other side, or the outside region (index K).
struct CellComplex {
    struct Face {
        std::vector<std::uint32_t> loop; // counter-clockwise seen from the back cell's outside
        Plane plane;
        std::uint32_t back = 0, front = 0;
    };
    struct Cell {
        std::vector<std::uint32_t> faces; // complex faces
        std::vector<bool> flipped;        // true where the cell is the face's front
        std::unordered_map<std::uint64_t, std::uint64_t> edgeOfFaces; // face pair (f<g) -> complex edge (a<b)
        Aabb box;
    };
    std::vector<Vec3> vertices;
    std::vector<Face> faces;
    std::vector<Cell> cells;
};

/// The error of a fast clip that leaves a configuration to an exact backend: GeometryFailure, "fast clip
/// declined: " and why.
Error clipDeclined(const char* why);

/// The cells (non-empty, convex) as a complex; eps is the overlap tolerance between cells. GeometryFailure
/// ("fast clip declined: ...") when a cell is not closed or has fewer than 4 faces, cells overlap, or their
/// union's boundary does not close up: configurations the fast clipper leaves to an exact backend.
Result<CellComplex> buildCellComplex(const std::vector<ConvexPolytope>& cells, double eps);

} // namespace rubble::detail
