#include "Sound.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <map>
#include <memory>
#include <mutex>

#include "rubble/structure/Material.hpp"

namespace demo {
namespace {

constexpr float kPi = 3.14159265358979f;

/// A decaying sine partial.
struct Partial {
    float hz = 0;    ///< frequency
    float decay = 0; ///< s to fall to 1/e
    float amp = 0;   ///< amplitude
};

/// How to synthesise one clip: partials plus low-passed noise, struck once or as a train of grains.
struct Recipe {
    float seconds = 0.3f;          ///< clip length
    std::vector<Partial> partials; ///< ringing modes
    float noiseAmp = 0;            ///< noise amplitude
    float noiseDecay = 0.05f;      ///< s
    float lowpass = 0.5f;          ///< one-pole coefficient of the noise (0: dark .. 1: white)
    int grains = 1;                ///< strikes (a break is a train of them)
    float grainSpread = 0;         ///< s over which the strikes after the first fall
};

/// A small deterministic generator (LCG) for noise and grain times.
struct Lcg {
    std::uint32_t s;
    float next() { // in [-1, 1)
        s = s * 1664525u + 1013904223u;
        return static_cast<float>(s >> 8) / 8388608.0f - 1.0f;
    }
};

std::vector<float> synthesise(const Recipe& r, int rate, std::uint32_t seed) {
    const auto n = static_cast<std::size_t>(r.seconds * static_cast<float>(rate));
    const double dt = 1.0 / rate;
    std::vector<float> out(n, 0.0f);
    Lcg rng{seed};
    // each partial is a damped phasor: one complex multiply per sample
    std::vector<std::complex<double>> z(r.partials.size()), w(r.partials.size());
    for (int g = 0; g < r.grains; ++g) {
        // grains after the first come later and softer, thinning out (a crumble)
        const float u = g == 0 ? 0.0f : (rng.next() + 1.0f) * 0.5f;
        const auto start = static_cast<std::size_t>(u * u * r.grainSpread * static_cast<float>(rate));
        const double level = g == 0 ? 1.0 : 0.35 + 0.4 * (1.0 - u);
        const double detune = g == 0 ? 1.0 : 0.8 + 0.4 * (rng.next() + 1.0f) * 0.5f;
        double longest = r.noiseDecay;
        for (std::size_t p = 0; p < r.partials.size(); ++p) {
            const Partial& q = r.partials[p];
            z[p] = level * q.amp;
            w[p] = std::exp(std::complex<double>(-dt / q.decay, 2 * kPi * q.hz * detune * dt));
            longest = std::max(longest, static_cast<double>(q.decay));
        }
        const auto stop = std::min(n, start + static_cast<std::size_t>(8 * longest * rate)); // -70 dB
        double noise = level * r.noiseAmp;
        const double noiseFall = std::exp(-dt / r.noiseDecay);
        float lp = 0;
        for (std::size_t i = start; i < stop; ++i) {
            double v = 0;
            for (std::size_t p = 0; p < z.size(); ++p) {
                v += z[p].imag();
                z[p] *= w[p];
            }
            lp += r.lowpass * (rng.next() - lp);
            v += noise * lp;
            noise *= noiseFall;
            out[i] += static_cast<float>(v);
        }
    }
    // 2 ms fade in and out (no clicks), then peak 1
    const std::size_t fade = std::min(n / 2, static_cast<std::size_t>(rate / 500));
    for (std::size_t i = 0; i < fade; ++i) {
        const float k = static_cast<float>(i) / static_cast<float>(fade);
        out[i] *= k;
        out[n - 1 - i] *= k;
    }
    float peak = 0;
    for (float v : out)
        peak = std::max(peak, std::abs(v));
    if (peak > 0)
        for (float& v : out)
            v /= peak;
    return out;
}

Recipe recipe(SoundKind kind, Timbre timbre) {
    Recipe r;
    switch (timbre) {
    case Timbre::Stone:
        r.partials = {{65, 0.09f, 1.0f}, {140, 0.05f, 0.4f}};
        r.noiseAmp = 1.2f;
        r.lowpass = 0.25f;
        break;
    case Timbre::Glass:
        r.partials = {{2100, 0.25f, 0.6f}, {3350, 0.18f, 0.5f}, {5230, 0.12f, 0.4f}};
        r.noiseAmp = 0.5f;
        r.noiseDecay = 0.02f;
        r.lowpass = 0.9f;
        break;
    case Timbre::Wood:
        r.partials = {{180, 0.06f, 0.8f}, {420, 0.04f, 0.5f}, {910, 0.02f, 0.3f}};
        r.noiseAmp = 0.7f;
        r.noiseDecay = 0.03f;
        r.lowpass = 0.5f;
        break;
    case Timbre::Metal:
        r.partials = {{320, 0.7f, 0.7f}, {857, 0.5f, 0.5f}, {1432, 0.35f, 0.35f}, {2210, 0.25f, 0.25f}};
        r.noiseAmp = 0.4f;
        r.noiseDecay = 0.02f;
        r.lowpass = 0.6f;
        break;
    }
    switch (kind) {
    case SoundKind::Impact:
        r.seconds = timbre == Timbre::Metal ? 1.2f : 0.5f;
        break;
    case SoundKind::Break: // a crumble: many strikes over most of a second
        r.seconds = timbre == Timbre::Metal ? 1.8f : 1.3f;
        r.grains = 28;
        r.grainSpread = 0.8f;
        r.noiseDecay *= 2;
        break;
    case SoundKind::Debris: // a short knock, duller than an impact
        r.seconds = 0.25f;
        r.lowpass *= 0.6f;
        r.noiseDecay *= 0.6f;
        for (Partial& p : r.partials)
            p.decay *= 0.4f;
        break;
    case SoundKind::Collapse: // a rumble: an octave down, dark noise, strikes over more than a second
        r.seconds = 2.4f;
        r.grains = 40;
        r.grainSpread = 1.6f;
        r.noiseDecay *= 4;
        r.lowpass *= 0.4f;
        for (Partial& p : r.partials) {
            p.hz *= 0.5f;
            p.decay *= 2;
        }
        break;
    }
    return r;
}

/// Reference impulse (N·s) of each kind: at it, loudness is the kind's base level.
constexpr std::array<float, kSoundKinds> kReferenceImpulse{680.0f, 1000.0f, 2000.0f, 20000.0f};
/// Base level of each kind.
constexpr std::array<float, kSoundKinds> kBaseLevel{0.8f, 1.0f, 0.45f, 1.0f};
/// Within this distance (m) a sound is not attenuated; beyond, it falls as 1/d.
constexpr float kNearDistance = 15.0f;
/// Master gain of the mix (several loud voices sum to more than 1 before the clamp).
constexpr float kMaster = 0.5f;

} // namespace

Timbre timbreOf(std::string_view material) {
    const rubble::Material* m = material.empty() ? nullptr : rubble::findMaterial(material);
    if (!m)
        return Timbre::Stone;
    switch (m->pattern) {
    case rubble::FracturePattern::Radial:
        return Timbre::Glass;
    case rubble::FracturePattern::Splinter:
        return Timbre::Wood;
    case rubble::FracturePattern::Uniform:
        return Timbre::Metal;
    case rubble::FracturePattern::Clustered:
        break;
    }
    return Timbre::Stone;
}

SoundBank::SoundBank(int sampleRate) {
    for (int k = 0; k < kSoundKinds; ++k)
        for (int t = 0; t < kTimbres; ++t)
            clips_[static_cast<std::size_t>(k)][static_cast<std::size_t>(t)] =
                synthesise(recipe(static_cast<SoundKind>(k), static_cast<Timbre>(t)), sampleRate,
                           static_cast<std::uint32_t>(1 + 16 * k + t));
}

namespace {
/// The bank of a sample rate, synthesised on first use.
const SoundBank& sharedBank(int sampleRate) {
    static std::mutex mutex;
    static std::map<int, std::unique_ptr<SoundBank>> banks;
    const std::lock_guard<std::mutex> lock(mutex);
    auto& bank = banks[sampleRate];
    if (!bank)
        bank = std::make_unique<SoundBank>(sampleRate);
    return *bank;
}
} // namespace

Mixer::Mixer(int maxVoices, int sampleRate)
    : bank_(sharedBank(sampleRate)), maxVoices_(std::max(1, maxVoices)), rate_(sampleRate) {
    voices_.reserve(static_cast<std::size_t>(maxVoices_));
}

void Mixer::setListener(const V3& position, const V3& right) {
    listener_ = position;
    right_ = norm(right);
}

float Mixer::gainOf(const SoundEvent& e) const {
    const auto k = static_cast<std::size_t>(e.kind);
    const float loud =
        kBaseLevel[k] * std::min(1.5f, std::sqrt(std::max(0.0f, e.impulse) / kReferenceImpulse[k]));
    const float d = len(e.position - listener_);
    return loud * kNearDistance / std::max(kNearDistance, d);
}

bool Mixer::play(const SoundEvent& e) {
    ++stats_.events;
    const float gain = gainOf(e);
    if (muted_ || !(gain >= kAudible)) {
        ++stats_.quiet;
        return false;
    }
    Voice* slot = nullptr;
    if (static_cast<int>(voices_.size()) < maxVoices_) {
        slot = &voices_.emplace_back();
    } else {
        // the quietest sounding voice, weighted by how much of its clip is left
        float weakest = 0;
        for (Voice& v : voices_) {
            const float left =
                v.gain * (1.0f - static_cast<float>(v.position / static_cast<double>(v.clip->size())));
            if (!slot || left < weakest) {
                slot = &v;
                weakest = left;
            }
        }
        if (weakest >= gain) {
            ++stats_.refused;
            return false;
        }
        ++stats_.stolen;
    }
    Voice v;
    v.clip = &bank_.clip(e.kind, e.timbre);
    v.gain = gain;
    // larger things sound lower: an octave down per 8x size, within [0.6, 1.7]
    v.step = std::clamp(std::pow(std::max(0.01f, e.size), -1.0f / 3.0f), 0.6f, 1.7f);
    const V3 to = e.position - listener_;
    const float dist = len(to);
    const float pan = dist > 1e-3f ? std::clamp(dot(to, right_) / dist, -1.0f, 1.0f) : 0.0f;
    const float angle = (pan + 1) * kPi / 4; // equal power
    v.left = std::cos(angle);
    v.right = std::sin(angle);
    *slot = v;
    ++stats_.played;
    stats_.peakVoices = std::max(stats_.peakVoices, static_cast<int>(voices_.size()));
    return true;
}

void Mixer::mix(float* out, int frames) {
    std::fill(out, out + 2 * static_cast<std::size_t>(std::max(0, frames)), 0.0f);
    for (Voice& v : voices_) {
        const std::vector<float>& c = *v.clip;
        for (int i = 0; i < frames && v.position + 1 < static_cast<double>(c.size()); ++i) {
            const auto j = static_cast<std::size_t>(v.position);
            const float f = static_cast<float>(v.position - static_cast<double>(j));
            const float s = v.gain * kMaster * (c[j] + f * (c[j + 1] - c[j]));
            out[2 * i] += s * v.left;
            out[2 * i + 1] += s * v.right;
            v.position += v.step;
        }
    }
    voices_.erase(
        std::remove_if(voices_.begin(), voices_.end(),
                       [](const Voice& v) { return v.position + 1 >= static_cast<double>(v.clip->size()); }),
        voices_.end());
    for (int i = 0; i < 2 * frames; ++i) {
        out[i] = muted_ ? 0.0f : std::clamp(out[i], -1.0f, 1.0f);
        stats_.peakLevel = std::max(stats_.peakLevel, std::abs(out[i]));
    }
}

bool writeWav(const std::string& path, const std::vector<float>& stereo, int sampleRate, std::string& error) {
    std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(path.c_str(), "wb"), &std::fclose);
    if (!f) {
        error = "cannot write " + path;
        return false;
    }
    const auto dataBytes = static_cast<std::uint32_t>(stereo.size() * 2);
    auto u32 = [&](std::uint32_t v) {
        const unsigned char b[4] = {static_cast<unsigned char>(v), static_cast<unsigned char>(v >> 8),
                                    static_cast<unsigned char>(v >> 16), static_cast<unsigned char>(v >> 24)};
        std::fwrite(b, 1, 4, f.get());
    };
    auto u16 = [&](std::uint16_t v) {
        const unsigned char b[2] = {static_cast<unsigned char>(v), static_cast<unsigned char>(v >> 8)};
        std::fwrite(b, 1, 2, f.get());
    };
    std::fwrite("RIFF", 1, 4, f.get());
    u32(36 + dataBytes);
    std::fwrite("WAVEfmt ", 1, 8, f.get());
    u32(16);
    u16(1); // PCM
    u16(2); // stereo
    u32(static_cast<std::uint32_t>(sampleRate));
    u32(static_cast<std::uint32_t>(sampleRate) * 4);
    u16(4);
    u16(16);
    std::fwrite("data", 1, 4, f.get());
    u32(dataBytes);
    for (float s : stereo)
        u16(static_cast<std::uint16_t>(
            static_cast<std::int16_t>(std::lround(std::clamp(s, -1.0f, 1.0f) * 32767))));
    if (std::ferror(f.get())) {
        error = "write failed: " + path;
        return false;
    }
    return true;
}

} // namespace demo
