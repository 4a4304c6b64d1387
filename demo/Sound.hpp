#pragma once
/// \file Sound.hpp
/// The game's sound: procedurally synthesised clips (by material and kind), a software mixer with a voice
/// limit, loudness by impulse and distance, and a WAV writer. No audio device here (AudioOutput plays it).

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "Math.hpp"

namespace demo {

/// What made a sound.
enum class SoundKind : int {
    Impact,   ///< a shell or blast hit an object
    Break,    ///< an object broke into pieces
    Debris,   ///< a falling piece hit the ground
    Collapse, ///< standing bodies lost their support and fell (one rumble a frame)
};
inline constexpr int kSoundKinds = 4;

/// How a material sounds.
enum class Timbre : int { Stone, Glass, Wood, Metal };
inline constexpr int kTimbres = 4;

/// The timbre of a material preset name (Material.hpp); unknown or empty names sound like stone.
Timbre timbreOf(std::string_view material);

/// One sound to play.
struct SoundEvent {
    SoundKind kind = SoundKind::Impact; ///< what made it
    Timbre timbre = Timbre::Stone;      ///< material
    V3 position{};                      ///< world position (m)
    float impulse = 0;                  ///< N·s: how hard (loudness)
    float size = 1;                     ///< m: how big (larger sounds lower)
};

/// Totals of a mixer.
struct MixerStats {
    long long events = 0;  ///< play() calls
    long long played = 0;  ///< events that got a voice
    long long quiet = 0;   ///< events too quiet to hear (no voice used)
    long long stolen = 0;  ///< voices taken from a quieter sound
    long long refused = 0; ///< events dropped: every voice busy with a louder sound
    int peakVoices = 0;    ///< most voices sounding at once
    float peakLevel = 0;   ///< largest absolute output sample
};

/// Mono clips for every kind and timbre, synthesised deterministically at a sample rate.
class SoundBank {
public:
    /// Synthesises every clip.
    explicit SoundBank(int sampleRate);
    /// The clip (peak 1) of a kind and timbre.
    const std::vector<float>& clip(SoundKind kind, Timbre timbre) const {
        return clips_[static_cast<std::size_t>(kind)][static_cast<std::size_t>(timbre)];
    }

private:
    std::array<std::array<std::vector<float>, kTimbres>, kSoundKinds> clips_;
};

/// Mixes SoundEvents into interleaved stereo float samples with at most maxVoices voices.
class Mixer {
public:
    /// Sample rate of the game's sound.
    static constexpr int kSampleRate = 44100;
    /// Gains below this are not played.
    static constexpr float kAudible = 0.01f;
    /// A mixer with a voice limit.
    explicit Mixer(int maxVoices = 24, int sampleRate = kSampleRate);
    Mixer(const Mixer&) = delete;
    Mixer& operator=(const Mixer&) = delete;

    /// Where the listener is, and its right-hand direction (for panning).
    void setListener(const V3& position, const V3& right);
    /// Muted: play() takes no voice and mix() writes silence.
    void setMuted(bool muted) { muted_ = muted; }
    /// Muted.
    bool muted() const { return muted_; }
    /// The gain an event would play at: loudness by impulse (relative to its kind's reference) times the
    /// attenuation by distance from the listener.
    float gainOf(const SoundEvent& e) const;
    /// Starts a sound: a free voice, else the quietest voice if quieter than it. False when not played.
    bool play(const SoundEvent& e);
    /// Mixes frames of stereo (2 floats each) into out, replacing its contents, and advances the voices.
    void mix(float* out, int frames);
    /// Voices sounding now.
    int activeVoices() const { return static_cast<int>(voices_.size()); }
    /// The voice limit.
    int maxVoices() const { return maxVoices_; }
    /// Sample rate.
    int sampleRate() const { return rate_; }
    /// Totals.
    const MixerStats& stats() const { return stats_; }

private:
    struct Voice {
        const std::vector<float>* clip = nullptr;
        double position = 0; // in clip samples
        float step = 1;      // clip samples per output sample (pitch)
        float gain = 0;
        float left = 0, right = 0; // pan gains
    };
    const SoundBank& bank_; // shared by mixers of the same rate
    std::vector<Voice> voices_;
    int maxVoices_;
    int rate_;
    bool muted_ = false;
    V3 listener_{}, right_{1, 0, 0};
    MixerStats stats_;
};

/// Writes interleaved stereo floats as a 16-bit PCM WAV file; false with a message naming the file.
bool writeWav(const std::string& path, const std::vector<float>& stereo, int sampleRate, std::string& error);

} // namespace demo
