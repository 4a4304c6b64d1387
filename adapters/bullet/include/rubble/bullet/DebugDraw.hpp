#pragma once
/// \file DebugDraw.hpp
/// Renderer-independent debug drawing data: coloured line segments in world coordinates.

#include <cstdint>
#include <vector>

#include "rubble/core/Vec3.hpp"

namespace rubble::bullet {

/// One line segment in world coordinates with an RGBA colour (0xRRGGBBAA).
struct DebugLine {
    Vec3 from;                       ///< start (world)
    Vec3 to;                         ///< end (world)
    std::uint32_t rgba = 0xFFFFFFFF; ///< colour
};

/// What to include in BulletBinding::debugDraw().
struct DebugDrawOptions {
    bool shapes = true;           ///< wireframes of the collision shapes (convex parts)
    bool aabbs = false;           ///< axis-aligned bounding boxes
    bool impacts = true;          ///< recent impact points as small crosses
    double impactCrossSize = 0.3; ///< half length of an impact cross (m)
};

/// Line segments for any renderer.
struct DebugDraw {
    std::vector<DebugLine> lines; ///< all segments
};

} // namespace rubble::bullet
