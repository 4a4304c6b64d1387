// Roughness parameters: validation and the material presets (justified in docs/roughness.md).

#include <cmath>
#include <string>

#include "rubble/Roughness.hpp"

namespace rubble {

namespace {

Status outOfRange(const char* name, double value, const std::string& range) {
    return makeError(ErrorCode::InvalidInput, std::string("roughness: ") + name + " = " +
                                                  std::to_string(value) + " is not in " + range);
}

} // namespace

Status validateRoughness(const Roughness& r) {
    const double maxAmplitude = r.relative ? 1.0 : 1e6, maxFeature = r.relative ? 4.0 : 1e6;
    const std::string scale = r.relative ? " (relative to the cell size)" : " (absolute)";
    if (!std::isfinite(r.amplitude) || r.amplitude < 0 || r.amplitude > maxAmplitude)
        return outOfRange("amplitude", r.amplitude, "[0, " + std::to_string(maxAmplitude) + "]" + scale);
    if (!std::isfinite(r.featureSize) || r.featureSize < 0 || r.featureSize > maxFeature)
        return outOfRange("featureSize", r.featureSize, "[0, " + std::to_string(maxFeature) + "]" + scale);
    if (!std::isfinite(r.hurst) || r.hurst <= 0 || r.hurst > 1)
        return outOfRange("hurst", r.hurst, "(0, 1]");
    if (r.octaves < 1 || r.octaves > kMaxRoughOctaves)
        return outOfRange("octaves", r.octaves, "[1, " + std::to_string(kMaxRoughOctaves) + "]");
    if (!std::isfinite(r.grainStretch) || r.grainStretch < 1 || r.grainStretch > 100)
        return outOfRange("grainStretch", r.grainStretch, "[1, 100]");
    if (!isFinite(r.grain))
        return makeError(ErrorCode::InvalidInput, "roughness: grain is not a finite vector");
    if (r.maxTrianglesPerPiece < 64 || r.maxTrianglesPerPiece > 10'000'000)
        return outOfRange("maxTrianglesPerPiece", r.maxTrianglesPerPiece, "[64, 10000000]");
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

} // namespace rubble
