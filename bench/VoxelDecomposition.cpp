#include "VoxelDecomposition.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>

#include "rubble/geometry/MassProperties.hpp"

namespace rubble::bench {

namespace {

/// Solid voxels of a mesh on a grid of cubes of edge h from origin; columns along z are contiguous.
struct Grid {
    int n[3] = {0, 0, 0};
    Vec3 origin;
    double h = 0;
    std::vector<std::uint8_t> solid;

    std::size_t index(int x, int y, int z) const {
        return (static_cast<std::size_t>(x) * static_cast<std::size_t>(n[1]) + static_cast<std::size_t>(y)) *
                   static_cast<std::size_t>(n[2]) +
               static_cast<std::size_t>(z);
    }
    int cellOf(double v, int axis) const {
        return std::clamp(static_cast<int>(std::floor((v - origin[axis]) / h)), 0, n[axis] - 1);
    }
};

/// A box of voxels [lo, hi) along each axis.
struct Box {
    std::array<int, 3> lo{}, hi{};
};

/// The solid voxels of a closed mesh: a voxel whose centre has an odd count of surface crossings below it
/// along z, or in which a sample of a triangle (spaced at most half a voxel) lies.
Grid voxelize(const Mesh& mesh, int cells) {
    Grid g;
    const Aabb box = mesh.bounds();
    const Vec3 size = box.size();
    g.h = std::max({size.x, size.y, size.z}) / cells;
    for (int a = 0; a < 3; ++a) {
        g.n[a] = static_cast<int>(std::ceil(size[a] / g.h)) + 2;
        g.origin[a] = box.center()[a] - 0.5 * g.n[a] * g.h;
    }
    g.solid.assign(static_cast<std::size_t>(g.n[0]) * g.n[1] * g.n[2], 0);
    // Crossings of each column's ray (its centre, offset by an odd fraction of a voxel so that it misses the
    // mesh's edges and vertices) with the triangles.
    const double ox = 0.5 + 1.37e-5, oy = 0.5 + 2.91e-5;
    std::vector<std::vector<double>> hits(static_cast<std::size_t>(g.n[0]) * g.n[1]);
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
        const auto c = mesh.corners(t);
        double lo[2] = {c[0].x, c[0].y}, hi[2] = {c[0].x, c[0].y};
        for (int k = 1; k < 3; ++k) {
            lo[0] = std::min(lo[0], c[k].x), hi[0] = std::max(hi[0], c[k].x);
            lo[1] = std::min(lo[1], c[k].y), hi[1] = std::max(hi[1], c[k].y);
        }
        const int x0 = std::max(0, static_cast<int>(std::floor((lo[0] - g.origin.x) / g.h - ox)));
        const int x1 = std::min(g.n[0] - 1, static_cast<int>(std::ceil((hi[0] - g.origin.x) / g.h - ox)));
        const int y0 = std::max(0, static_cast<int>(std::floor((lo[1] - g.origin.y) / g.h - oy)));
        const int y1 = std::min(g.n[1] - 1, static_cast<int>(std::ceil((hi[1] - g.origin.y) / g.h - oy)));
        const Vec3 normal = cross(c[1] - c[0], c[2] - c[0]);
        if (normal.z == 0)
            continue; // parallel to the rays
        for (int x = x0; x <= x1; ++x)
            for (int y = y0; y <= y1; ++y) {
                const double px = g.origin.x + (x + ox) * g.h, py = g.origin.y + (y + oy) * g.h;
                // The ray passes through the triangle's projection when p lies on one side of all three
                // edges.
                double e[3];
                for (int k = 0; k < 3; ++k) {
                    const Vec3& a = c[k];
                    const Vec3& b = c[(k + 1) % 3];
                    e[k] = (b.x - a.x) * (py - a.y) - (b.y - a.y) * (px - a.x);
                }
                if (!((e[0] > 0 && e[1] > 0 && e[2] > 0) || (e[0] < 0 && e[1] < 0 && e[2] < 0)))
                    continue;
                const double z = c[0].z - (normal.x * (px - c[0].x) + normal.y * (py - c[0].y)) / normal.z;
                hits[static_cast<std::size_t>(x) * g.n[1] + y].push_back(z);
            }
    }
    for (int x = 0; x < g.n[0]; ++x)
        for (int y = 0; y < g.n[1]; ++y) {
            std::vector<double>& zs = hits[static_cast<std::size_t>(x) * g.n[1] + y];
            std::sort(zs.begin(), zs.end());
            std::size_t below = 0;
            for (int z = 0; z < g.n[2]; ++z) {
                const double zc = g.origin.z + (z + 0.5) * g.h;
                while (below < zs.size() && zs[below] < zc)
                    ++below;
                if (below % 2 == 1)
                    g.solid[g.index(x, y, z)] = 1;
            }
        }
    // Voxels the surface passes through.
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
        const auto c = mesh.corners(t);
        const double edge = std::max({length(c[1] - c[0]), length(c[2] - c[1]), length(c[0] - c[2])});
        const int steps = std::max(1, static_cast<int>(std::ceil(edge / (0.5 * g.h))));
        for (int i = 0; i <= steps; ++i)
            for (int j = 0; i + j <= steps; ++j) {
                const Vec3 p =
                    c[0] + (c[1] - c[0]) * (double(i) / steps) + (c[2] - c[0]) * (double(j) / steps);
                g.solid[g.index(g.cellOf(p.x, 0), g.cellOf(p.y, 1), g.cellOf(p.z, 2))] = 1;
            }
    }
    return g;
}

/// The box shrunk to the solid voxels in it, and their count (0: none, box unchanged).
std::size_t tighten(const Grid& g, Box& box) {
    Box t;
    t.lo = box.hi;
    t.hi = box.lo;
    std::size_t count = 0;
    for (int x = box.lo[0]; x < box.hi[0]; ++x)
        for (int y = box.lo[1]; y < box.hi[1]; ++y) {
            const std::uint8_t* column = &g.solid[g.index(x, y, 0)];
            for (int z = box.lo[2]; z < box.hi[2]; ++z)
                if (column[z]) {
                    ++count;
                    const int at[3] = {x, y, z};
                    for (int a = 0; a < 3; ++a) {
                        t.lo[a] = std::min(t.lo[a], at[a]);
                        t.hi[a] = std::max(t.hi[a], at[a] + 1);
                    }
                }
        }
    if (count > 0)
        box = t;
    return count;
}

/// The hull of the solid voxels in a box: of the corners of the lowest and highest solid voxel of each
/// column (the voxels between lie in their hull); with a stride above 1, of every stride-th column along x
/// and y and the box's last ones (a cheaper, smaller hull that ranks the split planes).
std::optional<ConvexPolytope> voxelHull(const Grid& g, const Box& box, int stride = 1) {
    std::vector<std::uint64_t> keys; // corners as 21-bit grid coordinates
    auto key = [](int x, int y, int z) {
        return (static_cast<std::uint64_t>(x) << 42) | (static_cast<std::uint64_t>(y) << 21) |
               static_cast<std::uint64_t>(z);
    };
    for (int x = box.lo[0]; x < box.hi[0]; ++x) {
        if ((x - box.lo[0]) % stride != 0 && x != box.hi[0] - 1)
            continue;
        for (int y = box.lo[1]; y < box.hi[1]; ++y) {
            if ((y - box.lo[1]) % stride != 0 && y != box.hi[1] - 1)
                continue;
            const std::uint8_t* column = &g.solid[g.index(x, y, 0)];
            int z0 = box.lo[2];
            while (z0 < box.hi[2] && !column[z0])
                ++z0;
            if (z0 == box.hi[2])
                continue;
            int z1 = box.hi[2] - 1;
            while (!column[z1])
                --z1;
            for (int dx = 0; dx < 2; ++dx)
                for (int dy = 0; dy < 2; ++dy) {
                    keys.push_back(key(x + dx, y + dy, z0));
                    keys.push_back(key(x + dx, y + dy, z1 + 1));
                }
        }
    }
    std::sort(keys.begin(), keys.end());
    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
    std::vector<Vec3> points;
    points.reserve(keys.size());
    const std::uint64_t mask = (1u << 21) - 1;
    for (std::uint64_t k : keys)
        points.push_back(g.origin + Vec3{double(k >> 42), double((k >> 21) & mask), double(k & mask)} * g.h);
    auto hull = convexHull(points);
    if (!hull)
        return std::nullopt;
    return std::move(hull.value());
}

struct VoxelPart {
    Box box;
    std::size_t voxels = 0;
    ConvexPolytope hull;
    double error = 0; // hull volume over the voxels' volume
    bool done = false;
};

} // namespace

Result<Decomposition> voxelDecompose(const Mesh& mesh, const VoxelParams& params) {
    if (params.cells < 2 || params.cells > 1024 || params.maxParts < 1 || params.planesPerAxis < 1 ||
        params.rankStride < 1)
        return makeError(ErrorCode::InvalidInput,
                         "voxelDecompose: cells in [2, 1024], maxParts, planesPerAxis and "
                         "rankStride at least 1");
    Decomposition out;
    out.meshVolume = signedVolume(mesh);
    if (mesh.triangles.empty() || !(out.meshVolume > 0))
        return makeError(ErrorCode::InvalidInput,
                         "voxelDecompose: the mesh must be closed with positive volume");
    const Grid g = voxelize(mesh, params.cells);
    const double voxelVolume = g.h * g.h * g.h;
    auto makePart = [&](Box box, int stride) -> std::optional<VoxelPart> {
        VoxelPart p;
        p.voxels = tighten(g, box);
        if (p.voxels == 0)
            return std::nullopt;
        p.box = box;
        auto hull = voxelHull(g, box, stride);
        if (!hull)
            return std::nullopt;
        p.hull = std::move(*hull);
        p.error = p.hull.volume() - static_cast<double>(p.voxels) * voxelVolume;
        return p;
    };
    Box all;
    all.hi = {g.n[0], g.n[1], g.n[2]};
    auto root = makePart(all, 1);
    if (!root)
        return makeError(ErrorCode::GeometryFailure, "voxelDecompose: no solid voxels");
    const double stop = params.volumeError * static_cast<double>(root->voxels) * voxelVolume;
    std::vector<VoxelPart> parts;
    parts.push_back(std::move(*root));
    while (static_cast<int>(parts.size()) < params.maxParts) {
        int worst = -1;
        for (std::size_t i = 0; i < parts.size(); ++i)
            if (!parts[i].done && parts[i].error > stop && (worst < 0 || parts[i].error > parts[worst].error))
                worst = static_cast<int>(i);
        if (worst < 0)
            break;
        const Box box = parts[worst].box;
        std::optional<std::pair<Box, Box>> best;
        double bestScore = 0;
        for (int a = 0; a < 3; ++a) {
            const int extent = box.hi[a] - box.lo[a];
            int last = box.lo[a];
            for (int k = 1; k <= params.planesPerAxis; ++k) {
                const int at = box.lo[a] +
                               static_cast<int>(std::lround(double(extent) * k / (params.planesPerAxis + 1)));
                if (at <= last || at >= box.hi[a])
                    continue;
                last = at;
                Box lo = box, hi = box;
                lo.hi[a] = at;
                hi.lo[a] = at;
                auto l = makePart(lo, params.rankStride);
                auto r = l ? makePart(hi, params.rankStride) : std::nullopt;
                if (!l || !r)
                    continue;
                const double score = l->hull.volume() + r->hull.volume();
                if (!best || score < bestScore) {
                    bestScore = score;
                    best.emplace(lo, hi);
                }
            }
        }
        auto l = best ? makePart(best->first, 1) : std::nullopt;
        auto r = best ? makePart(best->second, 1) : std::nullopt;
        if (!l || !r) {
            parts[worst].done = true;
            continue;
        }
        parts[worst] = std::move(*l);
        parts.push_back(std::move(*r));
    }
    for (VoxelPart& p : parts) {
        out.hullVolume += p.hull.volume();
        out.parts.push_back(std::move(p.hull));
    }
    return out;
}

} // namespace rubble::bench
