#pragma once
// Private to rubble_fracture (and its tests): rough cut faces (docs/roughness.md).

#include <cstdint>
#include <vector>

#include "BooleanBackends.hpp"
#include "rubble/fracture/Fracture.hpp"
#include "rubble/fracture/Roughness.hpp"
#include "rubble/geometry/ConvexPolytope.hpp"

namespace rubble::detail {

/// An orthonormal basis (u, v) of the plane with normal n, the same for n and -n.
void cutBasis(Vec3 n, Vec3& u, Vec3& v);

/// A seeded fBm of value noise: sum over octaves k of 2^(-kH) noise(2^k x / featureSize), divided by the
/// sum of the octaves' weights, so |value| <= 1.
class RoughField {
public:
    RoughField(const Roughness& r, double featureSize, int octavesUsed, const Vec3& grain);
    /// The field at p, in [-1, 1].
    double operator()(const Vec3& p) const;

private:
    std::uint64_t seed_;
    double frequency_; // 1 / featureSize
    double gain_;      // 2^-H
    double norm_;      // 1 / sum of all octaves' weights
    int octaves_;
    double squash_; // 1 / grainStretch - 1
    Vec3 grain_;    // unit
};

/// What roughenSplit did.
struct RoughCutReport {
    double amplitude = 0;   ///< absolute amplitude
    double featureSize = 0; ///< absolute longest wavelength
    double edge = 0;        ///< longest cut-face edge after tessellation
    int octaves = 0;        ///< octaves used (the tessellation resolves them)
    std::size_t faces = 0;  ///< cut-face triangles after tessellation, over all outputs
};

/// Roughens the new cut faces of a split made by the convex-cell clipper (each cut triangle is in both
/// outputs it separates, reversed): tessellates them by splitting every edge longer than the target at its
/// midpoint (and the outer triangles along them, in their plane), then moves every vertex inside a cut face
/// along the face's normal by the height field, zero on the face's outline. Sets the cut faces' UVs
/// (planar, of the flat position) and normals (of the displaced surface); keeps remainderIntegrals exact.
/// focus: the cells' bounds; onPlane: the tolerance to recognise a cut face on a cell face.
RoughCutReport roughenSplit(SplitResult& split, const std::vector<ConvexPolytope>& cells, const Roughness& r,
                            double uvScale, const Aabb& meshBox, double onPlane);

/// roughenSplit on a split whose remainder is an edit of mesh: the edit's new triangles are roughened as a
/// mesh of their own (the rest of mesh is not read), the bisections' points appended to its new points, and
/// remainderIntegrals kept exact.
RoughCutReport roughenEdit(SplitEdit& split, const Mesh& mesh, const std::vector<ConvexPolytope>& cells,
                           const Roughness& r, double uvScale, const Aabb& meshBox, double onPlane);

} // namespace rubble::detail
