#pragma once
/// \file MeshIO.hpp
/// Reading and writing meshes: Rubble's own OBJ reader and writer, and other formats through Assimp.
/// Errors name the file and, where known, the line: "cube.obj:17: face refers to vertex 9 but only 8 are
/// defined". No reader crashes or allocates without bound on malformed input.

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "rubble/core/Export.hpp"
#include "rubble/core/Result.hpp"
#include "rubble/geometry/MassProperties.hpp"
#include "rubble/geometry/Mesh.hpp"
#include "rubble/io/SceneIO.hpp"

namespace rubble {

/// Name under which kInteriorMaterial is written to and read from OBJ/MTL files.
inline constexpr std::string_view kInteriorMaterialName = "interior";

/// One object of a multi-object file (OBJ `o` statements, or `g` groups when a file has no `o`).
struct RUBBLE_API NamedMesh {
    std::string name; ///< the object's name ("" for faces before the first `o`/`g`)
    Mesh mesh;        ///< its triangles; vertices renumbered to the ones it uses
};

/// Options of writeObj.
struct RUBBLE_API ObjWriteOptions {
    bool writeNormals = true; ///< write `vn` and v//vn corners when the mesh has normals
    bool writeUvs = true;     ///< write `vt` corners when the mesh has texture coordinates
    bool writeMaterials =
        true;               ///< write `usemtl` and a .mtl file next to the .obj when the mesh has materials
    std::string objectName; ///< an `o` statement with this name when non-empty
    std::vector<Mesh> collision; ///< convex collision parts, written as objects "UCX_<objectName>_<nn>"
                                 ///< (Unreal's convention) after the mesh; needs objectName
    std::vector<AssetMaterial>
        materials; ///< definitions of the mesh's materials, matched by name (the
                   ///< interior by "interior"); texture maps are copied next to the
                   ///< .obj (see writeGltf); materials without one get a palette colour
};

/// Parses OBJ text into one mesh (all objects merged). `displayName` prefixes error messages.
/// Supports v/vt/vn/f (v, v/vt, v//vn, v/vt/vn, negative indices), o/g, usemtl; quads and convex n-gons
/// are fanned, concave n-gons ear-clipped on their best-fit plane. Unreferenced vertices are dropped.
/// Material ids follow the order of first `usemtl` (names in Mesh::materialNames; faces before the first
/// `usemtl` get a material named "default"); the name "interior" maps to kInteriorMaterial. Corners without
/// a normal get the flat face normal, corners without a texture coordinate get (0, 0).
/// Non-finite coordinates ("nan", "inf") are accepted (checkMesh reports them); numbers beyond the double
/// range are a ParseError.
RUBBLE_API Result<Mesh> parseObj(std::string_view text, const std::string& displayName);
/// Parses OBJ text keeping objects apart (see NamedMesh); objects without faces are dropped.
RUBBLE_API Result<std::vector<NamedMesh>> parseObjObjects(std::string_view text,
                                                          const std::string& displayName);

/// Parses OFF text (Rubble's own reader: numbers exact to the double, polygons of any size triangulated as in
/// parseObj, `#` comments anywhere). The header [ST][C][N][4][n]OFF is followed by the vertex, face and
/// (ignored) edge counts; each vertex is one line `x y z` (`x y z w` for 4OFF, divided by w), each face one
/// line `n i1 ... in` with 0-based indices; anything after the numbers a line needs (normals, colours) is
/// ignored. The declared counts must match the file. Unreferenced vertices are dropped. Errors (ParseError,
/// Unsupported for binary OFF and dimensions other than 3) name displayName and the line.
RUBBLE_API Result<Mesh> parseOff(std::string_view text, const std::string& displayName);

/// Reads an OBJ file into one mesh (see parseObj). Errors: IoError when the file cannot be read, ParseError
/// naming file and line when it is malformed or has no triangles.
RUBBLE_API Result<Mesh> readObj(const std::filesystem::path& path);
/// Reads an OBJ file keeping its objects apart (see parseObjObjects).
RUBBLE_API Result<std::vector<NamedMesh>> readObjObjects(const std::filesystem::path& path);

/// Writes mesh as OBJ (exact shortest round-trip numbers), with normals and texture coordinates when present,
/// and, when the mesh has materials, `usemtl` statements and an MTL file (same stem, .mtl) in which
/// kInteriorMaterial is "interior" with its own colour (or its definition in options.materials). Collision
/// parts follow as UCX_ objects. Triangles keep their order. Each file is written to a
/// staging file next to it and renamed, so a failed write (IoError) leaves the previous file as it was.
RUBBLE_API Status writeObj(const std::filesystem::path& path, const Mesh& mesh,
                           const ObjWriteOptions& options = {});

/// One node of a glTF scene written by writeGltf.
struct RUBBLE_API GltfNode {
    GltfNode() = default;
    /// A node with the given fields.
    GltfNode(std::string name_, Mesh mesh_, const Vec3& origin_, std::vector<Mesh> collision_ = {},
             std::string extras_ = {}, int parent_ = -1)
        : name(std::move(name_)), mesh(std::move(mesh_)), origin(origin_), collision(std::move(collision_)),
          extras(std::move(extras_)), parent(parent_) {}

    std::string name; ///< node and mesh name (e.g. "piece_000")
    Mesh mesh;        ///< closed or open triangles in scene coordinates; must not be empty
    Vec3 origin;      ///< where the node is placed (e.g. the piece's centre of mass); the mesh is stored
                      ///< relative to it, so that a node's translation is `origin`
    std::vector<Mesh> collision; ///< convex parts in scene coordinates, written as child nodes
                                 ///< "<name>_hull_<nn>-convcolonly" (Godot's collision-only suffix)
    std::string extras;          ///< a JSON object stored as the node's "extras" ("" for none)
    int parent = -1; ///< index of the parent node among those written before it (-1: a root of the scene)
};

/// Writes a glTF 2.0 file (one embedded base64 buffer): one node per GltfNode, translated to its origin
/// (relative to its parent's), each with a mesh of one primitive per material id, and its collision parts as
/// child nodes. Materials are named after Mesh::materialNames ("surface" when a mesh has none;
/// kInteriorMaterial is "interior", i.e. cut faces) and take base colour and base colour texture from the
/// AssetMaterial of the same name in `materials`; texture images are copied into a folder "textures" next to
/// the file (embedded images written out; an image that cannot be read is referenced by its path relative to
/// the file) and referenced by URI. Every primitive has POSITION (float, relative to the origin), NORMAL
/// (unit; flat face normals when the mesh has none), TEXCOORD_0 (V flipped to glTF's top-left origin; (0, 0)
/// when the mesh has none) and uint32 indices; corners with equal position, normal and UV share a vertex.
/// Output is byte-identical for identical input. Errors: InvalidInput for an empty or invalid mesh, IoError
/// naming the file (written through a staging file and a rename, as writeObj). sceneExtras, when not empty,
/// is a JSON object stored as the scene's "extras".
RUBBLE_API Status writeGltf(const std::filesystem::path& path, const std::vector<GltfNode>& nodes,
                            const std::vector<AssetMaterial>& materials = {},
                            const std::string& sceneExtras = {});

/// The node extras Rubble writes for a piece (docs/authoring.md): {"rubble":{"level","density":1,"mass",
/// "volume","center_of_mass":[x,y,z],"inertia":[[...],[...],[...]]}} (density 1, so mass = volume), plus
/// "parent" when parent is not empty.
RUBBLE_API std::string pieceExtras(const MassProperties& mass, int level, const std::string& parent = {});

/// Reads a mesh by extension: .obj with readObj, .off with parseOff, ASCII .ply and .stl with Rubble's own
/// readers (exact doubles, file:line errors, equal positions welded); binary .stl and .ply, .3ds, .gltf and
/// .glb through Assimp (single precision; triangulated, positions welded exactly, node transforms applied).
/// Size claims in headers (binary STL triangle count, PLY element counts, OFF counts, 3DS chunk lengths, glTF
/// buffer/accessor lengths) are checked against the file before Assimp sees it, and so are glTF's JSON depth
/// and node hierarchy (at most 256 and 1024 levels; nodes must form trees). Errors: Unsupported for other
/// extensions, IoError, ParseError; every message names the file.
RUBBLE_API Result<Mesh> readMesh(const std::filesystem::path& path);

/// The extensions readMesh accepts, lower case with the dot (".obj", ".stl", ...).
RUBBLE_API const std::vector<std::string>& supportedMeshExtensions();

} // namespace rubble
