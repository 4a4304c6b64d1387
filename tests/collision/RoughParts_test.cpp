// The convex parts of rough pieces (docs/roughness.md, "Mass and collision"): the runtime updates the flat
// cut's parts (the parent's parts clipped by the cells), so they stay within the roughness amplitude of the
// visible rough surface, both ways.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "TestSupport.hpp"
#include "rubble/collision/ConvexDecomposition.hpp"
#include "rubble/core/Random.hpp"
#include "rubble/fracture/Fracture.hpp"

namespace rubble {
namespace {

double segmentDistance(const Vec3& p, const Vec3& a, const Vec3& b) {
    const Vec3 ab = b - a;
    const double len2 = dot(ab, ab);
    const double t = len2 > 0 ? std::clamp(dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
    return length(p - (a + ab * t));
}

/// Distance from p to a convex polygon (corners in order, in a plane with this normal).
double polygonDistance(const Vec3& p, const std::vector<Vec3>& corners, const Vec3& normal) {
    const std::size_t n = corners.size();
    bool inside = n >= 3;
    double edges = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < n; ++i) {
        const Vec3 &a = corners[i], &b = corners[(i + 1) % n];
        inside &= dot(cross(b - a, p - a), normal) >= 0;
        edges = std::min(edges, segmentDistance(p, a, b));
    }
    return inside ? std::abs(dot(p - corners[0], normal)) : edges;
}

/// Euclidean distance from p to the solid convex part (0 inside).
double partDistance(const ConvexPolytope& part, const Vec3& p) {
    if (part.contains(p))
        return 0;
    double d = std::numeric_limits<double>::infinity();
    for (const PolytopeFaceView& f : part.faces())
        d = std::min(d, polygonDistance(p, {f.corners.begin(), f.corners.end()}, f.plane.normal));
    return d;
}

/// Distance from p to the triangle abc.
double triangleDistance(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
    const Vec3 n = normalized(cross(b - a, c - a));
    return polygonDistance(p, {a, b, c}, n);
}

/// Distance from p to the solid closed mesh (0 inside).
double meshDistance(const Mesh& m, const Vec3& p) {
    if (windingNumber(m, p) > 0.5)
        return 0;
    double d = std::numeric_limits<double>::infinity();
    for (std::size_t t = 0; t < m.triangles.size(); ++t) {
        const auto c = m.corners(t);
        d = std::min(d, triangleDistance(p, c[0], c[1], c[2]));
    }
    return d;
}

TEST(RoughParts, PartsAndRoughSurfaceStayWithinTheAmplitudeOfEachOther) {
    const Mesh cube = makeSubdividedBox({-1, -1, -1}, {1, 1, 1}, 4);
    auto d = decompose(cube);
    ASSERT_TRUE(d);
    Rng rng(5);
    for (int i = 0; i < 4; ++i) {
        SCOPED_TRACE("impact " + std::to_string(i));
        FractureParams fp;
        fp.pattern = i % 2 ? CellPattern::Shatter : CellPattern::SingleCell;
        fp.cells = 6;
        fp.sizeLaw.base = 1.4;
        fp.sizeLaw.scale = 0;
        fp.roughness = roughnessPreset("concrete");
        fp.roughness.relative = false; // absolute, so that the bound is known
        fp.roughness.amplitude = 0.08;
        fp.roughness.featureSize = 0.3;
        auto fr = fracture(cube, {test::surfacePoint(cube, rng), {1, 0, 0}, 1}, fp, rng.next());
        ASSERT_TRUE(fr) << fr.error().message;
        ASSERT_TRUE(fr->stats.rough);
        const auto parts = updateDecomposition(d->parts, *fr, DecompositionParams{});
        ASSERT_EQ(parts.size(), fr->pieces.size());
        const double amplitude = fp.roughness.amplitude, eps = 1e-9;
        double farVertex = 0, farCorner = 0, displaced = 0;
        for (std::size_t p = 0; p < parts.size(); ++p) {
            const Mesh& m = fr->pieces[p].mesh;
            for (const Vec3& v : m.positions) { // every rough vertex within the amplitude of the parts
                double near = std::numeric_limits<double>::infinity();
                for (const ConvexPolytope& part : parts[p])
                    near = std::min(near, partDistance(part, v));
                farVertex = std::max(farVertex, near);
            }
            for (const ConvexPolytope& part : parts[p]) // the parts within the amplitude of the rough piece
                for (const PolytopeFaceView& f : part.faces())
                    for (const Vec3& c : f.corners)
                        farCorner = std::max(farCorner, meshDistance(m, c));
            for (std::size_t t = 0; t < m.triangles.size(); ++t)
                if (m.materials[t] == kInteriorMaterial)
                    for (const Vec3& c : m.corners(t)) {
                        double near = std::numeric_limits<double>::infinity();
                        for (const ConvexPolytope& part : parts[p])
                            near = std::min(near, partDistance(part, c));
                        displaced = std::max(displaced, near);
                    }
        }
        std::printf("far vertex %.4f, far corner %.4f, displaced %.4f\n", farVertex, farCorner, displaced);
        EXPECT_LE(farVertex, amplitude + eps);
        EXPECT_LE(farCorner, amplitude + eps);
        EXPECT_GT(displaced, amplitude / 4); // the surface does leave the parts: the bound is not vacuous
    }
}

} // namespace
} // namespace rubble
