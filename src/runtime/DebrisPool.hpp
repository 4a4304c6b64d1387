#pragma once
// Particles: pieces too small (or one too many) to simulate, drawn for a while and then gone.

#include <vector>

#include "rubble/runtime/DestructionRuntime.hpp"

namespace rubble::detail {

/// The particles of a runtime, moved ballistically until their lifetime runs out.
class DebrisPool {
public:
    /// Adds a particle.
    void add(const DebrisParticle& p) { particles_.push_back(p); }
    /// Adds particles.
    void add(const std::vector<DebrisParticle>& ps) {
        particles_.insert(particles_.end(), ps.begin(), ps.end());
    }
    /// Moves every particle under gravity for dt and drops the expired ones.
    void advance(double dt, const Vec3& gravity);
    /// The particles still drawn.
    const std::vector<DebrisParticle>& particles() const { return particles_; }

private:
    std::vector<DebrisParticle> particles_;
};

} // namespace rubble::detail
