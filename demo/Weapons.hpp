#pragma once
/// \file Weapons.hpp
/// The player's three weapons (keys 1-3): what each fires, and the autopilot's weapon cycle.

#include <array>

#include "rubble/rubble.hpp"

namespace demo {

/// A weapon; the value is its index (key 1 + index).
enum class Weapon : int {
    Cannon = 0,     ///< today's shot: light, fast, chips (adaptive pattern below the shatter impulse)
    HeavyShell = 1, ///< a 40 kg shell: its impulse shatters and cuts a bigger domain
    Charge = 2,     ///< a demolition charge: blasts every object within its radius where it lands
};

/// How many weapons there are.
inline constexpr int kWeaponCount = 3;

/// What a weapon fires.
struct WeaponSpec {
    const char* name;       ///< HUD and report name
    float mass;             ///< kg (the cannon's follows the panel's projectile mass)
    float speed;            ///< m/s muzzle speed on top of the jet's
    float radius;           ///< m, projectile sphere
    float interval;         ///< s between shots while Space is held
    float blastRadius = 0;  ///< m, 0: no blast
    float blastImpulse = 0; ///< N·s at the blast's centre (falls off to 40 % at its edge)
};

/// The weapons' specifications.
inline constexpr std::array<WeaponSpec, kWeaponCount> kWeapons{{
    {"cannon", 4, 170, 0.35f, 0.14f},
    {"heavy shell", 40, 150, 0.6f, 0.6f},
    {"demolition charge", 20, 120, 0.5f, 1.0f, 8, 3500},
}};

/// The demo's cell-size law: adaptive, a cannon shell (under 1,600 N·s) chips a domain of 2-6 m and a
/// heavy shell or a charge shatters; the fixed patterns keep the thesis-sized law.
inline rubble::CellSizeLaw demoSizeLaw(rubble::CellPattern pattern) {
    const bool adaptive = pattern == rubble::CellPattern::Adaptive;
    rubble::CellSizeLaw law;
    law.base = adaptive ? 2.0 : 3.0;
    law.scale = adaptive ? 0.1 : 0.35;
    law.exponent = 0.5;
    law.maxSize = 30;
    return law;
}

/// The weapon's specification.
inline const WeaponSpec& weaponSpec(Weapon w) {
    return kWeapons[static_cast<unsigned>(w) % kWeaponCount];
}

/// The weapon a digit key selects ('1'..'3'), or -1 for any other key.
inline int weaponForDigit(int digit) {
    return digit >= 1 && digit <= kWeaponCount ? digit - 1 : -1;
}

/// The autopilot's weapon after `shots` shots: each weapon fires `perWeapon` shots in turn.
inline Weapon autopilotWeapon(int shots, int perWeapon = 2) {
    const int n = perWeapon > 0 ? perWeapon : 1;
    return static_cast<Weapon>((shots < 0 ? 0 : shots / n) % kWeaponCount);
}

} // namespace demo
