#pragma once
/// \file Autopilot.hpp
/// Scripted pilot for headless runs: flies toward the nearest standing object, shoots when lined up,
/// pulls away before a collision and keeps clear of the ground; cycles the weapons, two shots each.
/// Deterministic given the game state.

#include "Game.hpp"

namespace demo {

/// Produces control input from the game state.
class Autopilot {
public:
    /// Input for the next step of dt seconds.
    ControlInput update(const Game& game, float dt);

private:
    V3 target_;
    bool hasTarget_ = false;
    float evade_ = 0;
    float evadeYaw_ = 1;
    float retarget_ = 0;
};

} // namespace demo
