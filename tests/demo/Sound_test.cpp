// The game's sound without a device: clips, loudness by impulse and distance, the voice limit, the mix and
// the WAV writer.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>

#include "Sound.hpp"
#include "TestSupport.hpp"

namespace demo {
namespace {

SoundEvent event(SoundKind kind, float impulse, V3 at = {0, 0, 0}) {
    SoundEvent e;
    e.kind = kind;
    e.impulse = impulse;
    e.position = at;
    return e;
}

TEST(Sound, MaterialsPickTheirTimbre) {
    EXPECT_EQ(timbreOf("glass"), Timbre::Glass);
    EXPECT_EQ(timbreOf("wood"), Timbre::Wood);
    EXPECT_EQ(timbreOf("steel"), Timbre::Metal);
    EXPECT_EQ(timbreOf("concrete"), Timbre::Stone);
    EXPECT_EQ(timbreOf(""), Timbre::Stone);
    EXPECT_EQ(timbreOf("cheese"), Timbre::Stone);
}

TEST(Sound, ClipsArePeakNormalisedAndBreaksOutlastKnocks) {
    const SoundBank bank(Mixer::kSampleRate);
    for (int t = 0; t < kTimbres; ++t) {
        for (int k = 0; k < kSoundKinds; ++k) {
            const auto& c = bank.clip(static_cast<SoundKind>(k), static_cast<Timbre>(t));
            ASSERT_FALSE(c.empty());
            float peak = 0;
            for (float v : c)
                peak = std::max(peak, std::abs(v));
            EXPECT_NEAR(peak, 1.0f, 1e-5f) << "kind " << k << " timbre " << t;
            EXPECT_EQ(c.front(), 0.0f); // faded in: no click
        }
        EXPECT_GT(bank.clip(SoundKind::Break, static_cast<Timbre>(t)).size(),
                  bank.clip(SoundKind::Debris, static_cast<Timbre>(t)).size());
    }
}

/// Sign changes per second of a clip: lower for a lower sound.
double crossingsPerSecond(const std::vector<float>& c) {
    int n = 0;
    for (std::size_t i = 1; i < c.size(); ++i)
        n += (c[i - 1] < 0) != (c[i] < 0) ? 1 : 0;
    return n * static_cast<double>(Mixer::kSampleRate) / static_cast<double>(c.size());
}

TEST(Sound, CollapsesRumbleLongerAndLowerThanBreaks) {
    const SoundBank bank(Mixer::kSampleRate);
    for (int t = 0; t < kTimbres; ++t) {
        const auto& collapse = bank.clip(SoundKind::Collapse, static_cast<Timbre>(t));
        const auto& crumble = bank.clip(SoundKind::Break, static_cast<Timbre>(t));
        EXPECT_GT(collapse.size(), crumble.size()) << "timbre " << t;
        EXPECT_LT(crossingsPerSecond(collapse), crossingsPerSecond(crumble)) << "timbre " << t;
    }
}

TEST(Sound, LoudnessGrowsWithImpulseAndFallsAsOneOverDistance) {
    Mixer m;
    m.setListener({0, 0, 0}, {1, 0, 0});
    const float soft = m.gainOf(event(SoundKind::Impact, 100));
    const float hard = m.gainOf(event(SoundKind::Impact, 400));
    EXPECT_NEAR(hard / soft, 2.0f, 1e-4f); // square root of the impulse
    EXPECT_EQ(m.gainOf(event(SoundKind::Impact, 0)), 0.0f);
    const float near = m.gainOf(event(SoundKind::Impact, 400, {30, 0, 0}));
    const float far = m.gainOf(event(SoundKind::Impact, 400, {300, 0, 0}));
    EXPECT_NEAR(near / far, 10.0f, 1e-3f);
    EXPECT_LT(near, hard);
    // within the near distance nothing is attenuated
    EXPECT_EQ(m.gainOf(event(SoundKind::Impact, 400, {5, 0, 0})), hard);
}

TEST(Sound, ThousandsOfEventsShareTheVoiceLimit) {
    Mixer m(16);
    m.setListener({0, 0, 0}, {1, 0, 0});
    for (int i = 0; i < 3000; ++i)
        m.play(
            event(SoundKind::Debris, 50.0f + static_cast<float>(i % 97), {0, 0, static_cast<float>(i % 40)}));
    const MixerStats& s = m.stats();
    EXPECT_EQ(m.activeVoices(), 16);
    EXPECT_EQ(s.peakVoices, 16);
    EXPECT_EQ(s.events, 3000);
    EXPECT_EQ(s.played + s.quiet + s.refused, s.events);
    EXPECT_GT(s.refused, 0);
    // the voices ring out and free themselves
    std::vector<float> buf(2 * 4096);
    for (int i = 0; i < 20 && m.activeVoices() > 0; ++i)
        m.mix(buf.data(), 4096);
    EXPECT_EQ(m.activeVoices(), 0);
}

TEST(Sound, ALouderSoundTakesTheQuietestVoice) {
    Mixer m(4);
    m.setListener({0, 0, 0}, {1, 0, 0});
    for (int i = 0; i < 4; ++i)
        ASSERT_TRUE(m.play(event(SoundKind::Impact, 50)));
    EXPECT_FALSE(m.play(event(SoundKind::Impact, 10))); // quieter than every voice
    EXPECT_EQ(m.stats().refused, 1);
    EXPECT_TRUE(m.play(event(SoundKind::Impact, 2000)));
    EXPECT_EQ(m.stats().stolen, 1);
    EXPECT_EQ(m.activeVoices(), 4);
    // an inaudible event uses no voice
    EXPECT_FALSE(m.play(event(SoundKind::Impact, 2000, {1e6f, 0, 0})));
    EXPECT_EQ(m.stats().quiet, 1);
}

TEST(Sound, MixPansAndStaysInRange) {
    Mixer m;
    m.setListener({0, 0, 0}, {1, 0, 0});
    ASSERT_TRUE(m.play(event(SoundKind::Break, 5000, {20, 0, 0}))); // to the right
    std::vector<float> buf(2 * 8192);
    m.mix(buf.data(), 8192);
    double left = 0, right = 0;
    for (std::size_t i = 0; i < buf.size(); i += 2) {
        left += buf[i] * buf[i];
        right += buf[i + 1] * buf[i + 1];
        ASSERT_LE(std::abs(buf[i]), 1.0f);
    }
    EXPECT_GT(right, 0);
    EXPECT_LT(left, right * 1e-6); // fully right
    EXPECT_GT(m.stats().peakLevel, 0.05f);
}

TEST(Sound, MutedIsSilentAndTakesNoVoice) {
    Mixer m;
    m.setMuted(true);
    EXPECT_FALSE(m.play(event(SoundKind::Break, 5000)));
    EXPECT_EQ(m.activeVoices(), 0);
    std::vector<float> buf(2 * 512, 1.0f);
    m.mix(buf.data(), 512);
    for (float v : buf)
        ASSERT_EQ(v, 0.0f);
}

TEST(Sound, SameEventsGiveTheSameSamples) {
    auto render = [] {
        Mixer m(8);
        m.setListener({0, 2, 0}, {0, 0, 1});
        std::vector<float> all, buf(2 * 735);
        for (int f = 0; f < 30; ++f) {
            m.play(event(SoundKind::Debris, 300.0f + 40.0f * static_cast<float>(f),
                         {static_cast<float>(f), 0, 3}));
            m.mix(buf.data(), 735);
            all.insert(all.end(), buf.begin(), buf.end());
        }
        return all;
    };
    EXPECT_EQ(render(), render());
}

TEST(Sound, WavHeaderAndSamples) {
    const std::string path = (rubble::test::tempDir("demo_sound") / "sound.wav").string();
    const std::vector<float> stereo{0.0f, 1.0f, -1.0f, 0.5f, 2.0f, -0.25f};
    std::string error;
    ASSERT_TRUE(writeWav(path, stereo, 44100, error)) << error;
    std::ifstream in(path, std::ios::binary);
    const std::vector<unsigned char> b((std::istreambuf_iterator<char>(in)), {});
    ASSERT_EQ(b.size(), 44u + 2 * stereo.size());
    EXPECT_EQ(std::string(b.begin(), b.begin() + 4), "RIFF");
    EXPECT_EQ(std::string(b.begin() + 8, b.begin() + 16), "WAVEfmt ");
    auto i16 = [&](std::size_t at) { return static_cast<std::int16_t>(b[at] | (b[at + 1] << 8)); };
    EXPECT_EQ(i16(22), 2);                       // channels
    EXPECT_EQ(i16(24) & 0xffff, 44100 & 0xffff); // rate (low half)
    EXPECT_EQ(i16(44 + 2), 32767);
    EXPECT_EQ(i16(44 + 4), -32767);
    EXPECT_EQ(i16(44 + 8), 32767); // clamped
    EXPECT_FALSE(writeWav("/nonexistent-dir/x.wav", stereo, 44100, error));
    EXPECT_NE(error.find("/nonexistent-dir/x.wav"), std::string::npos);
}

} // namespace
} // namespace demo
