#include <gtest/gtest.h>

#include <cmath>

#include "rubble/structure/Material.hpp"

using namespace rubble;

TEST(Material, PresetsAreTheSixNamedOnesInOrder) {
    const char* names[] = {"concrete", "brick", "stone", "wood", "glass", "steel"};
    ASSERT_EQ(materialPresets().size(), 6u);
    for (std::size_t i = 0; i < 6; ++i) {
        EXPECT_EQ(materialPresets()[i].name, names[i]);
        ASSERT_NE(findMaterial(names[i]), nullptr);
        EXPECT_EQ(findMaterial(names[i])->name, names[i]);
    }
    EXPECT_EQ(findMaterial("Concrete"), nullptr);
    EXPECT_EQ(findMaterial(""), nullptr);
    EXPECT_EQ(defaultMaterial().name, "concrete");
    EXPECT_EQ(materialNames(), "concrete, brick, stone, wood, glass, steel");
}

TEST(Material, ValuesArePhysicallyConsistent) {
    for (const Material& m : materialPresets()) {
        EXPECT_GT(m.density, 300) << m.name;
        EXPECT_LT(m.density, 8000) << m.name;
        EXPECT_GT(m.tensileStrength, 0) << m.name;
        EXPECT_GT(m.shearStrength, 0) << m.name;
        // Brittle materials and timber are stronger in compression than in tension; steel equally so.
        EXPECT_GE(m.compressiveStrength, m.tensileStrength) << m.name;
    }
    // Steel: shear yield by von Mises, fy / sqrt(3) (EN 1993-1-1, 6.2.6).
    const Material& steel = *findMaterial("steel");
    EXPECT_NEAR(steel.shearStrength, steel.tensileStrength / std::sqrt(3.0), 1.0);
    EXPECT_EQ(findMaterial("glass")->pattern, FracturePattern::Radial);
    EXPECT_EQ(findMaterial("wood")->pattern, FracturePattern::Splinter);
    EXPECT_EQ(findMaterial("concrete")->pattern, FracturePattern::Clustered);
}
