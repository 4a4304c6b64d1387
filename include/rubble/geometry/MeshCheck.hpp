#pragma once
/// \file MeshCheck.hpp
/// Checks whether a triangle mesh is a valid solid: closed, manifold, consistently and outward oriented,
/// free of degenerate triangles, non-finite coordinates and self-intersections.

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "rubble/core/Aabb.hpp"
#include "rubble/core/Export.hpp"
#include "rubble/core/Vec3.hpp"
#include "rubble/geometry/Mesh.hpp"

namespace rubble {

/// Largest coordinate magnitude of a valid mesh (1e50): the volume integrals (up to fifth powers of
/// coordinates, for the inertia) then stay finite; beyond about 1e61 they overflow.
inline constexpr double kMaxCoordinate = 1e50;

/// What checkMesh examines.
struct RUBBLE_API CheckOptions {
    /// Run the (CGAL) self-intersection test. It only runs on meshes that are valid polygon meshes
    /// (manifold, in-range indices, finite coordinates, no degenerate triangles).
    bool selfIntersections = true;
    /// Stop counting self-intersecting triangle pairs after this many (the count is then a lower bound).
    std::size_t maxSelfIntersections = 100000;
    /// How many individual problems (e.g. one line per open edge) to list before summarising.
    std::size_t maxListedPerKind = 3;
};

/// The verdict of checkMesh: counts, topology flags, geometry and a list of human-readable problems.
struct RUBBLE_API MeshReport {
    std::size_t vertices = 0;  ///< number of vertices
    std::size_t triangles = 0; ///< number of triangles

    bool closed = false;       ///< every edge has exactly two incident triangles
    bool edgeManifold = false; ///< no edge has more than two incident triangles
    /// Every vertex's triangles form one fan (no two solids touching at a single vertex); only examined when
    /// the mesh is edge-manifold and its indices are in range.
    bool vertexManifold = false;
    bool oriented = false; ///< every edge shared by two triangles is used once in each direction
    bool outward = false;  ///< total signed volume is positive

    std::size_t boundaryEdges = 0;       ///< edges with exactly one incident triangle (holes)
    std::size_t nonManifoldEdges = 0;    ///< edges with three or more incident triangles
    std::size_t nonManifoldVertices = 0; ///< vertices whose triangles form two or more separate fans
    std::size_t misorientedEdges = 0;    ///< edges used twice in the same direction
    std::size_t degenerateTriangles = 0; ///< triangles with a repeated index or zero area
    std::size_t duplicateTriangles = 0;  ///< triangles with the same three vertices as an earlier one
    std::size_t nonFiniteVertices = 0;   ///< vertices with a NaN or infinite coordinate
    std::size_t hugeVertices = 0;        ///< vertices with a coordinate beyond ±kMaxCoordinate
    std::size_t badIndices = 0;          ///< triangle corners referring to a vertex that does not exist
    std::size_t shells = 0;              ///< edge-connected components of triangles
    /// Shells facing the wrong way for their nesting: one inside an odd number of others must face inward
    /// (a cavity), any other outward. Examined on closed, oriented, manifold meshes.
    std::size_t misnestedShells = 0;
    std::size_t badAttributeArrays = 0; ///< normals/uvs/materials present with the wrong number of entries

    /// True when the self-intersection test ran (see CheckOptions::selfIntersections).
    bool selfIntersectionsChecked = false;
    /// Number of intersecting pairs of non-adjacent triangles (a lower bound when capped); 0 when not
    /// checked.
    std::size_t selfIntersections = 0;
    /// True when the count reached CheckOptions::maxSelfIntersections.
    bool selfIntersectionsCapped = false;
    /// Why the self-intersection test did not run or failed (empty when it ran).
    std::string selfIntersectionNote;

    double volume = 0; ///< signed volume (meaningful for closed meshes)
    Vec3 centerOfMass; ///< centre of mass for uniform density (meaningful for closed meshes)
    Aabb bounds;       ///< bounding box of all vertices

    /// Human-readable problems, one sentence each, most important first; empty for a valid mesh.
    std::vector<std::string> problems;

    /// True when both edges and vertices are manifold.
    bool manifold() const { return edgeManifold && vertexManifold; }

    /// True when the mesh is a valid solid: non-empty, closed, manifold, oriented outward (every shell as its
    /// nesting requires), finite and within ±kMaxCoordinate, with attribute arrays of the right sizes,
    /// without degenerate triangles and (when checked) without self-intersections.
    bool valid() const;
};

/// Examines a mesh and reports what is wrong with it. Never fails and never throws: any exception from the
/// geometric kernel is caught and recorded in selfIntersectionNote.
RUBBLE_API MeshReport checkMesh(const Mesh& mesh, const CheckOptions& options = {});

/// Ok when every coordinate is within ±kMaxCoordinate; otherwise an InvalidInput error naming the first
/// vertex beyond it and the bound ("what: vertex 3 has a coordinate of 1e+100, beyond ±1e+50 ...").
RUBBLE_API Status checkCoordinateRange(const Mesh& mesh, const std::string& what);

/// True when the triangle abc has (numerically) zero area: its doubled area is below 1e-12 times the square
/// of its longest edge.
RUBBLE_API bool isDegenerateTriangle(const Vec3& a, const Vec3& b, const Vec3& c);

/// Result of the self-intersection test alone.
struct RUBBLE_API SelfIntersectionResult {
    bool ran = false;      ///< false when the mesh is not a valid polygon mesh or the kernel failed
    std::size_t pairs = 0; ///< intersecting pairs of non-adjacent triangles found (up to the cap)
    bool capped = false;   ///< the search stopped at the cap
    std::string note;      ///< why the test did not run, or what the kernel reported
    std::vector<std::pair<std::size_t, std::size_t>> examples; ///< up to a few intersecting triangle pairs
};

/// Finds pairs of intersecting triangles (CGAL Polygon_mesh_processing::self_intersections on a Surface_mesh
/// built from the triangles). Requires a polygon mesh (manifold, finite, no degenerate triangles); returns
/// ran = false with a note otherwise. Never throws.
RUBBLE_API SelfIntersectionResult findSelfIntersections(const Mesh& mesh, std::size_t maxPairs = 100000);

} // namespace rubble
