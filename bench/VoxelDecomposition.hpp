#pragma once
// A voxel-based convex decomposition in the manner of V-HACD, written here as the bench's comparison method
// (no V-HACD source): the mesh is filled on a grid, the solid voxels are split by axis-aligned planes, and
// each part is the hull of its voxels' corners (docs/collision.md says what it is and is not).

#include <cstddef>

#include "rubble/collision/ConvexDecomposition.hpp"

namespace rubble::bench {

/// Settings of voxelDecompose.
struct VoxelParams {
    int cells = 64;             ///< voxels along the longest side of the mesh's box
    int maxParts = 32;          ///< at most this many parts
    double volumeError = 0.005; ///< a part whose hull exceeds its voxels by less (of all voxels) is kept
    int planesPerAxis = 7;      ///< candidate split planes per axis, evenly spaced in the part's voxels
    int rankStride = 2;         ///< the planes are ranked by hulls of every rankStride-th voxel column
};

/// Decomposes a closed mesh: voxels whose centre is inside (ray parity along z) or that a surface sample
/// falls in are solid; the part with the largest hull volume over its voxels' volume is split by the
/// candidate plane giving the least total hull volume, until params.maxParts parts or every part is within
/// params.volumeError. Parts contain every solid voxel, so they stick out of the mesh by up to a voxel.
Result<Decomposition> voxelDecompose(const Mesh& mesh, const VoxelParams& params = {});

} // namespace rubble::bench
