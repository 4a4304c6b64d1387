#include "Audio.hpp"

#include <AL/al.h>
#include <AL/alc.h>

#include <array>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <filesystem>

namespace demo {
namespace {
constexpr int kBuffers = 6;         // queued on the source
constexpr int kBufferFrames = 1024; // 23 ms each: about 140 ms queued

/// Sound hardware or a sound server may be there (else opening a device only prints ALSA's complaints).
bool soundSystemPresent() {
    std::error_code ec;
    if (std::getenv("ALSOFT_DRIVERS") || std::getenv("PULSE_SERVER") ||
        std::filesystem::exists("/dev/snd", ec))
        return true;
    const char* run = std::getenv("XDG_RUNTIME_DIR");
    return run && (std::filesystem::exists(std::filesystem::path(run) / "pulse/native", ec) ||
                   std::filesystem::exists(std::filesystem::path(run) / "pipewire-0", ec));
}
} // namespace

/// An open OpenAL device streaming one source.
struct Audio::Device {
    ALCdevice* device = nullptr;
    ALCcontext* context = nullptr;
    ALuint source = 0;
    std::array<ALuint, kBuffers> buffers{};
    std::vector<std::int16_t> pcm;

    ~Device() {
        if (context) {
            alSourceStop(source);
            alDeleteSources(1, &source);
            alDeleteBuffers(kBuffers, buffers.data());
            alcMakeContextCurrent(nullptr);
            alcDestroyContext(context);
        }
        if (device)
            alcCloseDevice(device);
    }
};

Audio::Audio(const Options& options) : options_(options), mixer_(options.maxVoices) {
    mixer_.setMuted(options.muted);
    scratch_.resize(2 * kBufferFrames);
    if (!options.device || options.muted || !options.wavPath.empty() || !soundSystemPresent())
        return;
    setenv("ALSOFT_LOGLEVEL", "0", 0); // no device is no error worth printing
    auto d = std::make_unique<Device>();
    d->device = alcOpenDevice(nullptr);
    if (!d->device)
        return;
    d->context = alcCreateContext(d->device, nullptr);
    if (!d->context || !alcMakeContextCurrent(d->context))
        return;
    alGetError();
    alGenSources(1, &d->source);
    alGenBuffers(kBuffers, d->buffers.data());
    if (alGetError() != AL_NO_ERROR)
        return;
    device_ = std::move(d);
    for (ALuint b : device_->buffers) {
        render(kBufferFrames);
        alBufferData(b, AL_FORMAT_STEREO16, device_->pcm.data(),
                     static_cast<ALsizei>(device_->pcm.size() * 2), Mixer::kSampleRate);
    }
    alSourceQueueBuffers(device_->source, kBuffers, device_->buffers.data());
    alSourcePlay(device_->source);
    if (alGetError() != AL_NO_ERROR) {
        device_.reset();
        return;
    }
    running_ = true;
    thread_ = std::thread([this] { pump(); });
}

Audio::~Audio() {
    running_ = false;
    if (thread_.joinable())
        thread_.join();
}

void Audio::render(int frames) {
    mixer_.mix(scratch_.data(), frames);
    if (device_) {
        device_->pcm.resize(2 * static_cast<std::size_t>(frames));
        for (std::size_t i = 0; i < device_->pcm.size(); ++i)
            device_->pcm[i] = static_cast<std::int16_t>(scratch_[i] * 32767.0f);
    }
}

void Audio::pump() {
    while (running_) {
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
        const std::lock_guard<std::mutex> lock(mutex_);
        ALint processed = 0;
        alGetSourcei(device_->source, AL_BUFFERS_PROCESSED, &processed);
        for (; processed > 0; --processed) {
            ALuint b = 0;
            alSourceUnqueueBuffers(device_->source, 1, &b);
            render(kBufferFrames);
            alBufferData(b, AL_FORMAT_STEREO16, device_->pcm.data(),
                         static_cast<ALsizei>(device_->pcm.size() * 2), Mixer::kSampleRate);
            alSourceQueueBuffers(device_->source, 1, &b);
        }
        ALint state = 0;
        alGetSourcei(device_->source, AL_SOURCE_STATE, &state);
        if (state != AL_PLAYING) // ran dry (a stall): start again
            alSourcePlay(device_->source);
    }
}

void Audio::setListener(const V3& position, const V3& right) {
    const std::lock_guard<std::mutex> lock(mutex_);
    mixer_.setListener(position, right);
}

void Audio::play(const std::vector<SoundEvent>& events) {
    const std::lock_guard<std::mutex> lock(mutex_);
    for (const SoundEvent& e : events)
        mixer_.play(e);
}

void Audio::advance(double seconds) {
    if (device_)
        return; // the device's clock drives the mix
    const std::lock_guard<std::mutex> lock(mutex_);
    owed_ += seconds * Mixer::kSampleRate;
    while (owed_ >= 1) {
        const int frames = static_cast<int>(std::min<double>(owed_, kBufferFrames));
        render(frames);
        if (!options_.wavPath.empty())
            capture_.insert(capture_.end(), scratch_.begin(), scratch_.begin() + 2 * frames);
        owed_ -= frames;
    }
}

bool Audio::finish(std::string& error) {
    if (options_.wavPath.empty())
        return true;
    const std::lock_guard<std::mutex> lock(mutex_);
    return writeWav(options_.wavPath, capture_, Mixer::kSampleRate, error);
}

MixerStats Audio::stats() const {
    const std::lock_guard<std::mutex> lock(mutex_);
    return mixer_.stats();
}

} // namespace demo
