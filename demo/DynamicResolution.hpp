#pragma once
/// \file DynamicResolution.hpp
/// Chooses the internal render resolution each frame so that frame times hold a target rate.

namespace demo {

/// Scale of the internal render resolution (1 = output size), driven by measured frame times.
class DynamicResolution {
public:
    /// targetMs: frame time to hold; minScale: the smallest scale allowed (per axis).
    DynamicResolution(float targetMs, float minScale);
    /// Feeds the last frame's time and returns the scale for the next frame.
    float update(float frameMs);
    /// The current scale.
    float scale() const { return scale_; }
    /// Internal size for an output size at the current scale (even, at least 1).
    void size(int outW, int outH, int& w, int& h) const;

private:
    float targetMs_;
    float minScale_;
    float scale_ = 1.0f;
    float smoothedMs_ = 0.0f;
    int cooldown_ = 0;
};

} // namespace demo
