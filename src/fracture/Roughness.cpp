// Roughness parameters: validation and the material presets (justified in docs/roughness.md).

#include <algorithm>
#include <cmath>
#include <iterator>
#include <string>

#include "rubble/fracture/Roughness.hpp"

#include "rubble/core/ParameterCheck.hpp"

namespace rubble {

Status validateRoughness(const Roughness& r) {
    const ParamRange& amplitude = r.relative ? *findParamRange("roughness") : kAbsoluteRoughness;
    const ParamRange& feature = r.relative ? *findParamRange("feature_size") : kAbsoluteFeatureSize;
    for (Status s : {checkParam(amplitude, r.amplitude), checkParam(feature, r.featureSize),
                     checkParam("hurst", r.hurst), checkParam("octaves", r.octaves),
                     checkParam("grain_stretch", r.grainStretch), checkParam("grain", r.grain),
                     checkParam("max_triangles_per_piece", r.maxTrianglesPerPiece)})
        if (!s)
            return s;
    return {};
}

Roughness roughnessPreset(std::string_view material) {
    Roughness r;
    if (material == "concrete" || material == "stone") {
        r.amplitude = material == "concrete" ? 0.1 : 0.08;
        r.featureSize = 0.35;
        r.hurst = material == "concrete" ? 0.75 : 0.8;
        r.octaves = 3;
    } else if (material == "brick") { // absolute: a course is 65 mm high, its mortar joint 10 mm
        r.relative = false;
        r.amplitude = 0.012;
        r.featureSize = 0.065;
        r.hurst = 0.7;
        r.octaves = 2;
    } else if (material == "wood") {
        r.amplitude = 0.08;
        r.featureSize = 0.4;
        r.hurst = 0.7;
        r.octaves = 3;
        r.grainStretch = 6;
    } else if (material == "glass") { // conchoidal: smooth and shallow
        r.amplitude = 0.01;
        r.featureSize = 0.5;
        r.hurst = 0.9;
        r.octaves = 2;
    }
    return r; // steel and unknown names: flat
}

Result<Roughness> chooseRoughness(const RoughnessChoice& choice) {
    Roughness r;
    if (!choice.material.empty()) {
        constexpr std::string_view kPresets[] = {"concrete", "brick", "stone", "wood", "glass", "steel"};
        if (std::find(std::begin(kPresets), std::end(kPresets), choice.material) == std::end(kPresets))
            return makeError(ErrorCode::InvalidInput, "unknown material '" + std::string(choice.material) +
                                                          "'; expected one of concrete, brick, stone, wood, "
                                                          "glass, steel");
        r = roughnessPreset(choice.material);
    }
    if (choice.amplitude || choice.hurst || choice.featureSize) {
        if (!r.relative)
            r = Roughness{};
        r.amplitude = choice.amplitude.value_or(r.amplitude);
        r.hurst = choice.hurst.value_or(r.hurst);
        r.featureSize = choice.featureSize.value_or(r.featureSize);
    }
    if (Status s = validateRoughness(r); !s)
        return s.error();
    return r;
}

} // namespace rubble
