#pragma once
// Private helpers of the io module: the Assimp half of readScene.

#include <filesystem>

#include "rubble/core/Result.hpp"
#include "rubble/io/SceneIO.hpp"

namespace rubble::io {

/// A glTF or GLB file as a scene (see readScene), after the same size and depth checks as readMesh.
Result<AssetScene> readGltfScene(const std::filesystem::path& path);

} // namespace rubble::io
