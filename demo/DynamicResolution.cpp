#include "DynamicResolution.hpp"

#include <algorithm>
#include <cmath>

namespace demo {

DynamicResolution::DynamicResolution(float targetMs, float minScale)
    : targetMs_(targetMs), minScale_(std::clamp(minScale, 0.1f, 1.0f)) {}

float DynamicResolution::update(float frameMs) {
    if (minScale_ >= 1.0f || frameMs <= 0)
        return scale_;
    // Smoothed over ~8 frames; a lone spike (a fracture's first upload) does not drop the resolution.
    smoothedMs_ = smoothedMs_ <= 0 ? frameMs : smoothedMs_ + (frameMs - smoothedMs_) * 0.125f;
    if (cooldown_ > 0) {
        --cooldown_;
        return scale_;
    }
    float next = scale_;
    if (smoothedMs_ > targetMs_ * 1.05f) // fill cost goes with the area: scale the axes by the root
        next = scale_ * std::max(0.85f, std::sqrt(targetMs_ / smoothedMs_));
    else if (smoothedMs_ < targetMs_ * 0.8f)
        next = scale_ + 0.03f;
    next = std::clamp(std::round(next * 64.0f) / 64.0f, minScale_, 1.0f);
    if (next != scale_) {
        scale_ = next;
        cooldown_ = 10; // let the smoothed time follow before the next change
    }
    return scale_;
}

void DynamicResolution::size(int outW, int outH, int& w, int& h) const {
    w = std::max(1, static_cast<int>(std::lround(static_cast<float>(outW) * scale_ / 2.0f)) * 2);
    h = std::max(1, static_cast<int>(std::lround(static_cast<float>(outH) * scale_ / 2.0f)) * 2);
    w = std::min(w, outW);
    h = std::min(h, outH);
}

} // namespace demo
