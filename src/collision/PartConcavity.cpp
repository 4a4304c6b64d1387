// One-sided Hausdorff distance from a mesh's surface to its convex parts (docs/collision.md).
#include "rubble/collision/PartConcavity.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "rubble/core/Random.hpp"
#include "rubble/fracture/Fracture.hpp"

namespace rubble {

namespace {

/// Distance from p to the boundary of the union of parts: the largest depth inside a part containing p, or
/// (outside every part) the smallest largest-plane distance, a lower bound of the distance to the nearest.
double distanceToParts(const Vec3& p, const std::vector<ConvexPolytope>& parts,
                       const std::vector<Aabb>& bounds) {
    double inside = 0, outside = std::numeric_limits<double>::infinity();
    bool covered = false; // p lies in (or on the boundary of) some part
    for (std::size_t k = 0; k < parts.size(); ++k) {
        double out = -std::numeric_limits<double>::infinity();
        for (const PolytopeFaceView& f : parts[k].faces())
            out = std::max(out, f.plane.signedDistance(p));
        if (out <= 0) {
            covered = true;
            inside = std::max(inside, -out);
        } else
            outside =
                std::min(outside, std::max(out, std::sqrt(lengthSquared(
                                                    max(max(bounds[k].lo - p, p - bounds[k].hi), Vec3{})))));
    }
    return covered || !std::isfinite(outside) ? inside : outside;
}

} // namespace

double partConcavity(const Mesh& mesh, const std::vector<ConvexPolytope>& parts, std::size_t samples) {
    const double diagonal = mesh.bounds().diagonal();
    if (mesh.triangles.empty() || parts.empty() || !(diagonal > 0))
        return 0;
    std::vector<Aabb> bounds;
    for (const ConvexPolytope& p : parts)
        bounds.push_back(p.bounds());
    std::vector<double> cumulative(mesh.triangles.size());
    double total = 0;
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
        total += length(mesh.triangleNormal(t));
        cumulative[t] = total;
    }
    Rng rng(0x5eed);
    double worst = 0;
    for (std::size_t s = 0; s < samples; ++s) {
        const double at = rng.uniform() * total;
        const std::size_t t = std::min<std::size_t>(
            static_cast<std::size_t>(std::lower_bound(cumulative.begin(), cumulative.end(), at) -
                                     cumulative.begin()),
            mesh.triangles.size() - 1);
        const auto c = mesh.corners(t);
        double u = rng.uniform(), v = rng.uniform();
        if (u + v > 1) {
            u = 1 - u;
            v = 1 - v;
        }
        const Vec3 p = c[0] + (c[1] - c[0]) * u + (c[2] - c[0]) * v;
        worst = std::max(worst, distanceToParts(p, parts, bounds));
    }
    return worst / diagonal;
}

std::vector<double> pieceConcavity(const FractureResult& result,
                                   const std::vector<std::vector<ConvexPolytope>>& parts,
                                   std::size_t samples) {
    std::vector<double> out;
    out.reserve(result.pieces.size());
    for (std::size_t i = 0; i < result.pieces.size(); ++i)
        out.push_back(i < parts.size() && !parts[i].empty()
                          ? partConcavity(result.pieces[i].mesh, parts[i], samples)
                          : -1.0);
    return out;
}

const std::vector<double>& recordConcavity(FractureResult& result,
                                           const std::vector<std::vector<ConvexPolytope>>& parts,
                                           std::size_t samples) {
    result.concavity = pieceConcavity(result, parts, samples);
    return result.concavity;
}

} // namespace rubble
