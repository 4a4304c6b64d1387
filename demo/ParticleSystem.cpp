#include "ParticleSystem.hpp"

#include <algorithm>
#include <cmath>

namespace demo {

float ParticleSystem::rnd(std::uint32_t& s) const {
    s = s * 1664525u + 1013904223u;
    return static_cast<float>((s >> 8) & 0xFFFFFF) / 16777215.0f;
}

void ParticleSystem::emit(Kind kind, const V3& pos, const V3& vel, float life, float size, float r, float g,
                          float b) {
    if (parts_.size() >= cap) {
        // Recycle the oldest particle relative to its life.
        auto it = std::max_element(parts_.begin(), parts_.end(),
                                   [](const P& x, const P& y) { return x.age / x.life < y.age / y.life; });
        parts_.erase(it);
    }
    P p;
    p.kind = kind;
    p.pos = pos;
    p.vel = vel;
    p.life = life;
    p.size = size;
    p.r = r;
    p.g = g;
    p.b = b;
    parts_.push_back(p);
}

void ParticleSystem::impactBurst(const V3& point, const V3& normal, float strength, std::uint32_t seed) {
    std::uint32_t s = seed * 2654435761u + 17;
    const V3 n = norm(normal);
    const int sparks = 18 + static_cast<int>(strength * 10);
    for (int i = 0; i < sparks; ++i) {
        V3 d{rnd(s) * 2 - 1, rnd(s) * 2 - 1, rnd(s) * 2 - 1};
        d = norm(d + n * 1.2f);
        emit(Kind::Spark, point, d * ((12 + 22 * rnd(s)) * std::sqrt(strength)), 0.25f + 0.35f * rnd(s),
             (0.25f + 0.25f * rnd(s)) * std::sqrt(strength), 1.0f, 0.55f + 0.3f * rnd(s), 0.15f);
    }
    const int dust = std::max(1, static_cast<int>(std::lround((10 + strength * 8) * dustDensity)));
    for (int i = 0; i < dust; ++i) {
        V3 d{rnd(s) * 2 - 1, rnd(s) * 2 - 1, rnd(s) * 2 - 1};
        d = norm(d + n);
        const float grey = 0.55f + 0.2f * rnd(s);
        emit(Kind::Dust, point + d * 0.5f * strength, d * ((1.5f + 4 * rnd(s)) * strength),
             1.6f + 1.6f * rnd(s), (1.2f + 1.8f * rnd(s)) * strength, grey, grey * 0.95f, grey * 0.88f);
    }
    const int chunks = 6 + static_cast<int>(strength * 6);
    for (int i = 0; i < chunks; ++i) {
        V3 d{rnd(s) * 2 - 1, rnd(s) * 2 - 1, rnd(s) * 2 - 1};
        d = norm(d + n * 1.5f);
        const float grey = 0.35f + 0.2f * rnd(s);
        emit(Kind::Chunk, point, d * (6 + 10 * rnd(s)), 2.5f + 2 * rnd(s), 0.1f + 0.18f * rnd(s), grey,
             grey * 0.92f, grey * 0.85f);
    }
}

void ParticleSystem::debrisPuff(const V3& center, const V3& vel, float radius, std::uint32_t seed) {
    std::uint32_t s = seed * 747796405u + 3;
    for (int i = 0; i < 6; ++i) {
        V3 d{rnd(s) * 2 - 1, rnd(s) * 2 - 1, rnd(s) * 2 - 1};
        const float grey = 0.4f + 0.2f * rnd(s);
        emit(Kind::Chunk, center + d * radius, vel + d * 3.0f, 2 + 2 * rnd(s),
             std::clamp(radius * 0.5f, 0.1f, 0.35f), grey, grey * 0.9f, grey * 0.85f);
    }
    const int dust = std::max(1, static_cast<int>(std::lround(3 * dustDensity)));
    for (int i = 0; i < dust; ++i) {
        V3 d{rnd(s) * 2 - 1, rnd(s), rnd(s) * 2 - 1};
        emit(Kind::Dust, center + d * radius, vel * 0.3f + d, 1.5f + rnd(s), 1.0f + radius * 2, 0.6f, 0.58f,
             0.55f);
    }
}

void ParticleSystem::step(float dt, float groundY) {
    for (auto& p : parts_) {
        p.age += dt;
        switch (p.kind) {
        case Kind::Spark:
            p.vel.y -= 9.81f * dt;
            p.vel = p.vel * std::exp(-2.0f * dt);
            break;
        case Kind::Dust:
            p.vel = p.vel * std::exp(-1.5f * dt);
            p.vel.y += 0.6f * dt;
            p.size += dt * 1.4f;
            break;
        case Kind::Chunk:
            p.vel.y -= 9.81f * dt;
            break;
        case Kind::Trail:
            p.vel = p.vel * std::exp(-3.0f * dt);
            break;
        }
        p.pos += p.vel * dt;
        if (p.pos.y < groundY + p.size * 0.5f && p.kind != Kind::Dust) {
            p.pos.y = groundY + p.size * 0.5f;
            p.vel = V3{p.vel.x * 0.5f, -p.vel.y * 0.3f, p.vel.z * 0.5f};
        }
    }
    parts_.erase(std::remove_if(parts_.begin(), parts_.end(), [](const P& p) { return p.age >= p.life; }),
                 parts_.end());
}

void ParticleSystem::draw(Renderer& renderer) const {
    for (const auto& p : parts_) {
        const float t = p.age / p.life;
        Particle q;
        q.pos = p.pos;
        q.size = p.size;
        q.r = p.r;
        q.g = p.g;
        q.b = p.b;
        switch (p.kind) {
        case Kind::Spark:
            q.a = 1.0f - t;
            q.size = p.size * (1.0f - 0.5f * t);
            renderer.addParticle(q, true);
            break;
        case Kind::Trail:
            q.a = (1.0f - t) * 0.8f;
            renderer.addParticle(q, true);
            break;
        case Kind::Dust:
            q.a = std::min(0.9f, 0.55f / std::sqrt(dustDensity)) * (1.0f - t) * std::min(1.0f, t * 8.0f);
            renderer.addParticle(q, false);
            break;
        case Kind::Chunk:
            q.a = t > 0.8f ? (1.0f - t) * 5.0f : 1.0f;
            renderer.addParticle(q, false);
            break;
        }
    }
}

} // namespace demo
