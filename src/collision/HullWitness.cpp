#include "collision/HullWitness.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "collision/MeshRegion.hpp"
#include "geometry/ClosestPoint.hpp"
#include "rubble/collision/ConvexDecomposition.hpp"

namespace rubble::detail {

namespace {

/// Most cells of a witness grid along one axis.
constexpr int kMaxRowCells = 256;
/// Most buckets of large triangles along one axis.
constexpr int kMaxBuckets = 32;

/// Distance from p to the segment ab.
double segmentDistance(const Vec3& p, const Vec3& a, const Vec3& b) {
    const Vec3 ab = b - a;
    const double len2 = lengthSquared(ab);
    const double t = len2 > 0 ? std::clamp(dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
    return length(p - (a + ab * t));
}

} // namespace

std::vector<std::uint8_t> usedVertices(const Mesh& mesh) {
    std::vector<std::uint8_t> used(mesh.positions.size(), 0);
    for (const Triangle& t : mesh.triangles)
        for (std::uint32_t v : t)
            used[v] = 1;
    return used;
}

HullWitness::HullWitness(const Mesh& mesh, double reach)
    : mesh_(mesh), reach_(reach), used_(mesh.positions.size(), 0) {
    // One pass over the triangles: the used vertices, and the triangles longer than reach (crossRows).
    const double reach2 = reach * reach;
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
        const Triangle& tri = mesh.triangles[t];
        used_[tri[0]] = used_[tri[1]] = used_[tri[2]] = 1;
        const Vec3 &p0 = mesh.positions[tri[0]], &p1 = mesh.positions[tri[1]], &p2 = mesh.positions[tri[2]];
        const double longest =
            std::max({lengthSquared(p1 - p0), lengthSquared(p2 - p1), lengthSquared(p0 - p2)});
        if (longest > reach2)
            large_.push_back(t);
    }
    for (std::size_t v = 0; v < mesh.positions.size(); ++v)
        if (used_[v])
            box_.extend(mesh.positions[v]);
    if (box_.empty() || !(reach > 0)) {
        large_.clear();
        return;
    }
    // Rows half of reach across: a point near the hull finds a row's segment near it among a few rows.
    const Vec3 extent = box_.size();
    for (int a = 0; a < 3; ++a) {
        cells_[a] =
            static_cast<int>(std::clamp(std::ceil(extent[a] / (0.5 * reach)), 1.0, double(kMaxRowCells)));
        cell_[a] = std::max(extent[a] / cells_[a], 1e-300);
    }
    for (int a = 0; a < 3; ++a) {
        const int b = (a + 1) % 3, c = (a + 2) % 3;
        rows_[a].assign(static_cast<std::size_t>(cells_[b]) * static_cast<std::size_t>(cells_[c]), Span{});
    }
    for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
        if (!used_[v])
            continue;
        const Vec3& p = mesh.positions[v];
        const int cell[3] = {cellOf(0, p.x), cellOf(1, p.y), cellOf(2, p.z)};
        for (int a = 0; a < 3; ++a) {
            const int b = (a + 1) % 3, c = (a + 2) % 3;
            rows_[a][static_cast<std::size_t>(cell[b]) * cells_[c] + cell[c]].add(
                p[a], static_cast<std::uint32_t>(v));
        }
    }
    for (std::size_t t : large_) {
        const auto c = mesh.corners(t);
        for (int a = 0; a < 3; ++a)
            crossRows(a, c[0], c[1], c[2]);
    }
}

void HullWitness::crossRows(int a, const Vec3& p0, const Vec3& p1, const Vec3& p2) {
    const int b = (a + 1) % 3, c = (a + 2) % 3;
    // The triangle projected along axis a: (b, c) coordinates of its edges and twice its signed area.
    const double p0b = p0[b], p0c = p0[c];
    const double e1b = p1[b] - p0b, e1c = p1[c] - p0c, e2b = p2[b] - p0b, e2c = p2[c] - p0c;
    const double area = e1b * e2c - e2b * e1c;
    if (std::abs(area) <= 1e-12 * lengthSquared(p1 - p0 + p2 - p0))
        return;
    const int b0 = cellOf(b, std::min({p0b, p1[b], p2[b]})), b1 = cellOf(b, std::max({p0b, p1[b], p2[b]}));
    const int c0 = cellOf(c, std::min({p0c, p1[c], p2[c]})), c1 = cellOf(c, std::max({p0c, p1[c], p2[c]}));
    const Vec3 e1 = p1 - p0, e2 = p2 - p0;
    const double loB = box_.lo[b], loC = box_.lo[c], cellB = cell_[b], cellC = cell_[c];
    for (int i = b0; i <= b1; ++i) {
        const double du = (loB + (i + 0.5) * cellB) - p0b;
        const double du2 = du * e2c, du1 = du * e1c;
        for (int j = c0; j <= c1; ++j) {
            const double dv = (loC + (j + 0.5) * cellC) - p0c;
            const double w1 = (du2 - e2b * dv) / area;
            const double w2 = (e1b * dv - du1) / area;
            if (w1 < 0 || w2 < 0 || w1 + w2 > 1)
                continue;
            const Vec3 q = p0 + e1 * w1 + e2 * w2; // on the triangle
            rows_[a][static_cast<std::size_t>(i) * cells_[c] + j].add(
                q[a], static_cast<std::uint32_t>(mesh_.positions.size() + crossings_.size()));
            crossings_.push_back(q);
        }
    }
}

void HullWitness::buildBuckets() const {
    // Triangles longer than reach, in buckets of a coarse grid by their bounds grown by reach.
    const std::vector<std::size_t> large = std::move(large_);
    large_.clear();
    bucketBox_ = box_;
    bucketBox_.lo -= Vec3{reach_, reach_, reach_};
    bucketBox_.hi += Vec3{reach_, reach_, reach_};
    buckets_ = std::clamp(static_cast<int>(std::cbrt(static_cast<double>(large.size()))), 1, kMaxBuckets);
    const std::size_t count = static_cast<std::size_t>(buckets_) * buckets_ * buckets_;
    bucketStart_.assign(count + 1, 0);
    // Two passes over the triangles' buckets: counts, then places (a counting sort).
    auto forBuckets = [&](std::size_t t, auto&& visit) {
        Aabb b;
        for (const Vec3& p : mesh_.corners(t))
            b.extend(p);
        int lo[3], hi[3];
        for (int a = 0; a < 3; ++a) {
            lo[a] = bucketOf(a, b.lo[a] - reach_);
            hi[a] = bucketOf(a, b.hi[a] + reach_);
        }
        for (int x = lo[0]; x <= hi[0]; ++x)
            for (int y = lo[1]; y <= hi[1]; ++y)
                for (int z = lo[2]; z <= hi[2]; ++z)
                    visit(static_cast<std::size_t>((x * buckets_ + y) * buckets_ + z));
    };
    for (std::size_t t : large)
        forBuckets(t, [&](std::size_t k) { ++bucketStart_[k + 1]; });
    for (std::size_t k = 0; k < count; ++k)
        bucketStart_[k + 1] += bucketStart_[k];
    large_.resize(bucketStart_[count]);
    std::vector<std::uint32_t> next(bucketStart_.begin(), bucketStart_.end() - 1);
    for (std::size_t t : large)
        forBuckets(t, [&](std::size_t k) { large_[next[k]++] = t; });
}

int HullWitness::bucketOf(int axis, double x) const {
    const double extent = std::max(bucketBox_.hi[axis] - bucketBox_.lo[axis], 1e-300);
    const double i = std::floor((x - bucketBox_.lo[axis]) / extent * buckets_);
    return static_cast<int>(std::clamp(i, 0.0, double(buckets_ - 1)));
}

int HullWitness::cellOf(int axis, double x) const {
    const double i = std::floor((x - box_.lo[axis]) / cell_[axis]);
    return static_cast<int>(std::clamp(i, 0.0, double(cells_[axis] - 1)));
}

bool HullWitness::near(const Vec3& p) const {
    if (box_.empty())
        return false;
    // The segment between a row's extreme vertices lies in the hull; rows across within reach of p.
    for (int a = 0; a < 3; ++a) {
        const int b = (a + 1) % 3, c = (a + 2) % 3;
        const Span& own = rows_[a][static_cast<std::size_t>(cellOf(b, p[b])) * cells_[c] + cellOf(c, p[c])];
        if (own.set() && segmentDistance(p, pointOf(own.lo), pointOf(own.hi)) <= reach_)
            return true;
    }
    for (int a = 0; a < 3; ++a) {
        const int b = (a + 1) % 3, c = (a + 2) % 3;
        const int b0 = cellOf(b, p[b] - reach_), b1 = cellOf(b, p[b] + reach_);
        const int c0 = cellOf(c, p[c] - reach_), c1 = cellOf(c, p[c] + reach_);
        for (int i = b0; i <= b1; ++i)
            for (int j = c0; j <= c1; ++j) {
                const Span& s = rows_[a][static_cast<std::size_t>(i) * cells_[c] + j];
                if (s.set() && segmentDistance(p, pointOf(s.lo), pointOf(s.hi)) <= reach_)
                    return true;
            }
    }
    if (!bucketsBuilt_) {
        buildBuckets();
        bucketsBuilt_ = true;
    }
    if (bucketStart_.empty() || !bucketBox_.contains(p))
        return false;
    const std::size_t k =
        (static_cast<std::size_t>(bucketOf(0, p.x)) * buckets_ + bucketOf(1, p.y)) * buckets_ +
        bucketOf(2, p.z);
    for (std::uint32_t i = bucketStart_[k]; i < bucketStart_[k + 1]; ++i) {
        const auto c = mesh_.corners(large_[i]);
        if (length(p - closestOnTriangle(p, c[0], c[1], c[2])) <= reach_)
            return true;
    }
    return false;
}

namespace {

/// The hull of the points' extremes in n directions spread over the sphere: inside the points' hull, with at
/// most 2n − 4 faces.
Result<ConvexPolytope> hullOfExtremes(const std::vector<Vec3>& points, std::size_t n) {
    std::vector<Vec3> extremes;
    for (std::size_t k = 0; k < n; ++k) {
        const Vec3 d = sphereDirection(k, n);
        std::size_t best = 0;
        for (std::size_t i = 1; i < points.size(); ++i)
            if (dot(d, points[i]) > dot(d, points[best]))
                best = i;
        if (std::find(extremes.begin(), extremes.end(), points[best]) == extremes.end())
            extremes.push_back(points[best]);
    }
    return convexHull(extremes);
}

} // namespace

std::size_t keepNearHull(std::vector<ConvexPolytope>& parts, const Mesh& mesh, double reach,
                         std::size_t maxFaces, const ConvexPolytope* hull) {
    if (parts.empty())
        return 0;
    std::optional<HullWitness> witness;
    if (!hull)
        witness.emplace(mesh, reach);
    auto near = [&](const Vec3& c) {
        if (witness)
            return witness->near(c);
        for (const PolytopeFaceView& f : hull->faces())
            if (f.plane.signedDistance(c) > reach)
                return false;
        return true;
    };
    std::vector<std::uint8_t> used;
    std::vector<ConvexPolytope> kept;
    kept.reserve(parts.size());
    std::size_t replaced = 0;
    for (ConvexPolytope& part : parts) {
        std::vector<Vec3> points = part.vertices();
        const auto far = std::partition(points.begin(), points.end(), [&](const Vec3& c) { return near(c); });
        if (far == points.end()) {
            kept.push_back(std::move(part));
            continue;
        }
        // The hull of the proven corners and the vertices inside the part: within reach of the mesh's hull.
        ++replaced;
        points.erase(far, points.end());
        const Aabb b = part.bounds();
        const double eps = 1e-9 * (b.diagonal() + 1e-300);
        if (used.empty())
            used = witness ? witness->used() : usedVertices(mesh);
        // Vertices inside the proven corners' hull add nothing to it: only the others are kept.
        std::optional<ConvexPolytope> proven;
        if (points.size() >= 4)
            if (auto h = convexHull(points))
                proven = std::move(h.value());
        for (std::size_t v = 0; v < mesh.positions.size(); ++v)
            if (used[v] && b.contains(mesh.positions[v]) && part.contains(mesh.positions[v], eps) &&
                !(proven && proven->contains(mesh.positions[v])))
                points.push_back(mesh.positions[v]);
        auto shape = convexHull(points);
        if (shape && shape->faces().size() > maxFaces)
            shape = hullOfExtremes(points, std::max<std::size_t>(maxFaces / 2, 4));
        if (shape)
            kept.push_back(std::move(shape.value()));
    }
    parts = std::move(kept);
    return replaced;
}

} // namespace rubble::detail
