#pragma once
/// \file Audio.hpp
/// The game's audio output: the Mixer played on the default OpenAL device from its own thread, on no device
/// (muted, headless, or none could be opened: silently), or captured to a WAV file in step with the game.

#include <atomic>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "Sound.hpp"

namespace demo {

/// Plays SoundEvents.
class Audio {
public:
    /// How to play.
    struct Options {
        bool device = true;  ///< open the default audio device (else play on none)
        bool muted = false;  ///< --mute: every event is dropped
        std::string wavPath; ///< capture the mix to this WAV file instead of a device
        int maxVoices = 24;  ///< voice limit
    };
    /// Opens the device when asked; without one the events still go through the mixer (for its counters).
    explicit Audio(const Options& options);
    ~Audio();
    Audio(const Audio&) = delete;
    Audio& operator=(const Audio&) = delete;

    /// True when sound reaches an audio device.
    bool hasDevice() const { return device_ != nullptr; }
    /// Where the listener is and its right-hand direction.
    void setListener(const V3& position, const V3& right);
    /// Starts sounds.
    void play(const std::vector<SoundEvent>& events);
    /// Advances the capture (and the voices when there is no device) by seconds of game time.
    void advance(double seconds);
    /// Writes the capture (when capturing); false with a message.
    bool finish(std::string& error);
    /// The mixer's totals.
    MixerStats stats() const;

private:
    void pump(); // the device thread: refills processed buffers
    void render(int frames);

    Options options_;
    mutable std::mutex mutex_;
    Mixer mixer_;
    std::vector<float> scratch_;
    std::vector<float> capture_; // interleaved stereo (WAV capture)
    double owed_ = 0;            // sample frames of game time not yet mixed
    struct Device;
    std::unique_ptr<Device> device_;
    std::atomic<bool> running_{false};
    std::thread thread_;
};

} // namespace demo
