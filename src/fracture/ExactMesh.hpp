#pragma once
// Private to the fracture module: what the exact CGAL backends (Corefine and Nef) share — the kernel, the
// surface mesh type, deterministic rounding, and conversions between rubble::Mesh / ConvexPolytope and
// CGAL::Surface_mesh.

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>

#include "rubble/geometry/ConvexPolytope.hpp"
#include "rubble/geometry/Mesh.hpp"

namespace rubble::detail::exact {

using K = CGAL::Exact_predicates_exact_constructions_kernel;
using SM = CGAL::Surface_mesh<K::Point_3>;

/// A backend's internal failure; caught at the backend's boundary and returned as an Error.
struct Failure {
    std::string why; ///< what went wrong
};

/// A deterministic double for a lazy exact number: the approximation when it is a single double (e.g. an
/// input coordinate), else the rounded exact value. CGAL::to_double of the interval is not deterministic:
/// it depends on whether earlier predicates happened to refine the interval.
double toDouble(const K::FT& x);

/// Adds a mesh's vertices and triangles to sm (vertex i becomes SM::Vertex_index(i) when sm was empty);
/// onFace(t, f) for every triangle. Throws Failure when a triangle cannot be added (not a manifold surface).
void addMesh(const Mesh& mesh, SM& sm, const std::function<void(std::size_t, SM::Face_index)>& onFace = {});

/// Adds a convex cell as a closed triangle mesh: corners welded exactly, each face fanned from its
/// lexicographically smallest corner (so a face shared by two cells is triangulated identically in both);
/// onFace(f) for every triangle. Throws Failure when the cell does not close up.
void addCell(const ConvexPolytope& cell, SM& sm, const std::function<void(SM::Face_index)>& onFace = {});

/// The triangles of sm, rounded with toDouble; vertices numbered in order of first use. onFace(f) for every
/// triangle, in output order. Throws Failure on a face that is not a triangle.
void toTriangles(const SM& sm, std::vector<Vec3>& positions, std::vector<Triangle>& triangles,
                 const std::function<void(SM::Face_index)>& onFace = {});

} // namespace rubble::detail::exact
