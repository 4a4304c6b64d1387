#pragma once
/// \file SceneLoader.hpp
/// Builds the bodies of a parsed world.cfg scene (SceneConfig) in a DestructionRuntime: ground box, vehicle,
/// destructible objects.

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "rubble/core/Export.hpp"
#include "rubble/io/SceneConfig.hpp"
#include "rubble/runtime/DestructionRuntime.hpp"

namespace rubble {

/// How scene objects are made.
struct RUBBLE_API SceneLoadOptions {
    bool loadVehicle = true;        ///< create the vehicle's body (headless scenes may skip it)
    double staticDensity = 200;     ///< density (kg/m³) of static objects, used by their moving pieces
    double impulseThreshold = 50;   ///< ObjectDesc::impulseThreshold of every object
    FractureParams fracture;        ///< ObjectDesc::fracture of every object
    bool materialRoughness = false; ///< cuts of an object without a roughness field get its material's
                                    ///< roughness preset (roughnessPreset) instead of fracture.roughness
    double maxOverlap = 0.5; ///< an object whose bounding box overlaps an earlier one's by more than this
                             ///< share of the smaller box, one of them moving, is not loaded (with a warning)
    std::function<void(Mesh&)>
        prepareMesh; ///< called on every object mesh (scaled, object coordinates) before it is added, e.g.
                     ///< to generate texture coordinates; may be empty
};

/// What loading produced.
struct RUBBLE_API LoadedScene {
    BodyId ground = 0;                   ///< the ground box (0 when the scene has none)
    BodyId vehicle = 0;                  ///< the vehicle (0 when not loaded; it never sleeps)
    double groundTop = 0;                ///< height of the ground's top face
    std::vector<ObjectId> objects;       ///< objects in file order (stand-ins included)
    std::vector<std::size_t> sceneIndex; ///< for each of objects: its index in SceneConfig::objects
    std::vector<std::string> warnings;   ///< missing files, stand-ins, meshes made indestructible
    double initialVolume = 0;            ///< Σ object volumes at load
};

/// Loads a scene. The ground line gives a static box of full size (sx, sy, sz) centred at (x, y, z); the
/// vehicle line a dynamic convex body; every object line readMesh(model) scaled by (sx, sy, sz) and placed at
/// (x, y, z), mass 0 = static but destructible. An object's roughness field sets the amplitude of its cuts
/// over its material's preset (SceneObject::roughness; 0 = flat). A missing or unreadable model becomes a
/// stand-in box (a cube of edge 1 scaled by (sx, sy, sz)) with a warning; a mesh that cannot be made valid
/// stays intact and indestructible with one warning. Never fails on a parsed scene.
RUBBLE_API LoadedScene loadScene(const SceneConfig& scene, DestructionRuntime& runtime,
                                 const SceneLoadOptions& options = {});

} // namespace rubble
