#pragma once
// Private to the persist module (and its tests): a mesh's per-corner attributes with each distinct corner
// kept once (snapshot version 6).

#include <cstdint>
#include <string>
#include <vector>

#include "rubble/geometry/Mesh.hpp"

namespace rubble::persist {

/// The distinct corners of a mesh (a vertex with its normal and texture coordinates, compared bit for bit) in
/// the order the triangles first use them, and the triangles' corners as codes: (the largest corner used
/// before, plus one) minus the corner, so that a corner used for the first time is 0.
struct CornerTable {
    std::vector<std::uint32_t> vertex; ///< each corner's vertex
    std::vector<Vec3f> normals;        ///< each corner's normal (empty when the mesh has none)
    std::vector<Vec2f> uvs;            ///< each corner's texture coordinates (empty when the mesh has none)
    std::vector<std::uint32_t> codes;  ///< three per triangle
};

/// The table of m with its normals and uvs where asked (each then one per triangle corner).
CornerTable cornerTable(const Mesh& m, bool normals, bool uvs);

/// What is wrong with a table: the index of the first bad code (or corner) and why; empty `what` when
/// nothing.
struct CornerError {
    std::size_t index = 0;
    std::string what;
};

/// The first corner whose vertex is not below vertexCount.
CornerError checkCornerVertices(const CornerTable& t, std::size_t vertexCount);

/// Sets m's triangles, normals and uvs from t, whose corners' vertices are below vertexCount (checked).
/// Fails, leaving m's triangles and attributes unspecified, at the first code that names no corner or makes a
/// corner equal to one before it, or (index: the code count) when a corner is never used: the tables
/// cornerTable makes are the only ones accepted, so a table read and written again gives the same bytes.
CornerError expandCorners(const CornerTable& t, std::size_t vertexCount, Mesh& m);

} // namespace rubble::persist
