#pragma once
/// \file Islands.hpp
/// Splitting a mesh into its connected solid parts.

#include <cstdint>
#include <vector>

#include "rubble/geometry/Mesh.hpp"

namespace rubble {

/// Labels each triangle with the id of its edge-connected shell; returns the number of shells.
std::size_t labelShells(const Mesh& mesh, std::vector<std::uint32_t>& triangleShell);

/// Splits a mesh into solid islands. Triangles that share an edge (by vertex index) are one shell; an
/// inward-facing shell (a cavity) joins the smallest outward shell that contains it. Attributes are kept,
/// unreferenced vertices dropped. Islands come out in a deterministic order (by lowest triangle index).
std::vector<Mesh> splitIntoIslands(const Mesh& mesh);

/// As splitIntoIslands(const Mesh&), but a mesh that is one island is moved into the result, not copied.
std::vector<Mesh> splitIntoIslands(Mesh&& mesh);

/// As splitIntoIslands(Mesh&&) with the shell labels already known (triangleShell and shells as returned by
/// labelShells for this mesh).
std::vector<Mesh> splitIntoIslands(Mesh&& mesh, const std::vector<std::uint32_t>& triangleShell,
                                   std::size_t shells);

} // namespace rubble
