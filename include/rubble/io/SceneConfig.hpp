#pragma once
/// \file SceneConfig.hpp
/// The thesis's scene file (media/world.cfg, thesis appendix A.3), accepted unchanged.
///
/// Line 1: six skybox images separated by ';' (top, bottom, left, right, front, back). Line 2: the ground,
/// line 3: the vehicle, every further line an object, all as `model;texture;x;y;z;sx;sy;sz;mass` (mass 0 =
/// static), optionally followed by `;material` (a preset of Material.hpp: concrete, brick, stone, wood,
/// glass, steel; objects without one are concrete), optionally followed by `;roughness`: `flat` or the
/// amplitude of rough cuts relative to the cell size (0 = flat; the material field may then be empty).
/// Blank lines are ignored, '#' starts a comment that runs
/// to the end of the line, CRLF line ends and a UTF-8 byte order mark are accepted, spaces around fields are
/// trimmed, one trailing ';' is allowed.

#include <array>
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "rubble/core/Export.hpp"
#include "rubble/core/Result.hpp"
#include "rubble/core/Vec3.hpp"

namespace rubble {

/// One entity line of a scene file (ground, vehicle or object).
struct RUBBLE_API SceneObject {
    std::size_t line = 0;              ///< 1-based line in the file
    std::string model;                 ///< model file as written (may be empty, e.g. for the ground)
    std::string texture;               ///< texture file as written (may be empty)
    std::filesystem::path modelPath;   ///< model resolved against the file's folder (empty when not given)
    std::filesystem::path texturePath; ///< texture resolved against the file's folder (empty when not given)
    bool modelFound = false;           ///< the resolved model file exists
    bool textureFound = false;         ///< the resolved texture file exists
    Vec3 position;                     ///< x;y;z
    Vec3 scale{1, 1, 1};               ///< sx;sy;sz
    double mass = 0;                   ///< mass; 0 means static
    std::string material;              ///< optional 10th field, a material preset name; empty when not given
    std::optional<double> roughness;   ///< optional 11th field, relative amplitude of rough cuts (0 = flat)

    /// True when the object does not move (mass 0).
    bool isStatic() const { return mass == 0; }
};

/// Something the scene refers to that is missing; the demo substitutes a stand-in.
struct RUBBLE_API SceneWarning {
    std::size_t line = 0; ///< 1-based line in the file
    std::string message;  ///< e.g. "world.cfg:3: model 'fighter.3ds' not found"
};

/// A parsed scene file.
struct RUBBLE_API SceneConfig {
    std::filesystem::path baseDir;                    ///< folder that relative names are resolved against
    std::array<std::string, 6> skybox;                ///< top, bottom, left, right, front, back, as written
    std::array<std::filesystem::path, 6> skyboxPaths; ///< the same, resolved
    SceneObject ground;                               ///< line 2
    SceneObject vehicle;                              ///< line 3
    std::vector<SceneObject> objects;                 ///< every further line
    std::vector<SceneWarning> warnings;               ///< missing files, in line order
};

/// Parses a scene file. Errors (ParseError) name file, line and field, e.g.
/// "world.cfg:4: field 'sy' (7th): expected a number, got 'abc'"; missing model, texture or skybox files are
/// not errors but SceneWarning entries. IoError when the file cannot be read.
RUBBLE_API Result<SceneConfig> parseSceneConfig(const std::filesystem::path& path);

/// Parses scene text; displayName prefixes messages. Relative names are resolved against baseDir, or against
/// the folder of displayName when baseDir is empty.
RUBBLE_API Result<SceneConfig> parseSceneConfigText(const std::string& text, const std::string& displayName,
                                                    const std::filesystem::path& baseDir = {});

} // namespace rubble
