#pragma once
// How much the collision parts of fractured pieces reach into each other's solids, and out of their own
// piece's convex hull: the measures of docs/collision.md. Header only.

#include <algorithm>
#include <cstddef>
#include <vector>

#include "rubble/collision/ConvexDecomposition.hpp"
#include "rubble/geometry/ConvexPolytope.hpp"
#include "rubble/geometry/MassProperties.hpp"
#include "rubble/geometry/Mesh.hpp"

namespace rubble::test {

/// Volume inside both a convex part and a closed mesh, from a grid of samplesPerAxis³ points in the common
/// bounds (each at its grid cell's centre).
inline double overlapVolume(const ConvexPolytope& part, const Mesh& mesh, int samplesPerAxis = 14) {
    const Aabb pb = part.bounds(), mb = mesh.bounds();
    Aabb box;
    box.lo = max(pb.lo, mb.lo);
    box.hi = min(pb.hi, mb.hi);
    const Vec3 size = box.hi - box.lo;
    if (!(size.x > 0 && size.y > 0 && size.z > 0))
        return 0;
    const int n = samplesPerAxis;
    std::size_t hits = 0;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j)
            for (int k = 0; k < n; ++k) {
                const Vec3 p =
                    box.lo + Vec3{size.x * (i + 0.5) / n, size.y * (j + 0.5) / n, size.z * (k + 0.5) / n};
                if (part.contains(p) && windingNumber(mesh, p) > 0.5)
                    ++hits;
            }
    return size.x * size.y * size.z * static_cast<double>(hits) / (double(n) * n * n);
}

/// The worst overlap between one piece's parts and another piece's solid, over every ordered pair of pieces,
/// as a fraction of the smaller piece's volume (parts of one piece summed: an upper bound of their union's).
struct PieceOverlap {
    double fraction = 0; ///< worst overlap / smaller volume
    std::size_t piece = 0, other = 0;
};
inline PieceOverlap worstPieceOverlap(const std::vector<Mesh>& pieces,
                                      const std::vector<std::vector<ConvexPolytope>>& parts) {
    PieceOverlap worst;
    std::vector<double> volumes;
    for (const Mesh& m : pieces)
        volumes.push_back(signedVolume(m));
    for (std::size_t i = 0; i < pieces.size() && i < parts.size(); ++i)
        for (std::size_t j = 0; j < pieces.size(); ++j) {
            if (i == j)
                continue;
            double v = 0;
            for (const ConvexPolytope& part : parts[i])
                v += overlapVolume(part, pieces[j]);
            const double f = v / std::min(volumes[i], volumes[j]);
            if (f > worst.fraction)
                worst = {f, i, j};
        }
    return worst;
}

/// How far the parts reach outside the convex hull of the piece, over its bounding-box diagonal (0 inside).
inline double reachOutsideHull(const Mesh& piece, const std::vector<ConvexPolytope>& parts) {
    auto hull = convexHull(piece.positions);
    if (!hull)
        return 0;
    double worst = 0;
    for (const ConvexPolytope& part : parts)
        for (const PolytopeFaceView& f : part.faces())
            for (const Vec3& c : f.corners)
                for (const PolytopeFaceView& h : hull->faces())
                    worst = std::max(worst, h.plane.signedDistance(c));
    return worst / piece.bounds().diagonal();
}

} // namespace rubble::test
