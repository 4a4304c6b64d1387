#pragma once
/// \file GroundMesh.hpp
/// The scene's ground as drawn: a box of the ground line's scale (thesis: "a solid cube with 1x1x1 size"),
/// with UVs of a 16 m grid in world x and z.

#include <cmath>

#include "rubble/rubble.hpp"

namespace demo {

/// The ground box in its own coordinates (centred on the ground line's position).
inline rubble::Mesh groundMesh(const rubble::SceneObject& g) {
    const rubble::Vec3 half{std::abs(g.scale.x) * 0.5, std::abs(g.scale.y) * 0.5, std::abs(g.scale.z) * 0.5};
    rubble::Mesh box = rubble::makeBox(-half, half);
    box.uvs.assign(box.triangles.size() * 3, {});
    for (size_t t = 0; t < box.triangles.size(); ++t)
        for (int c = 0; c < 3; ++c) {
            const auto& p = box.positions[box.triangles[t][static_cast<size_t>(c)]];
            box.uvs[3 * t + static_cast<size_t>(c)] = {(p.x + g.position.x) / 16.0,
                                                       (p.z + g.position.z) / 16.0};
        }
    return box;
}

} // namespace demo
