#pragma once
// An impact at a random point of a mesh's surface, just inside it, along the inward normal. Header only.

#include "rubble/core/Random.hpp"
#include "rubble/fracture/Fracture.hpp"

namespace rubble::test {

/// An impact of the given impulse at the centre of a random triangle of mesh, 1e-3 inside, pointing in.
inline Impact randomSurfaceImpact(const Mesh& mesh, Rng& rng, double impulse) {
    const auto t = static_cast<std::size_t>(rng.below(mesh.triangles.size()));
    const auto c = mesh.corners(t);
    const Vec3 n = normalized(cross(c[1] - c[0], c[2] - c[0]));
    return {(c[0] + c[1] + c[2]) / 3.0 - n * 1e-3, n, impulse};
}

} // namespace rubble::test
