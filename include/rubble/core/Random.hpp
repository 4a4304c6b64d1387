#pragma once
/// \file Random.hpp
/// A small deterministic random generator: the same seed gives the same numbers on every platform.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "rubble/core/Export.hpp"
#include "rubble/core/Vec3.hpp"

namespace rubble {

/// SplitMix64 generator with platform-independent distributions (std distributions are not portable).
class RUBBLE_API Rng {
public:
    /// A generator seeded with seed.
    explicit Rng(std::uint64_t seed = 0) : state_(seed) {}
    /// Next raw 64-bit value.
    std::uint64_t next() {
        std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    /// Uniform double in [0, 1).
    double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
    /// Uniform double in [a, b).
    double uniform(double a, double b) { return a + (b - a) * uniform(); }
    /// Uniform integer in [0, n) for n > 0.
    std::uint64_t below(std::uint64_t n) { return next() % n; }
    /// Uniform point in the axis-aligned box [lo, hi).
    Vec3 inBox(const Vec3& lo, const Vec3& hi) {
        return {uniform(lo.x, hi.x), uniform(lo.y, hi.y), uniform(lo.z, hi.z)};
    }
    /// Uniform unit vector.
    Vec3 unitVector() {
        const double z = uniform(-1.0, 1.0);
        const double phi = uniform(0.0, 2.0 * std::numbers::pi);
        const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
        return {r * std::cos(phi), r * std::sin(phi), z};
    }
    /// Uniform random rotation matrix (from a uniform unit quaternion).
    Mat3 rotation() {
        const double u1 = uniform(), u2 = uniform(0.0, 2.0 * std::numbers::pi),
                     u3 = uniform(0.0, 2.0 * std::numbers::pi);
        const double a = std::sqrt(1 - u1), b = std::sqrt(u1);
        const double w = a * std::sin(u2), x = a * std::cos(u2), y = b * std::sin(u3), z = b * std::cos(u3);
        Mat3 r;
        r.m[0][0] = 1 - 2 * (y * y + z * z);
        r.m[0][1] = 2 * (x * y - z * w);
        r.m[0][2] = 2 * (x * z + y * w);
        r.m[1][0] = 2 * (x * y + z * w);
        r.m[1][1] = 1 - 2 * (x * x + z * z);
        r.m[1][2] = 2 * (y * z - x * w);
        r.m[2][0] = 2 * (x * z - y * w);
        r.m[2][1] = 2 * (y * z + x * w);
        r.m[2][2] = 1 - 2 * (x * x + y * y);
        return r;
    }

private:
    std::uint64_t state_;
};

/// Mixes two 64-bit values into one (for deriving per-job seeds from a world seed).
inline std::uint64_t mixSeed(std::uint64_t a, std::uint64_t b) {
    Rng r(a ^ (b * 0x9E3779B97F4A7C15ull + 0x632BE59BD9B4E019ull));
    return r.next();
}

} // namespace rubble
