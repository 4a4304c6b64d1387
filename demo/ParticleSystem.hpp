#pragma once
/// \file ParticleSystem.hpp
/// CPU particles for sparks, dust and tiny debris, drawn by the renderer's instanced particle pass.

#include <cstdint>
#include <vector>

#include "Math.hpp"
#include "Renderer.hpp"

namespace demo {

/// Fixed-step particle simulation with a hard cap (oldest particles are recycled first).
class ParticleSystem {
public:
    /// Kinds of particles.
    enum class Kind { Spark, Dust, Chunk, Trail };
    /// Emits one particle.
    void emit(Kind kind, const V3& pos, const V3& vel, float life, float size, float r, float g, float b);
    /// A burst at an impact: sparks, dust and chunks around point, pushed along normal.
    void impactBurst(const V3& point, const V3& normal, float strength, std::uint32_t seed);
    /// A dust cloud for a retired debris piece of the given size.
    void debrisPuff(const V3& center, const V3& vel, float radius, std::uint32_t seed);
    /// Advances by dt seconds; groundY is the height particles settle on.
    void step(float dt, float groundY);
    /// Queues all particles for drawing.
    void draw(Renderer& renderer) const;
    /// Live particle count.
    std::size_t size() const { return parts_.size(); }
    /// Removes all particles.
    void clear() { parts_.clear(); }
    /// Maximum number of live particles.
    std::size_t cap = 6000;
    /// Share of dust particles emitted (software GL: fewer, denser puffs, since blended overdraw is its
    /// cost).
    float dustDensity = 1.0f;

private:
    struct P {
        V3 pos, vel;
        float life = 1, age = 0, size = 0.2f;
        float r = 1, g = 1, b = 1;
        Kind kind = Kind::Dust;
    };
    std::vector<P> parts_;
    std::uint32_t rng_ = 12345;
    float rnd(std::uint32_t& s) const;
};

} // namespace demo
