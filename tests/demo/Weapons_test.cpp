// The game's weapons: keys, the autopilot's cycle, and which hits chip and which shatter under the demo's
// law.
#include <gtest/gtest.h>

#include "Weapons.hpp"

namespace demo {
namespace {

using rubble::CellPattern;

// What the adaptive pattern cuts on a 6 x 3 x 0.3 m wall hit with `impulse`.
rubble::ImpactCut wallCut(double impulse) {
    rubble::FractureParams params;
    params.pattern = CellPattern::Adaptive;
    params.sizeLaw = demoSizeLaw(CellPattern::Adaptive);
    return rubble::impactCut(params, rubble::Aabb{{0, 0, 0}, {6, 3, 0.3}}, impulse);
}

double muzzleImpulse(Weapon w, double jetSpeed) {
    const WeaponSpec& s = weaponSpec(w);
    return s.mass * (s.speed + jetSpeed);
}

TEST(Weapons, DigitKeysSelectTheThreeWeapons) {
    EXPECT_EQ(weaponForDigit(1), static_cast<int>(Weapon::Cannon));
    EXPECT_EQ(weaponForDigit(2), static_cast<int>(Weapon::HeavyShell));
    EXPECT_EQ(weaponForDigit(3), static_cast<int>(Weapon::Charge));
    EXPECT_EQ(weaponForDigit(0), -1);
    EXPECT_EQ(weaponForDigit(4), -1);
}

TEST(Weapons, TheAutopilotFiresEachWeaponInTurn) {
    int fired[kWeaponCount] = {};
    for (int shot = 0; shot < 12; ++shot)
        ++fired[static_cast<int>(autopilotWeapon(shot))];
    for (int n : fired)
        EXPECT_EQ(n, 4);
    EXPECT_EQ(autopilotWeapon(0), Weapon::Cannon);
    EXPECT_EQ(autopilotWeapon(2), Weapon::HeavyShell);
    EXPECT_EQ(autopilotWeapon(4), Weapon::Charge);
    EXPECT_EQ(autopilotWeapon(6), Weapon::Cannon);
    EXPECT_EQ(autopilotWeapon(-3), Weapon::Cannon);
}

TEST(Weapons, TheCannonChipsAndTheHeavyShellAndTheChargeShatter) {
    for (double jet : {0.0, 90.0}) { // hovering and at full speed
        EXPECT_EQ(wallCut(muzzleImpulse(Weapon::Cannon, jet)).pattern, CellPattern::SingleCell) << jet;
        EXPECT_EQ(wallCut(muzzleImpulse(Weapon::HeavyShell, jet)).pattern, CellPattern::Shatter) << jet;
    }
    const WeaponSpec& charge = weaponSpec(Weapon::Charge);
    ASSERT_GT(charge.blastRadius, 0);
    EXPECT_EQ(wallCut(charge.blastImpulse).pattern, CellPattern::Shatter) << "at the blast's centre";
    EXPECT_EQ(wallCut(0.4 * charge.blastImpulse).pattern, CellPattern::SingleCell) << "at its edge it chips";
}

TEST(Weapons, AHarderHitCutsABiggerDomain) {
    double last = 0;
    for (double impulse : {0.0, 200.0, 680.0, 1500.0, 1700.0, 6000.0, 20000.0}) {
        const double size = wallCut(impulse).size;
        EXPECT_GE(size, last) << impulse;
        last = size;
    }
    EXPECT_LE(last, demoSizeLaw(CellPattern::Adaptive).maxSize);
    EXPECT_GT(wallCut(muzzleImpulse(Weapon::HeavyShell, 0)).size,
              2 * wallCut(muzzleImpulse(Weapon::Cannon, 0)).size)
        << "a heavy shell takes a visible chunk";
}

} // namespace
} // namespace demo
