#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <string>
#include <tuple>

#include "TestSupport.hpp"
#include "geometry/PseudoAngle.hpp"
#include "rubble/core/Random.hpp"
#include "rubble/geometry/ConvexPolytope.hpp"
#include "rubble/geometry/MassProperties.hpp"
#include "rubble/geometry/MeshCheck.hpp"

using namespace rubble;

namespace {
// A random plane through a point inside the box lo..hi.
Plane randomPlane(Rng& rng, const Vec3& lo, const Vec3& hi) {
    return Plane::fromPointNormal(rng.inBox(lo, hi), rng.unitVector());
}
} // namespace

TEST(ConvexPolytope, BoxHasExactVolumeCentroidAndMesh) {
    const auto p = ConvexPolytope::fromAabb({{-1, 0, 2}, {3, 1, 5}});
    EXPECT_FALSE(p.empty());
    EXPECT_NEAR(p.volume(), 4 * 1 * 3, 1e-12);
    const Vec3 c = p.centroid();
    EXPECT_NEAR(c.x, 1, 1e-12);
    EXPECT_NEAR(c.y, 0.5, 1e-12);
    EXPECT_NEAR(c.z, 3.5, 1e-12);
    EXPECT_EQ(p.vertices().size(), 8u);
    EXPECT_TRUE(p.contains({0, 0.5, 3}));
    EXPECT_FALSE(p.contains({0, 1.5, 3}));
    const Mesh m = p.toMesh();
    const MeshReport r = checkMesh(m);
    EXPECT_TRUE(r.valid()) << test::joinLines(r.problems);
    EXPECT_NEAR(r.volume, 12, 1e-12);
}

TEST(ConvexPolytope, ClippingByRandomPlanesConservesVolume) {
    Rng rng(2024);
    const Vec3 lo{-1, -2, -0.5}, hi{2, 1, 1.5};
    const auto box = ConvexPolytope::fromAabb({lo, hi});
    const double whole = box.volume();
    for (int i = 0; i < 300; ++i) {
        const Plane plane = randomPlane(rng, lo, hi);
        const ConvexPolytope in = box.clipped(plane, 7);
        const ConvexPolytope out = box.clippedOutside(plane, 8);
        EXPECT_NEAR(in.volume() + out.volume(), whole, 1e-9 * whole) << "plane " << i;
        for (const ConvexPolytope* part : {&in, &out}) {
            if (part->empty())
                continue;
            const Mesh m = part->toMesh();
            const MeshReport r = checkMesh(m);
            EXPECT_TRUE(r.closed) << "plane " << i << "\n" << test::joinLines(r.problems);
            EXPECT_TRUE(r.oriented) << "plane " << i << "\n" << test::joinLines(r.problems);
            EXPECT_TRUE(r.outward) << "plane " << i;
            EXPECT_NEAR(r.volume, part->volume(), 1e-9 * whole) << "plane " << i;
        }
        // The cap face carries the tag of the plane that made it.
        bool tagged = false;
        for (const auto& f : in.faces())
            tagged = tagged || f.tag == 7;
        EXPECT_TRUE(in.empty() || tagged);
    }
}

TEST(ConvexPolytope, RepeatedClippingMakesClosedCellsThatTileTheBox) {
    // Split a box by several random planes into all sign combinations; the cells tile the box.
    Rng rng(99);
    const Vec3 lo{0, 0, 0}, hi{1, 1, 1};
    std::vector<ConvexPolytope> cells{ConvexPolytope::fromAabb({lo, hi})};
    for (int k = 0; k < 5; ++k) {
        const Plane plane = randomPlane(rng, lo, hi);
        std::vector<ConvexPolytope> next;
        for (const auto& c : cells) {
            for (const ConvexPolytope& part : {c.clipped(plane, k), c.clippedOutside(plane, k)})
                if (!part.empty())
                    next.push_back(part);
        }
        cells = std::move(next);
    }
    double total = 0;
    for (const auto& c : cells) {
        total += c.volume();
        const MeshReport r = checkMesh(c.toMesh());
        EXPECT_TRUE(r.closed && r.oriented && r.outward) << test::joinLines(r.problems);
        EXPECT_EQ(r.nonManifoldEdges, 0u);
    }
    EXPECT_GT(cells.size(), 5u);
    EXPECT_NEAR(total, 1.0, 1e-9);
}

TEST(ConvexPolytope, PlanesMissingTheBoxKeepOrEmptyIt) {
    const auto box = ConvexPolytope::fromAabb({{0, 0, 0}, {1, 1, 1}});
    const Plane far = Plane::fromPointNormal({5, 0, 0}, {1, 0, 0}); // box entirely on the inner side
    EXPECT_NEAR(box.clipped(far).volume(), 1.0, 1e-12);
    EXPECT_TRUE(box.clippedOutside(far).empty());
    const Plane face = Plane::fromPointNormal({1, 0, 0}, {1, 0, 0}); // coincides with a face
    EXPECT_NEAR(box.clipped(face).volume(), 1.0, 1e-12);
    EXPECT_TRUE(box.clippedOutside(face).empty());
}

TEST(ConvexPolytope, MassPropertiesOfClippedMeshMatchThePolytope) {
    Rng rng(5);
    const auto box = ConvexPolytope::fromAabb({{-2, -2, -2}, {2, 2, 2}});
    for (int i = 0; i < 50; ++i) {
        const ConvexPolytope part = box.clipped(randomPlane(rng, {-1, -1, -1}, {1, 1, 1}));
        if (part.empty())
            continue;
        const MassProperties mp = computeMassProperties(part.toMesh());
        const Vec3 c = part.centroid();
        EXPECT_NEAR(mp.volume, part.volume(), 1e-9);
        EXPECT_NEAR(mp.centerOfMass.x, c.x, 1e-9);
        EXPECT_NEAR(mp.centerOfMass.y, c.y, 1e-9);
        EXPECT_NEAR(mp.centerOfMass.z, c.z, 1e-9);
    }
}

namespace {
bool sameBits(const Vec3& a, const Vec3& b) {
    return std::bit_cast<std::array<std::uint64_t, 3>>(a) == std::bit_cast<std::array<std::uint64_t, 3>>(b);
}

// Faces equal bit for bit: planes, corners in order, tags.
void expectSameFaces(const std::vector<PolytopeFace>& a, const std::vector<PolytopeFace>& b,
                     const std::string& where) {
    ASSERT_EQ(a.size(), b.size()) << where;
    for (std::size_t i = 0; i < a.size(); ++i) {
        EXPECT_TRUE(sameBits(a[i].plane.normal, b[i].plane.normal)) << where << " face " << i;
        EXPECT_EQ(std::bit_cast<std::uint64_t>(a[i].plane.offset),
                  std::bit_cast<std::uint64_t>(b[i].plane.offset))
            << where << " face " << i;
        EXPECT_EQ(a[i].tag, b[i].tag) << where << " face " << i;
        ASSERT_EQ(a[i].corners.size(), b[i].corners.size()) << where << " face " << i;
        for (std::size_t k = 0; k < a[i].corners.size(); ++k)
            EXPECT_TRUE(sameBits(a[i].corners[k], b[i].corners[k]))
                << where << " face " << i << " corner " << k;
    }
}

bool lexLess(const Vec3& a, const Vec3& b) {
    return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z);
}

// The clipping of faces that each hold their own corners: what a polytope of shared corners must reproduce.
std::vector<PolytopeFace> clippedFaces(const std::vector<PolytopeFace>& faces, const Plane& plane,
                                       std::int32_t tag, double eps) {
    Aabb b;
    for (const PolytopeFace& f : faces)
        for (const Vec3& c : f.corners)
            b.extend(c);
    const double tol = eps * std::max(1.0, std::max({std::abs(b.lo.x), std::abs(b.lo.y), std::abs(b.lo.z),
                                                     std::abs(b.hi.x), std::abs(b.hi.y), std::abs(b.hi.z)}));
    auto snapped = [&](const Vec3& p) {
        const double d = plane.signedDistance(p);
        return std::abs(d) <= tol ? 0 : d;
    };
    std::vector<PolytopeFace> out;
    std::vector<Vec3> cap;
    for (const PolytopeFace& f : faces) {
        PolytopeFace nf{f.plane, {}, f.tag};
        for (std::size_t i = 0; i < f.corners.size(); ++i) {
            Vec3 a = f.corners[i], c = f.corners[(i + 1) % f.corners.size()];
            double da = snapped(a), dc = snapped(c);
            if (da <= 0) {
                nf.corners.push_back(a);
                if (da == 0)
                    cap.push_back(a);
            }
            if ((da < 0 && dc > 0) || (da > 0 && dc < 0)) {
                if (lexLess(c, a)) { // from the lexicographically smaller end
                    std::swap(a, c);
                    std::swap(da, dc);
                }
                const Vec3 x = a + (c - a) * (da / (da - dc));
                nf.corners.push_back(x);
                cap.push_back(x);
            }
        }
        if (nf.corners.size() >= 3)
            out.push_back(std::move(nf));
    }
    std::sort(cap.begin(), cap.end(), lexLess);
    cap.erase(std::unique(cap.begin(), cap.end()), cap.end());
    if (cap.size() >= 3) {
        Vec3 center;
        for (const Vec3& p : cap)
            center += p;
        center = center / static_cast<double>(cap.size());
        const Vec3 n = plane.normal;
        const Vec3 u = normalized(std::abs(n.x) < 0.9 ? cross(n, Vec3{1, 0, 0}) : cross(n, Vec3{0, 1, 0}));
        const Vec3 v = cross(n, u);
        std::vector<std::pair<double, Vec3>> ordered;
        for (const Vec3& p : cap)
            ordered.emplace_back(detail::pseudoAngle(dot(p - center, u), dot(p - center, v)), p);
        std::sort(ordered.begin(), ordered.end(),
                  [](const auto& x, const auto& y) { return x.first < y.first; });
        PolytopeFace capFace{plane, {}, tag};
        for (const auto& [angle, p] : ordered)
            capFace.corners.push_back(p);
        out.push_back(std::move(capFace));
    }
    return out;
}
} // namespace

// A polytope keeps each corner once and a face as indices of them. Clipping again and again (as a Voronoi
// cell is made) must give, bit for bit, the faces that clipping faces with their own corners gives, and keep
// each corner once.
TEST(ConvexPolytope, SharedCornersClipBitForBitAsFacesWithTheirOwnCorners) {
    Rng rng(31);
    const Vec3 lo{-1.3, -0.7, 0.2}, hi{0.9, 1.1, 2.5};
    for (int cell = 0; cell < 40; ++cell) {
        ConvexPolytope p = ConvexPolytope::fromAabb({lo, hi});
        std::vector<PolytopeFace> reference = p.faceList();
        for (int k = 0; k < 12 && !p.empty(); ++k) {
            const Plane plane = randomPlane(rng, lo, hi);
            p = p.clipped(plane, k);
            reference = clippedFaces(reference, plane, k, 1e-12);
            const std::string where = "cell " + std::to_string(cell) + " clip " + std::to_string(k);
            if (p.empty())
                break;
            expectSameFaces(p.faceList(), reference, where);
            std::size_t uses = 0;
            for (const PolytopeFaceView& f : p.faces())
                uses += f.corners.size();
            EXPECT_EQ(p.corners().size(), p.vertices().size()) << where << ": each corner kept once";
            EXPECT_GE(uses, 3 * p.corners().size()) << where << ": every corner on three faces or more";
        }
        // moved rigidly and rebuilt from its faces, the faces stay exactly what they were
        Frame f;
        f.rotation = rng.rotation();
        f.translation = {0.25, -3, 1e3};
        if (!p.empty()) {
            const ConvexPolytope moved = p.transformed(f);
            EXPECT_EQ(moved.corners().size(), p.corners().size());
            for (std::size_t i = 0; i < p.faces().size(); ++i)
                for (std::size_t k = 0; k < p.faces()[i].corners.size(); ++k)
                    EXPECT_TRUE(sameBits(moved.faces()[i].corners[k], f.apply(p.faces()[i].corners[k])));
            expectSameFaces(ConvexPolytope::fromFaces(moved.faceList()).faceList(), moved.faceList(),
                            "rebuilt");
        }
    }
}

// Faces are shared where their corners' bits are equal, not where they compare equal: −0 and +0 stay apart,
// so a part read back from a file or a snapshot keeps every corner exactly.
TEST(ConvexPolytope, FromFacesSharesOnlyBitEqualCorners) {
    std::vector<PolytopeFace> faces = ConvexPolytope::fromAabb({{0, 0, 0}, {1, 1, 1}}).faceList();
    std::size_t negated = 0;
    for (Vec3& c : faces[0].corners) // the face x = 0: its corners at −0
        if (c.x == 0) {
            c.x = -0.0;
            ++negated;
        }
    ASSERT_EQ(negated, 4u);
    const ConvexPolytope p = ConvexPolytope::fromFaces(faces);
    expectSameFaces(p.faceList(), faces, "from faces");
    EXPECT_EQ(p.corners().size(), 12u); // 8 box corners, and the four of face 0 at −0 apart
    EXPECT_TRUE(std::signbit(p.faces()[0].corners[0].x));
    EXPECT_FALSE(std::signbit(p.faces()[2].corners[0].x)); // face y = 0 starts at (+0, 0, 0)
}
