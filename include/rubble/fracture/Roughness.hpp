#pragma once
/// \file Roughness.hpp
/// Rough cut surfaces: every new cut face is displaced along its normal by a seeded self-affine height field
/// that is zero on the face's outline (docs/roughness.md).

#include <cstdint>
#include <optional>
#include <string_view>

#include "rubble/core/Export.hpp"
#include "rubble/core/ParameterCheck.hpp"
#include "rubble/core/Result.hpp"
#include "rubble/core/Vec3.hpp"

namespace rubble {

/// The cut-surface model of a fracture. amplitude 0 is the thesis's flat cut.
struct RUBBLE_API Roughness {
    double amplitude = 0;    ///< largest height of a cut face above or below its plane; 0 = flat
    double featureSize = 0;  ///< longest wavelength; 0 = 8 × amplitude
    double hurst = 0.75;     ///< Hurst (roughness) exponent in (0, 1]
    int octaves = 4;         ///< wavelengths featureSize / 2^k for k < octaves (fewer when the budget binds)
    bool relative = true;    ///< amplitude and featureSize are fractions of the cut's cell size
    std::uint64_t seed = 0;  ///< of the height field (fracture() mixes its own seed in)
    double grainStretch = 1; ///< wavelengths along grain are this many times longer (wood); 1 = isotropic
    Vec3 grain; ///< grain direction in mesh coordinates; zero = the longest axis of the mesh's bounds
    int maxTrianglesPerPiece = 2000; ///< budget of a piece's rough cut faces: the tessellation coarsens
    /// True when cuts are rough.
    bool active() const { return amplitude > 0; }
};

/// Checks every field of r against the parameter table (rubble/core/ParameterCheck.hpp: roughness,
/// feature_size, hurst, octaves, grain_stretch, grain, max_triangles_per_piece); InvalidInput naming the
/// first one refused.
RUBBLE_API Status validateRoughness(const Roughness& r);

/// A cut's roughness as a caller sets it: a material's preset, then any of amplitude, hurst and feature size
/// by hand (fractions of the cell size; an absolute preset set by hand becomes relative).
struct RUBBLE_API RoughnessChoice {
    std::string_view material;         ///< a material name, or empty for flat before the values set by hand
    std::optional<double> amplitude;   ///< Roughness::amplitude, unless unset
    std::optional<double> hurst;       ///< Roughness::hurst, unless unset
    std::optional<double> featureSize; ///< Roughness::featureSize, unless unset
};

/// The roughness of choice, checked by validateRoughness; InvalidInput for a material with no preset.
RUBBLE_API Result<Roughness> chooseRoughness(const RoughnessChoice& choice);

/// The roughness preset of a material name (concrete, brick, stone, wood, glass, steel; docs/roughness.md),
/// or flat for any other name.
RUBBLE_API Roughness roughnessPreset(std::string_view material);

} // namespace rubble
