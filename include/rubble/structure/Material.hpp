#pragma once
/// \file Material.hpp
/// Structural materials: density, strength limits and fracture pattern, with literature presets
/// (values and sources in docs/structure.md).

#include <string>
#include <string_view>
#include <vector>

#include "rubble/core/Export.hpp"

namespace rubble {

/// How a material breaks (the cell layout an impact cuts).
enum class FracturePattern : int {
    Clustered, ///< fine cells near the impact, coarse further away (concrete, stone, brick)
    Radial,    ///< radial cracks and concentric rings (glass)
    Splinter,  ///< cells elongated along the grain (wood)
    Uniform,   ///< evenly spread cells (steel)
};

/// A structural material. Strengths in MPa, density in kg/m^3.
struct RUBBLE_API Material {
    std::string name;                                     ///< preset name, e.g. "concrete"
    double density = 0;                                   ///< kg/m^3
    double compressiveStrength = 0;                       ///< MPa
    double tensileStrength = 0;                           ///< MPa
    double shearStrength = 0;                             ///< MPa
    FracturePattern pattern = FracturePattern::Clustered; ///< fracture-pattern preset
};

/// The material presets, in a fixed order: concrete, brick, stone, wood, glass, steel.
RUBBLE_API const std::vector<Material>& materialPresets();
/// The preset with this name (lower case), or nullptr.
RUBBLE_API const Material* findMaterial(std::string_view name);
/// The material of objects that name none (concrete).
RUBBLE_API const Material& defaultMaterial();
/// The preset names joined by ", " (for error messages).
RUBBLE_API std::string materialNames();

} // namespace rubble
