#include <algorithm>
#include <cmath>

#include "rubble/fracture/Fracture.hpp"

namespace rubble {

double CellSizeLaw::sizeFor(double impulse) const {
    const double i = std::isfinite(impulse) ? std::max(0.0, impulse) : 0.0;
    const double s = base + scale * std::pow(i, exponent);
    const double lo = std::min(minSize, maxSize), hi = std::max(minSize, maxSize);
    return std::isfinite(s) ? std::clamp(s, lo, hi) : hi;
}

ImpactCut impactCut(const FractureParams& params, const Aabb& meshBounds, double impulse) {
    const double size = params.sizeLaw.sizeFor(impulse);
    if (params.pattern != CellPattern::Adaptive)
        return {params.pattern, size};
    const bool strong = size >= kShatterGrowth * params.sizeLaw.sizeFor(0);
    const double diagonal = meshBounds.diagonal();
    const double growth = std::max(1.0, std::sqrt(diagonal / kAdaptiveReferenceSize));
    const double hi = std::max(params.sizeLaw.minSize, params.sizeLaw.maxSize);
    return {strong ? CellPattern::Shatter : CellPattern::SingleCell, std::min(size * growth, hi)};
}

} // namespace rubble
