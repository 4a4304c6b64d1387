// Shared by the boolean backends: output meshes with attributes carried over from the input.

#include <algorithm>
#include <cmath>
#include <limits>

#include "BooleanBackends.hpp"
#include "geometry/ClosestPoint.hpp"
#include "geometry/OrientedShells.hpp"

namespace rubble::detail {

namespace {

/// A uniform grid of the input's triangles for nearest-triangle queries near the surface.
class TriangleGrid {
public:
    explicit TriangleGrid(const Mesh& m) : mesh_(m) {
        box_ = m.bounds();
        const double n = std::max(1.0, std::cbrt(static_cast<double>(m.triangleCount())));
        for (int a = 0; a < 3; ++a) {
            dims_[a] = static_cast<int>(std::clamp(n, 1.0, 64.0));
            const double ext = box_.hi[a] - box_.lo[a];
            cell_[a] = ext > 0 ? ext / dims_[a] : 1.0;
        }
        buckets_.resize(static_cast<std::size_t>(dims_[0] * dims_[1] * dims_[2]));
        for (std::size_t t = 0; t < m.triangleCount(); ++t) {
            Aabb b;
            for (const Vec3& p : m.corners(t))
                b.extend(p);
            int lo[3], hi[3];
            for (int a = 0; a < 3; ++a) {
                lo[a] = index(b.lo[a], a);
                hi[a] = index(b.hi[a], a);
            }
            for (int x = lo[0]; x <= hi[0]; ++x)
                for (int y = lo[1]; y <= hi[1]; ++y)
                    for (int z = lo[2]; z <= hi[2]; ++z)
                        buckets_[slot(x, y, z)].push_back(static_cast<std::uint32_t>(t));
        }
    }

    /// The nearest triangle to p among those in the buckets within one ring; squared distance out.
    std::int64_t nearest(const Vec3& p, double& dist2) const {
        std::int64_t best = -1;
        dist2 = std::numeric_limits<double>::infinity();
        int c[3];
        for (int a = 0; a < 3; ++a)
            c[a] = index(p[a], a);
        for (int x = std::max(0, c[0] - 1); x <= std::min(dims_[0] - 1, c[0] + 1); ++x)
            for (int y = std::max(0, c[1] - 1); y <= std::min(dims_[1] - 1, c[1] + 1); ++y)
                for (int z = std::max(0, c[2] - 1); z <= std::min(dims_[2] - 1, c[2] + 1); ++z)
                    for (std::uint32_t t : buckets_[slot(x, y, z)]) {
                        const auto k = mesh_.corners(t);
                        const double d = lengthSquared(closestOnTriangle(p, k[0], k[1], k[2]) - p);
                        if (d < dist2) {
                            dist2 = d;
                            best = t;
                        }
                    }
        return best;
    }

private:
    const Mesh& mesh_;
    Aabb box_;
    int dims_[3] = {1, 1, 1};
    double cell_[3] = {1, 1, 1};
    std::vector<std::vector<std::uint32_t>> buckets_;

    int index(double v, int a) const {
        const double f = std::floor((v - box_.lo[a]) / cell_[a]);
        return static_cast<int>(std::clamp(f, 0.0, static_cast<double>(dims_[a] - 1)));
    }
    std::size_t slot(int x, int y, int z) const {
        return static_cast<std::size_t>((x * dims_[1] + y) * dims_[2] + z);
    }
};

} // namespace

Mesh assembleMesh(const Mesh& input, std::vector<Vec3> positions, const std::vector<Triangle>& triangles,
                  std::vector<std::int64_t> sources) {
    Mesh m;
    m.materialNames = input.materialNames;
    if (std::find(sources.begin(), sources.end(), kUnknownSource) != sources.end()) {
        const TriangleGrid grid(input);
        const double tol = 1e-9 * std::max(1.0, input.bounds().diagonal());
        for (std::size_t t = 0; t < triangles.size(); ++t) {
            if (sources[t] != kUnknownSource)
                continue;
            const Vec3 c =
                (positions[triangles[t][0]] + positions[triangles[t][1]] + positions[triangles[t][2]]) *
                (1.0 / 3.0);
            double d2 = 0;
            const std::int64_t s = grid.nearest(c, d2);
            // On the input surface (and facing the same way): an input face; otherwise a cut face.
            if (s >= 0 && d2 <= tol * tol) {
                const Vec3 n = cross(positions[triangles[t][1]] - positions[triangles[t][0]],
                                     positions[triangles[t][2]] - positions[triangles[t][0]]);
                sources[t] = dot(n, input.triangleNormal(static_cast<std::size_t>(s))) > 0 ? s : kCutFace;
            } else {
                sources[t] = kCutFace;
            }
        }
    }
    m.positions = std::move(positions);
    m.triangles = triangles;
    const bool hasN = input.hasNormals(), hasUv = input.hasUvs();
    const std::size_t nt = triangles.size();
    if (hasN)
        m.normals.reserve(3 * nt);
    m.uvs.reserve(3 * nt);
    m.materials.reserve(nt);
    for (std::size_t t = 0; t < nt; ++t) {
        const std::int64_t src = sources[t];
        const Triangle& tri = triangles[t];
        if (src < 0) {
            if (hasN) {
                const Vec3 n = normalized(cross(m.positions[tri[1]] - m.positions[tri[0]],
                                                m.positions[tri[2]] - m.positions[tri[0]]));
                m.normals.insert(m.normals.end(), 3, Vec3f(n));
            }
            m.uvs.insert(m.uvs.end(), 3, Vec2f{});
            m.materials.push_back(kInteriorMaterial);
            continue;
        }
        const auto s = static_cast<std::size_t>(src);
        m.materials.push_back(input.material(s));
        if (!hasN && !hasUv) {
            m.uvs.insert(m.uvs.end(), 3, Vec2f{});
            continue;
        }
        const auto c = input.corners(s);
        const Vec3 n = cross(c[1] - c[0], c[2] - c[0]);
        const double nn = dot(n, n);
        const double inv = nn > 0 ? 1.0 / nn : 0.0;
        for (std::uint32_t v : tri) {
            const Vec3& p = m.positions[v];
            double w0 = dot(cross(c[1] - p, c[2] - p), n) * inv;
            double w1 = dot(cross(c[2] - p, c[0] - p), n) * inv;
            if (inv == 0) {
                w0 = 1;
                w1 = 0;
            }
            const double w2 = 1 - w0 - w1;
            const std::size_t b = 3 * s;
            if (hasN)
                m.normals.emplace_back(normalized(w0 * input.normals[b] + w1 * input.normals[b + 1] +
                                                  w2 * input.normals[b + 2]));
            if (hasUv) {
                const Vec2f &u0 = input.uvs[b], &u1 = input.uvs[b + 1], &u2 = input.uvs[b + 2];
                m.uvs.push_back({u0.x * w0 + u1.x * w1 + u2.x * w2, u0.y * w0 + u1.y * w1 + u2.y * w2});
            } else {
                m.uvs.push_back({});
            }
        }
    }
    return m;
}

bool isClosedOriented(const Mesh& mesh) {
    return closedOrientedShells(mesh, nullptr) >= 0;
}

} // namespace rubble::detail
