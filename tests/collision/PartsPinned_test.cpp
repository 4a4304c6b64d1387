// The decomposition update's parts, pinned (as GoldenHash pins the world's geometry): fixed chains of
// fractures of fixed meshes must give these parts to the byte, in the gcc build and the clang sanitizer build
// alike. A change of this value changes the collision shape of every piece: update it only on purpose, and
// say why (docs/collision.md).
#include <gtest/gtest.h>

#include <bit>
#include <cmath>

#include "rubble/collision/ConvexDecomposition.hpp"
#include "rubble/core/Random.hpp"
#include "rubble/fracture/Fracture.hpp"
#include "rubble/geometry/MassProperties.hpp"

namespace rubble {
namespace {

constexpr std::uint64_t kExpectedPartsHash = 0x202F62372B1D2F63ull;

std::uint64_t mixParts(std::uint64_t h, const std::vector<ConvexPolytope>& parts) {
    h = mixSeed(h, parts.size());
    for (const ConvexPolytope& p : parts)
        for (const PolytopeFaceView& f : p.faces()) {
            for (double x : {f.plane.normal.x, f.plane.normal.y, f.plane.normal.z, f.plane.offset})
                h = mixSeed(h, std::bit_cast<std::uint64_t>(x));
            for (const Vec3& c : f.corners)
                for (double x : {c.x, c.y, c.z})
                    h = mixSeed(h, std::bit_cast<std::uint64_t>(x));
        }
    return h;
}

TEST(PartsPinned, ChainsOfFracturesGiveThePinnedParts) {
    // A subdivided box (convex: the merge guard at work on its craters), a torus and a sphere; one cell and a
    // shatter pattern; three hits each, every one on the largest piece of the one before.
    const std::vector<Mesh> meshes = {makeSubdividedBox({-1, -1, -1}, {1, 1, 1}, 6),
                                      makeTorus({0, 0, 0}, 2, 0.7, 32, 16),
                                      makeSphere({0, 0, 0}, 1.5, 24, 12)};
    std::uint64_t h = 1469598103934665603ull;
    int updates = 0;
    for (const Mesh& mesh : meshes)
        for (const CellPattern pattern : {CellPattern::SingleCell, CellPattern::Shatter}) {
            auto d = decompose(mesh);
            ASSERT_TRUE(d);
            Mesh current = mesh;
            std::vector<ConvexPolytope> parts = d->parts;
            FractureParams fp;
            fp.pattern = pattern;
            fp.cells = 12;
            fp.sizeLaw.base = 0.35 * mesh.bounds().diagonal();
            fp.sizeLaw.scale = 0;
            for (int hit = 0; hit < 3; ++hit) {
                const Aabb b = current.bounds();
                Impact impact;
                impact.point = {b.hi.x - 0.02 * b.size().x, b.center().y + 0.15 * (hit - 1) * b.size().y,
                                b.center().z};
                impact.normal = {1, 0, 0};
                auto r = fracture(current, impact, fp, 100 + static_cast<std::uint64_t>(hit));
                ASSERT_TRUE(r) << r.error().message;
                const auto updated = updateDecomposition(parts, *r);
                ASSERT_EQ(updated.size(), r->pieces.size());
                for (const auto& piece : updated)
                    h = mixParts(h, piece);
                ++updates;
                std::size_t largest = 0;
                for (std::size_t i = 1; i < r->pieces.size(); ++i)
                    if (std::abs(r->pieces[i].mass.volume) > std::abs(r->pieces[largest].mass.volume))
                        largest = i;
                current = r->pieces[largest].mesh;
                parts = updated[largest];
            }
        }
    EXPECT_EQ(updates, 18);
    EXPECT_EQ(h, kExpectedPartsHash) << std::hex << "parts hash 0x" << h;
}

} // namespace
} // namespace rubble
