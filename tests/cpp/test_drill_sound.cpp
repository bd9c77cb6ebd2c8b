// The drill sound's engine parts: the lock-free tick queue, the synthesiser's silence and
// determinism, and the live player's audio-thread path against the offline render.

#include <gtest/gtest.h>

#include <thread>
#include <vector>

#include "ambfplus/audio/drill_sound.h"
#include "ambfplus/audio/drill_synth.h"
#include "ambfplus/errors.h"
#include "audio/spsc_ring.h"

namespace ambfplus::audio {
namespace {

// On for the first on_ticks, then off.
std::vector<DrillTick> cutting_ticks(int n, int on_ticks) {
  std::vector<DrillTick> ticks(n);
  for (int i = 0; i < n; ++i) {
    ticks[i].on = i < on_ticks;
    ticks[i].load = 1.5f;
    ticks[i].removal_rate = 20e-9f;
  }
  return ticks;
}

TEST(SpscRing, KeepsOrderAcrossThreadsAndRefusesWhenFull) {
  SpscRing<int> ring(8);
  for (int i = 0; i < 8; ++i) EXPECT_TRUE(ring.push(i));
  EXPECT_FALSE(ring.push(8));
  int v = -1;
  EXPECT_TRUE(ring.pop(v));
  EXPECT_EQ(v, 0);

  SpscRing<int> big(64);
  constexpr int kCount = 200000;
  std::thread producer([&] {
    for (int i = 0; i < kCount;) {
      if (big.push(i)) ++i;
    }
  });
  int expected = 0;
  while (expected < kCount) {
    if (big.pop(v)) {
      ASSERT_EQ(v, expected);
      ++expected;
    }
  }
  producer.join();
}

TEST(DrillSynth, SilentExactlyOnceSpunDownAndDeterministic) {
  DrillSoundSpec spec;
  const std::vector<DrillTick> ticks = cutting_ticks(5000, 1000);
  const std::vector<float> a = render_drill_sound(spec, ticks);
  const std::vector<float> b = render_drill_sound(spec, ticks);
  ASSERT_EQ(a.size(), 5000u * 48u);
  EXPECT_EQ(a, b);
  // Sound while on; exact zeros by the end of the coast (the motor stops about 0.4 s after
  // switching off: 0.06 s x ln(0.65 / 1e-3)).
  float loudest = 0;
  for (std::size_t i = 0; i < 48000; ++i) loudest = std::max(loudest, std::abs(a[i]));
  EXPECT_GT(loudest, 0.05f);
  for (std::size_t i = a.size() - 4800; i < a.size(); ++i) ASSERT_EQ(a[i], 0.0f) << i;
  // Never switched on: zeros from the first sample.
  std::vector<DrillTick> off(100);
  for (float s : render_drill_sound(spec, off)) ASSERT_EQ(s, 0.0f);
}

TEST(DrillSynth, AnotherSeedAnotherNoise) {
  DrillSoundSpec spec;
  const std::vector<DrillTick> ticks = cutting_ticks(200, 100);
  const std::vector<float> a = render_drill_sound(spec, ticks);
  spec.seed = 7;
  EXPECT_NE(a, render_drill_sound(spec, ticks));
}

TEST(DrillSynth, BadSpecsAreRefused) {
  DrillSoundSpec spec;
  spec.droop = 1.5;
  EXPECT_THROW(DrillSynth{spec}, ArgumentError);
  spec = DrillSoundSpec{};
  spec.warnings.push_back(WarningTone{"nerve", 3, 0.001, 0.002});
  EXPECT_THROW(DrillSynth{spec}, ArgumentError);
}

TEST(DrillSoundPlayer, TheAudioThreadPathPlaysWhatTheOfflineRenderGives) {
  DrillSoundSpec spec;
  PlayerOptions options;
  options.output = AudioOutput::kNone;
  options.max_backlog_ticks = 4096;
  options.trim_backlog = false;
  options.capture_frames = 1 << 16;
  DrillSoundPlayer player(spec, options);
  // Silence before the first tick, the synthesiser untouched.
  std::vector<float> before(300, 1.0f);
  player.fill(before.data(), 300);
  EXPECT_EQ(before, std::vector<float>(300, 0.0f));
  player.take_capture();
  const std::vector<DrillTick> ticks = cutting_ticks(1000, 500);
  for (const DrillTick& t : ticks) ASSERT_TRUE(player.push(t));
  // Callbacks of an awkward size: frames straddle ticks.
  std::vector<float> played(1000 * 48);
  for (std::size_t at = 0; at < played.size(); at += 100) {
    player.fill(played.data() + at,
                static_cast<std::uint32_t>(std::min<std::size_t>(100, played.size() - at)));
  }
  EXPECT_EQ(played, render_drill_sound(spec, ticks));
  EXPECT_EQ(player.stats().played, 1000);
  EXPECT_EQ(player.take_capture(), played);
  EXPECT_EQ(player.take_latencies().size(), 1000u);
}

TEST(DrillSoundPlayer, KeepsTheBacklogBoundedAndMutes) {
  DrillSoundSpec spec;
  PlayerOptions options;
  options.output = AudioOutput::kNone;
  options.max_backlog_ticks = 2;
  DrillSoundPlayer player(spec, options);
  for (const DrillTick& t : cutting_ticks(100, 50)) player.push(t);
  std::vector<float> out(96);
  player.fill(out.data(), 96);
  EXPECT_EQ(player.stats().played, 2);
  EXPECT_EQ(player.stats().dropped, 96);
  player.set_muted(true);
  player.fill(out.data(), 96);
  for (float s : out) EXPECT_EQ(s, 0.0f);
}

}  // namespace
}  // namespace ambfplus::audio
