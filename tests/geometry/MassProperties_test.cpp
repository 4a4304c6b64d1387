#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "rubble/core/Random.hpp"
#include "rubble/geometry/MassProperties.hpp"

using namespace rubble;

namespace {
// An L-shaped prism: the polygon (0,0)-(2,0)-(2,1)-(1,1)-(1,2)-(0,2) in xy, extruded from z=0 to z=1.
Mesh lShape() {
    Mesh m;
    m.positions = {{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {1, 1, 0}, {1, 2, 0}, {0, 2, 0},
                   {0, 0, 1}, {2, 0, 1}, {2, 1, 1}, {1, 1, 1}, {1, 2, 1}, {0, 2, 1}};
    auto quad = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d) {
        m.triangles.push_back({a, b, c});
        m.triangles.push_back({a, c, d});
    };
    quad(0, 3, 2, 1); // bottom (z=0, outward -z), as two convex quads
    quad(0, 5, 4, 3);
    quad(6, 7, 8, 9); // top (z=1, outward +z)
    quad(6, 9, 10, 11);
    for (std::uint32_t i = 0; i < 6; ++i) { // sides
        const std::uint32_t a = i, b = (i + 1) % 6;
        quad(a, b, b + 6, a + 6);
    }
    return m;
}
} // namespace

TEST(MassProperties, UnitBoxMatchesAnalyticValues) {
    const Mesh box = makeBox({-1, -2, -3}, {1, 2, 3}); // 2 x 4 x 6
    const MassProperties mp = computeMassProperties(box);
    EXPECT_NEAR(mp.volume, 48.0, 1e-12);
    EXPECT_NEAR(mp.centerOfMass.x, 0.0, 1e-12);
    EXPECT_NEAR(mp.centerOfMass.y, 0.0, 1e-12);
    EXPECT_NEAR(mp.centerOfMass.z, 0.0, 1e-12);
    // I_xx = m (b² + c²) / 12 with edge lengths a=2, b=4, c=6 and m = 48.
    EXPECT_NEAR(mp.inertia.m[0][0], 48.0 * (16 + 36) / 12, 1e-9);
    EXPECT_NEAR(mp.inertia.m[1][1], 48.0 * (4 + 36) / 12, 1e-9);
    EXPECT_NEAR(mp.inertia.m[2][2], 48.0 * (4 + 16) / 12, 1e-9);
    EXPECT_NEAR(mp.inertia.m[0][1], 0.0, 1e-9);
    EXPECT_NEAR(mp.inertia.m[1][2], 0.0, 1e-9);
    EXPECT_NEAR(mp.principalMoments.x, 48.0 * 20 / 12, 1e-9);
    EXPECT_NEAR(mp.principalMoments.z, 48.0 * 52 / 12, 1e-9);
}

TEST(MassProperties, SubdividedBoxHasSameVolumeAsCoarseBox) {
    for (int n : {1, 3, 7, 15}) {
        const Mesh box = makeSubdividedBox({-1, -1, -1}, {1, 1, 1}, n);
        EXPECT_EQ(box.triangleCount(), static_cast<std::size_t>(12 * n * n));
        EXPECT_NEAR(computeMassProperties(box).volume, 8.0, 1e-12) << n;
    }
}

TEST(MassProperties, TetrahedronMatchesAnalyticValues) {
    Mesh t;
    t.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    t.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
    const MassProperties mp = computeMassProperties(t);
    EXPECT_NEAR(mp.volume, 1.0 / 6.0, 1e-15);
    EXPECT_NEAR(mp.centerOfMass.x, 0.25, 1e-15);
    EXPECT_NEAR(mp.centerOfMass.y, 0.25, 1e-15);
    EXPECT_NEAR(mp.centerOfMass.z, 0.25, 1e-15);
    // Tonon (2004): for this tetrahedron about its centroid, I_xx = m·(3/80)·... ; with density 1:
    // ∫(y²+z²)dV about origin = 2·(1/60) = 1/30; shift by m·(cy²+cz²) = (1/6)(1/8) = 1/48.
    EXPECT_NEAR(mp.inertia.m[0][0], 1.0 / 30.0 - 1.0 / 48.0, 1e-15);
    // Product: -∫xy dV about origin = -1/120; shifted: -(1/120 - m·cx·cy) = -(1/120 - 1/96).
    EXPECT_NEAR(mp.inertia.m[0][1], -(1.0 / 120.0 - 1.0 / 96.0), 1e-15);
}

TEST(MassProperties, LShapeVolumeAndCentroid) {
    const MassProperties mp = computeMassProperties(lShape());
    // Box [0,2]x[0,1]x[0,1] (volume 2, centroid (1,.5,.5)) + box [0,1]x[1,2]x[0,1] (volume 1, centroid
    // (.5,1.5,.5)).
    EXPECT_NEAR(mp.volume, 3.0, 1e-12);
    EXPECT_NEAR(mp.centerOfMass.x, (2 * 1.0 + 0.5) / 3, 1e-12);
    EXPECT_NEAR(mp.centerOfMass.y, (2 * 0.5 + 1.5) / 3, 1e-12);
    EXPECT_NEAR(mp.centerOfMass.z, 0.5, 1e-12);
}

TEST(MassProperties, InvariantUnderTranslationAndRotation) {
    const Mesh l = lShape();
    const MassProperties ref = computeMassProperties(l);
    Rng rng(7);
    for (int i = 0; i < 20; ++i) {
        const Mat3 rot = rng.rotation();
        const Vec3 shift = rng.inBox({-1e5, -1e5, -1e5}, {1e5, 1e5, 1e5});
        const MassProperties mp = computeMassProperties(l.transformed(rot, {1, 1, 1}, shift));
        EXPECT_NEAR(mp.volume, ref.volume, 1e-9 * ref.volume);
        const Vec3 expected = rot * ref.centerOfMass + shift;
        EXPECT_NEAR(length(mp.centerOfMass - expected), 0.0, 1e-9);
        // Principal moments are rotation invariant.
        EXPECT_NEAR(mp.principalMoments.x, ref.principalMoments.x, 1e-8);
        EXPECT_NEAR(mp.principalMoments.y, ref.principalMoments.y, 1e-8);
        EXPECT_NEAR(mp.principalMoments.z, ref.principalMoments.z, 1e-8);
        // I' = R I Rᵀ.
        const Mat3 expectedI = rot * ref.inertia * rot.transposed();
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b)
                EXPECT_NEAR(mp.inertia.m[a][b], expectedI.m[a][b], 1e-8);
    }
}

TEST(MassProperties, FineSphereApproachesAnalyticVolumeAndInertia) {
    const double r = 2.0;
    const Mesh s = makeSphere({3, -1, 2}, r, 256, 128);
    const MassProperties mp = computeMassProperties(s);
    const double v = 4.0 / 3.0 * std::numbers::pi * r * r * r;
    EXPECT_NEAR(mp.volume, v, 2e-3 * v);
    EXPECT_NEAR(length(mp.centerOfMass - Vec3{3, -1, 2}), 0.0, 1e-9);
    const double I = 0.4 * v * r * r;
    for (int a = 0; a < 3; ++a)
        EXPECT_NEAR(mp.inertia.m[a][a], I, 4e-3 * I);
}

TEST(MassProperties, PrincipalAxesDiagonaliseTheTensor) {
    Rng rng(3);
    const Mesh box = makeBox({0, 0, 0}, {1, 2, 5}).transformed(rng.rotation(), {1, 1, 1}, {4, 5, 6});
    const MassProperties mp = computeMassProperties(box);
    const Mat3 d = mp.principalAxes.transposed() * mp.inertia * mp.principalAxes;
    EXPECT_NEAR(d.m[0][1], 0.0, 1e-9);
    EXPECT_NEAR(d.m[0][2], 0.0, 1e-9);
    EXPECT_NEAR(d.m[1][2], 0.0, 1e-9);
    EXPECT_NEAR(d.m[0][0], mp.principalMoments.x, 1e-9);
    EXPECT_LE(mp.principalMoments.x, mp.principalMoments.y);
    EXPECT_LE(mp.principalMoments.y, mp.principalMoments.z);
    // Proper rotation: determinant +1.
    const Mat3& R = mp.principalAxes;
    const double det = dot(R.column(0), cross(R.column(1), R.column(2)));
    EXPECT_NEAR(det, 1.0, 1e-12);
}

TEST(MassProperties, InvertedMeshHasNegativeVolume) {
    Mesh box = makeBox({0, 0, 0}, {1, 1, 1});
    for (auto& t : box.triangles)
        std::swap(t[1], t[2]);
    EXPECT_NEAR(signedVolume(box), -1.0, 1e-12);
}

TEST(MassProperties, TorusVolume) {
    const double R = 3, r = 1;
    const Mesh t = makeTorus({0, 0, 0}, R, r, 256, 128);
    const double v = 2 * std::numbers::pi * std::numbers::pi * R * r * r;
    EXPECT_NEAR(signedVolume(t), v, 2e-3 * v);
}
