#pragma once
/// \file SceneIO.hpp
/// Reading multi-object files as scenes: each object with its collision parts and the materials it uses,
/// so that pre-fractured assets (glTF node trees, OBJ objects with UCX_ parts) can be read back piece by
/// piece.

#include <filesystem>
#include <string>
#include <vector>

#include "rubble/core/Export.hpp"
#include "rubble/core/Result.hpp"
#include "rubble/geometry/Mesh.hpp"

namespace rubble {

/// One texture map of a material: an image file, or the bytes of an image embedded in the source file.
struct RUBBLE_API TextureMap {
    std::string slot;    ///< MTL statement ("map_Kd", "map_Bump", "norm", ...); glTF base colour is "map_Kd"
    std::string options; ///< MTL options before the file name ("-s 2 2 1"), kept verbatim
    std::filesystem::path
        file;              ///< the image, absolute or relative to the working directory; empty when embedded
    std::string bytes;     ///< embedded image bytes (glTF data URI or GLB buffer) when file is empty
    std::string extension; ///< extension of an embedded image (".png", ".jpg")
};

/// A material as read from a file, for writers to carry over (MTL `newmtl` blocks, glTF materials).
struct RUBBLE_API AssetMaterial {
    std::string name;                    ///< the name meshes refer to in Mesh::materialNames
    Vec3 baseColor{0.8, 0.8, 0.8};       ///< MTL Kd, glTF baseColorFactor
    std::vector<TextureMap> maps;        ///< texture maps; "map_Kd" is the base colour texture
    std::vector<std::string> statements; ///< other MTL statements ("Ns 10", "illum 2"), kept verbatim
};

/// One object of a scene in scene coordinates, with the convex collision parts that belong to it.
struct RUBBLE_API AssetObject {
    std::string name;            ///< node or object name ("" when the file has none)
    Mesh mesh;                   ///< render mesh (faces in material "interior" have kInteriorMaterial)
    std::vector<Mesh> collision; ///< collision parts: glTF child nodes named "*-convcolonly"/"*-colonly",
                                 ///< OBJ objects named "UCX_<name>_<n>"
    int parent = -1;             ///< index of the enclosing object in a node tree (-1: top level)
};

/// A file read as separate objects.
struct RUBBLE_API AssetScene {
    std::vector<AssetObject> objects;     ///< in file order (glTF: depth-first node order)
    std::vector<AssetMaterial> materials; ///< the materials the objects name (OBJ: from its mtllib files)
    std::vector<std::string> warnings;    ///< what was skipped (a missing .mtl or image), naming the file
};

/// True when a node or object name marks a collision-only shape: a Godot suffix ("-colonly", "-convcolonly")
/// or Unreal's "UCX_" prefix.
RUBBLE_API bool isCollisionName(const std::string& name);

/// Reads a file as a scene. glTF/GLB: one object per node that has a mesh (node transforms applied, so
/// positions are in scene coordinates), collision nodes attached to their nearest non-collision ancestor,
/// materials with base colour and base colour texture (image files resolved against the file's folder,
/// embedded images as bytes). OBJ: one object per `o` (see parseObjObjects; without any `o`, the whole file
/// is one object, since `g` groups usually split one solid), "UCX_<name>_<n>" objects attached to object
/// <name>, materials from the `mtllib` files with map paths resolved against the .obj's folder. Other
/// formats: one object named after the file stem (readMesh). Errors as readMesh; a missing or malformed .mtl
/// and a missing image are warnings, not errors. An image named by an absolute path is dropped with a
/// warning, so that writers never copy files from anywhere on the machine (relative paths, "../textures/",
/// are the model's layout).
RUBBLE_API Result<AssetScene> readScene(const std::filesystem::path& path);

/// Parses MTL text into materials; map file names are resolved against folder. Unknown statements are kept
/// in AssetMaterial::statements. Errors (ParseError) name displayName and the line.
RUBBLE_API Result<std::vector<AssetMaterial>> parseMtl(std::string_view text, const std::string& displayName,
                                                       const std::filesystem::path& folder);

} // namespace rubble
