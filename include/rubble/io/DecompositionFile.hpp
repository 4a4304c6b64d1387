#pragma once
/// \file DecompositionFile.hpp
/// A convex decomposition cached beside its asset as JSON (`rubble decompose MESH -o MESH.parts.json`), so
/// that a level never decomposes at load.

#include <cstdint>
#include <filesystem>
#include <vector>

#include "rubble/core/Export.hpp"
#include "rubble/core/Result.hpp"
#include "rubble/geometry/ConvexPolytope.hpp"

namespace rubble {

/// The contents of a decomposition file: the parts and the mesh they were made for.
struct RUBBLE_API DecompositionFile {
    std::uint64_t meshHash = 0;        ///< Mesh::hash() of the mesh as read (version 1: its former hash)
    double meshVolume = 0;             ///< volume of that mesh
    std::vector<ConvexPolytope> parts; ///< convex parts in the mesh's coordinates
};

/// The file beside a mesh asset: "arch.obj" -> "arch.parts.json".
RUBBLE_API std::filesystem::path decompositionPathFor(const std::filesystem::path& meshPath);

/// Writes {"format": "rubble-decomposition", "version": 2, "mesh_hash", "mesh_volume", "parts": [{"faces":
/// [{"normal", "offset", "corners"}]}]} with shortest round-trip numbers, atomically (staging file + rename).
RUBBLE_API Status writeDecompositionFile(const std::filesystem::path& path, const DecompositionFile& file);

/// Reads a file written by writeDecompositionFile. ParseError naming the file and the field (or the byte
/// offset of a JSON syntax error) when it is malformed; IoError when it cannot be read.
RUBBLE_API Result<DecompositionFile> readDecompositionFile(const std::filesystem::path& path);

} // namespace rubble
