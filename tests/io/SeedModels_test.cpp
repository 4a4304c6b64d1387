// Verdicts of the mesh check on the thesis's models (verified by hand, see docs/robustness.md): all nine seed
// OBJ files are closed, 2-manifold, consistently outward oriented and free of self-intersections.
#include <gtest/gtest.h>

#include "TestSupport.hpp"
#include "rubble/geometry/MeshCheck.hpp"
#include "rubble/io/MeshIO.hpp"

using namespace rubble;

namespace {
struct Expected {
    const char* file;
    std::size_t vertices;
    std::size_t triangles;
    double volume;
};
} // namespace

TEST(SeedModels, AllSeedObjFilesAreValidSolids) {
    RUBBLE_REQUIRE_SEED_MEDIA(media);
    const Expected expected[] = {
        {"building.obj", 32, 60, 3484.41185}, {"cube_12.obj", 8, 12, 8.0},
        {"cube_108.obj", 56, 108, 8.0},       {"cube_588.obj", 296, 588, 8.0},
        {"cube_2700.obj", 1352, 2700, 8.0},   {"cube_10092.obj", 5048, 10092, 8.0},
        {"empty.obj", 69, 138, 16.5553358},   {"missile.obj", 73, 142, 274.801677},
        {"ship.obj", 54, 104, 4915199.87},
    };
    for (const Expected& e : expected) {
        const auto mesh = readMesh(media / e.file);
        ASSERT_TRUE(mesh.isOk()) << mesh.error().message;
        const MeshReport r = checkMesh(mesh.value());
        std::string problems;
        for (const std::string& p : r.problems)
            problems += p + "\n";
        EXPECT_TRUE(r.valid()) << e.file << "\n" << problems;
        EXPECT_EQ(r.vertices, e.vertices) << e.file;
        EXPECT_EQ(r.triangles, e.triangles) << e.file;
        EXPECT_TRUE(r.selfIntersectionsChecked) << e.file;
        EXPECT_EQ(r.selfIntersections, 0u) << e.file;
        EXPECT_NEAR(r.volume, e.volume, 1e-4 * e.volume) << e.file;
    }
}

TEST(SeedModels, MultiMaterialModelsKeepTheirMaterialNames) {
    RUBBLE_REQUIRE_SEED_MEDIA(media);
    const auto missile = readObj(media / "missile.obj");
    ASSERT_TRUE(missile.isOk()) << missile.error().message;
    ASSERT_TRUE(missile->hasMaterials());
    EXPECT_EQ(missile->materialNames.front(), "mediumred_0");
    EXPECT_EQ(missile->materialNames.size(), 7u);
    const auto objects = readObjObjects(media / "ship.obj");
    ASSERT_TRUE(objects.isOk());
    ASSERT_EQ(objects->size(), 1u);
    EXPECT_EQ((*objects)[0].name, "mothership_mothership_2");
}
