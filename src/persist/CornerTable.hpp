#pragma once
// Private to the persist module: a mesh's distinct corners, each once (snapshot version 6, docs/journal.md).

#include <cstdint>
#include <string>
#include <vector>

#include "rubble/geometry/Mesh.hpp"

namespace rubble::persist {

/// A mesh's distinct corners in first-use order, and its triangles' corners as codes (corners used so far −
/// k).
struct CornerTable {
    std::vector<std::uint32_t> vertex; ///< each corner's vertex
    std::vector<Vec3f> normals;        ///< each corner's normal (empty when the mesh has none)
    std::vector<Vec2f> uvs;            ///< each corner's texture coordinates (empty when the mesh has none)
    std::vector<std::uint32_t> codes;  ///< three per triangle
};

/// The table of m with its normals and uvs where asked (each then one per triangle corner).
CornerTable cornerTable(const Mesh& m, bool normals, bool uvs);

/// The first bad code or corner of a table and why (empty `what`: none).
struct CornerError {
    std::size_t index = 0;
    std::string what;
};

/// The first corner whose vertex is not below vertexCount.
CornerError checkCornerVertices(const CornerTable& t, std::size_t vertexCount);

/// Sets m's triangles and attributes from a table only cornerTable could have made, else fails
/// (docs/journal.md).
CornerError expandCorners(const CornerTable& t, std::size_t vertexCount, Mesh& m);

} // namespace rubble::persist
