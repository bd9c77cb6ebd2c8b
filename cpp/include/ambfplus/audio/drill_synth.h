#pragma once

// The drill's sound, synthesised from the burr's state one haptic tick at a time: the same code
// plays live (audio/drill_sound.h) and renders offline (a recording to WAV), so what a test
// measures offline is what a trainee hears.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "ambfplus/export.h"

namespace ambfplus::audio {

/// Most structures one tick can carry distances for (the most a warning list may hold).
inline constexpr int kMaxWarnings = 16;

/// The burr's state at one haptic tick: what the sound is made from.
struct AMBFPLUS_API DrillTick {
  bool on = false;            ///< the burr spins
  float speed = 1.0f;         ///< commanded speed, 0..1 of full speed
  float load = 0.0f;          ///< N, the force on the burr (its magnitude)
  float removal_rate = 0.0f;  ///< m^3/s of tissue removed at this tick
  float hardness = 1.0f;      ///< of the tissue cut, relative to bone (1)
  /// Distance (m) from the burr's surface to each structure of the warning list, in its order;
  /// infinity where unknown or out of reach.
  std::array<float, kMaxWarnings> distances;
  /// steady_clock nanoseconds when the tick was pushed to a live player (latency figures).
  std::int64_t pushed_ns = 0;
  DrillTick();
};

/// A proximity warning for one structure: a beep whose repetition rate rises as the burr's
/// distance to the structure falls from `start` to `full`.
struct AMBFPLUS_API WarningTone {
  std::string name;           ///< for messages: the structure's label name
  std::uint16_t label = 0;    ///< the volume label the distance is to (live feeding)
  double start = 0.001;       ///< m: no beep at or beyond this distance
  double full = 0.0;          ///< m: the fastest beeps at or within this distance
  double frequency = 1500.0;  ///< Hz, the tone's pitch
  double slow_period = 0.5;   ///< s between beeps just inside `start`
  double fast_period = 0.08;  ///< s between beeps at `full`
};

/// The synthesiser's settings. Defaults: a 48 kHz signal from 1 kHz ticks, a motor of 600 Hz at
/// full speed without load.
struct AMBFPLUS_API DrillSoundSpec {
  int sample_rate = 48000;         ///< Hz
  double tick_seconds = 0.001;     ///< s between ticks (the world's step)
  double motor_frequency = 600.0;  ///< Hz, the motor's fundamental at full speed without load
  double spin_up = 0.12;           ///< s, time constant of the motor speeding up
  double spin_down = 0.06;         ///< s, time constant of it slowing down (stopped in 0.4 s)
  /// Fraction of the speed the motor loses under `load_reference` newtons (first-order droop:
  /// speed x (1 - droop x load / (load + load_reference))).
  double droop = 0.35;
  double load_reference = 2.0;       ///< N
  double motor_gain = 0.18;          ///< amplitude of the fundamental at full speed
  double cut_gain = 0.25;            ///< amplitude of the cutting noise at the reference rate
  double removal_reference = 30e-9;  ///< m^3/s at which the cutting noise has cut_gain
  double removal_smoothing = 0.02;   ///< s, time constant of the removal rate heard
  /// Centre of the cutting band for bone (hardness 1); it moves by hardness^cut_spread (soft
  /// tissue lower, harder higher), kept within 150 Hz .. 0.4 x sample_rate.
  double cut_frequency = 3200.0;
  double cut_spread = 0.7;
  double cut_q = 1.2;                 ///< the band-pass filter's quality factor
  double warning_gain = 0.2;          ///< amplitude of the warning tones
  std::uint64_t seed = 0x5eed;        ///< of the cutting noise: one seed, one signal
  std::vector<WarningTone> warnings;  ///< at most kMaxWarnings

  /// Throws ArgumentError naming the value unless every value can be used.
  void validate() const;
  /// Frames a tick renders, on average (sample_rate x tick_seconds).
  double frames_per_tick() const { return sample_rate * tick_seconds; }
};

/// The synthesiser: deterministic (seeded noise, no clock), sample-exact, one tick at a time.
/// Tick k renders frames [floor(k x R), floor((k + 1) x R)) of the signal, R = frames_per_tick.
/// Not thread-safe: one thread renders (the audio thread live, the caller offline).
class AMBFPLUS_API DrillSynth {
 public:
  /// Throws ArgumentError for a bad spec.
  explicit DrillSynth(const DrillSoundSpec& spec);
  const DrillSoundSpec& spec() const { return spec_; }

  /// Frames the next tick renders.
  int next_tick_frames() const;
  /// Renders one tick into out (next_tick_frames() values); returns how many it wrote.
  int render_tick(const DrillTick& tick, float* out);
  /// Renders ticks one after the other, appending to out.
  void render(const std::vector<DrillTick>& ticks, std::vector<float>& out);
  /// Back to the state at construction (silent, motor stopped, the noise reseeded).
  void reset();

  /// The motor's speed now, 0..1 (after its lag).
  double motor_speed() const { return motor_; }
  /// The motor's fundamental now, Hz.
  double fundamental() const { return motor_ * spec_.motor_frequency; }
  /// Which warning beeps now (its index), -1 for none.
  int warning_index() const { return warning_; }
  /// Seconds between beeps now (0 without a warning).
  double beep_period() const { return beep_period_; }

 private:
  void set_tick(const DrillTick& tick);
  float next_noise();

  DrillSoundSpec spec_;
  std::int64_t tick_index_ = 0;
  // Per-tick targets.
  double motor_target_ = 0.0, motor_tau_ = 0.0;
  double cut_target_ = 0.0;
  double removal_ = 0.0;                               // removal rate heard (smoothed), m^3/s
  double b0_ = 0, b1_ = 0, b2_ = 0, a1_ = 0, a2_ = 0;  // band-pass coefficients
  // Per-sample state.
  double motor_ = 0.0;                        // motor speed 0..1
  double phase_ = 0.0;                        // motor phase, cycles
  double cut_ = 0.0;                          // smoothed cutting amplitude
  double x1_ = 0, x2_ = 0, y1_ = 0, y2_ = 0;  // band-pass memory
  std::uint64_t noise_state_ = 0;
  int warning_ = -1;
  double beep_period_ = 0.0;
  double beep_phase_ = 0.0;  // cycles of the beep pattern
  double tone_phase_ = 0.0;  // cycles of the tone
  double tone_frequency_ = 0.0;
  double tone_env_ = 0.0;
};

/// Renders a tick sequence from silence with a fresh synthesiser: what a player plays for it.
AMBFPLUS_API std::vector<float> render_drill_sound(const DrillSoundSpec& spec,
                                                   const std::vector<DrillTick>& ticks);

}  // namespace ambfplus::audio
