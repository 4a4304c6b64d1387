#include <algorithm>
#include <cmath>

#include "rubble/Fracture.hpp"

namespace rubble {

double CellSizeLaw::sizeFor(double impulse) const {
    const double i = std::isfinite(impulse) ? std::max(0.0, impulse) : 0.0;
    const double s = base + scale * std::pow(i, exponent);
    const double lo = std::min(minSize, maxSize), hi = std::max(minSize, maxSize);
    return std::isfinite(s) ? std::clamp(s, lo, hi) : hi;
}

} // namespace rubble
