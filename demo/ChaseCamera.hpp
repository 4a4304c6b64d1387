#pragma once
/// \file ChaseCamera.hpp
/// A smoothed third-person camera behind and above the vehicle.

#include <cmath>

#include "Math.hpp"

namespace demo {

/// Follows a target frame (position, forward, up) with exponential smoothing; never rolls with the target.
class ChaseCamera {
public:
    float distance = 19;  ///< metres behind the target
    float height = 5.5f;  ///< metres above the target
    float lookAhead = 30; ///< metres ahead of the target the camera looks at
    V3 eye{0, 30, 20};    ///< current position
    V3 target;            ///< current look-at point

    /// Jumps to the ideal position.
    void snap(const V3& pos, const V3& forward, const V3& up) {
        eye = ideal(pos, forward, up);
        target = pos + forward * lookAhead;
    }
    /// Moves toward the ideal position over dt seconds.
    void update(const V3& pos, const V3& forward, const V3& up, float dt) {
        const float k = 1.0f - std::exp(-8.0f * dt);
        eye = lerp(eye, ideal(pos, forward, up), k);
        target = lerp(target, pos + forward * lookAhead, 1.0f - std::exp(-10.0f * dt));
    }
    /// The view matrix.
    M4 view() const { return lookAt(eye, target, V3{0, 1, 0}); }

private:
    V3 ideal(const V3& pos, const V3& forward, const V3& up) const {
        const V3 u = norm(lerp(V3{0, 1, 0}, up, 0.3f));
        return pos - forward * distance + u * height;
    }
};

} // namespace demo
