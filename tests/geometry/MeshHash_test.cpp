// Mesh::hash names a mesh's bytes: equal meshes hash equal (-0.0 as 0.0), and a change of any one value in
// any array, or of an array's length, changes it.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <set>

#include "TestSupport.hpp"
#include "geometry/FormerMeshHash.hpp"
#include "rubble/geometry/MeshCheck.hpp"

using namespace rubble;

namespace {

/// A sphere with per-corner normals, texture coordinates and materials.
Mesh attributedSphere() {
    Mesh m = test::unwelded(makeSphere({0.25, -0.5, 1}, 1.0, 7, 5), true);
    return m;
}

} // namespace

TEST(MeshHash, EqualMeshesHashEqualAndNegativeZeroIsZero) {
    const Mesh a = attributedSphere();
    Mesh b = a;
    EXPECT_EQ(a.hash(), b.hash());
    Mesh zero = makeBox({0, 0, 0}, {1, 1, 1});
    zero.computeFlatNormals();
    Mesh negative = zero;
    for (Vec3& p : negative.positions)
        for (int k = 0; k < 3; ++k)
            if (p[k] == 0)
                p[k] = -0.0;
    for (Vec3f& n : negative.normals)
        for (float* c : {&n.x, &n.y, &n.z})
            if (*c == 0)
                *c = -0.0f;
    ASSERT_NE(std::signbit(negative.positions[0].x), std::signbit(zero.positions[0].x));
    EXPECT_EQ(negative.hash(), zero.hash());
}

TEST(MeshHash, EveryValueAndEveryLengthCounts) {
    const Mesh base = attributedSphere();
    ASSERT_TRUE(base.hasNormals() && base.hasUvs() && base.hasMaterials());
    std::set<std::uint64_t> seen{base.hash()};
    std::size_t edits = 0;
    auto expectNew = [&](const Mesh& m, const std::string& what) {
        ++edits;
        EXPECT_TRUE(seen.insert(m.hash()).second) << what;
    };
    for (std::size_t i = 0; i < base.positions.size(); ++i)
        for (int k = 0; k < 3; ++k) {
            Mesh m = base;
            m.positions[i][k] = std::nextafter(m.positions[i][k], 2.0);
            expectNew(m, "position " + std::to_string(i));
        }
    for (std::size_t t = 0; t < base.triangles.size(); ++t) {
        Mesh m = base;
        std::swap(m.triangles[t][0], m.triangles[t][1]);
        expectNew(m, "triangle " + std::to_string(t));
    }
    for (std::size_t i = 0; i < base.normals.size(); ++i) {
        Mesh m = base;
        m.normals[i].z = std::nextafter(m.normals[i].z, 2.0f);
        expectNew(m, "normal " + std::to_string(i));
        Mesh u = base;
        u.uvs[i].x = std::nextafter(u.uvs[i].x, 2.0f);
        expectNew(u, "uv " + std::to_string(i));
    }
    for (std::size_t t = 0; t < base.materials.size(); ++t) {
        Mesh m = base;
        m.materials[t] += 1;
        expectNew(m, "material " + std::to_string(t));
    }
    Mesh noUvs = base;
    noUvs.uvs.clear();
    expectNew(noUvs, "no uvs");
    Mesh zeroUvs = base;
    for (Vec2f& u : zeroUvs.uvs)
        u = Vec2f{0, 0};
    expectNew(zeroUvs, "zero uvs");
    Mesh extra = base;
    extra.positions.push_back(Vec3{});
    expectNew(extra, "an unused vertex");
    EXPECT_EQ(seen.size(), edits + 1);
}

// Stable across runs, builds and platforms: snapshots and decomposition files carry it.
TEST(MeshHash, PinnedForAFixedMesh) {
    EXPECT_EQ(attributedSphere().hash(), 0x034f2be20bd036eeull);
    // The former FNV-1a, which version-1 decomposition files name their mesh by.
    EXPECT_EQ(detail::formerMeshHash(attributedSphere()), 0xb8a8419ca1a680b7ull);
}
