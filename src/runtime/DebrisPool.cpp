#include "runtime/DebrisPool.hpp"

namespace rubble::detail {

void DebrisPool::advance(double dt, const Vec3& gravity) {
    for (DebrisParticle& p : particles_) {
        p.velocity += gravity * dt;
        p.position += p.velocity * dt;
        p.lifetime -= dt;
    }
    std::erase_if(particles_, [](const DebrisParticle& p) { return p.lifetime <= 0; });
}

} // namespace rubble::detail
