#pragma once
/// \file DebrisParticle.hpp
/// A retired piece, drawn as a particle instead of being simulated.

#include "rubble/Vec3.hpp"

namespace rubble::bullet {

/// A piece too small (or one too many) to keep as a rigid body: the demo draws it as a particle. Its volume
/// stays counted in DestructionBridge::retiredVolume().
struct DebrisParticle {
    Vec3 position;       ///< world position (m)
    Vec3 velocity;       ///< world velocity (m/s)
    double size = 0;     ///< edge length of a cube of the same volume (m)
    double volume = 0;   ///< volume of the retired piece (m³)
    double lifetime = 0; ///< seconds left to draw it
};

} // namespace rubble::bullet
