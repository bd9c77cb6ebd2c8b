#include "ambfplus/audio/drill_synth.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "ambfplus/errors.h"

namespace ambfplus::audio {
namespace {

constexpr double kPi = 3.14159265358979323846;
// Relative strength of the motor's harmonics (1st .. 4th): a whine with some edge.
constexpr double kHarmonics[] = {1.0, 0.5, 0.3, 0.15};
// Below this the motor is stopped and the signal exactly silent.
constexpr double kStopped = 1e-3;
// Time constants of the cutting noise's level and of a beep's edges, s: no clicks.
constexpr double kCutSmoothing = 0.004;
constexpr double kBeepEdge = 0.002;

void check(bool ok, const std::string& what, double value, const char* expected) {
  if (ok) return;
  std::ostringstream message;
  message << "DrillSoundSpec: " << what << " = " << value << ", expected " << expected;
  throw ArgumentError(message.str());
}

double smoothing(double tau, int rate) { return 1.0 - std::exp(-1.0 / (tau * rate)); }

}  // namespace

DrillTick::DrillTick() { distances.fill(std::numeric_limits<float>::infinity()); }

void DrillSoundSpec::validate() const {
  auto positive = [](double v) { return std::isfinite(v) && v > 0; };
  check(sample_rate >= 8000 && sample_rate <= 384000, "sample_rate", sample_rate,
        "8000..384000 Hz");
  check(positive(tick_seconds) && tick_seconds * sample_rate >= 1, "tick_seconds", tick_seconds,
        "> 0 and at least one frame");
  check(positive(motor_frequency) && motor_frequency < 0.1 * sample_rate, "motor_frequency",
        motor_frequency, "> 0 and below a tenth of the sample rate (its harmonics fit)");
  check(positive(spin_up), "spin_up", spin_up, "> 0 s");
  check(positive(spin_down), "spin_down", spin_down, "> 0 s");
  check(std::isfinite(droop) && droop >= 0 && droop < 1, "droop", droop, "0 <= droop < 1");
  check(positive(load_reference), "load_reference", load_reference, "> 0 N");
  check(std::isfinite(motor_gain) && motor_gain >= 0, "motor_gain", motor_gain, ">= 0");
  check(std::isfinite(cut_gain) && cut_gain >= 0, "cut_gain", cut_gain, ">= 0");
  check(positive(removal_reference), "removal_reference", removal_reference, "> 0 m^3/s");
  check(positive(removal_smoothing), "removal_smoothing", removal_smoothing, "> 0 s");
  check(positive(cut_frequency), "cut_frequency", cut_frequency, "> 0 Hz");
  check(std::isfinite(cut_spread) && cut_spread >= 0, "cut_spread", cut_spread, ">= 0");
  check(positive(cut_q), "cut_q", cut_q, "> 0");
  check(std::isfinite(warning_gain) && warning_gain >= 0, "warning_gain", warning_gain, ">= 0");
  check(warnings.size() <= static_cast<std::size_t>(kMaxWarnings), "warnings",
        static_cast<double>(warnings.size()), "at most 16");
  for (std::size_t i = 0; i < warnings.size(); ++i) {
    const WarningTone& w = warnings[i];
    const std::string at = "warnings[" + std::to_string(i) + "] (" + w.name + ").";
    check(std::isfinite(w.full) && w.full >= 0, at + "full", w.full, ">= 0 m");
    check(std::isfinite(w.start) && w.start > w.full, at + "start", w.start, "> full");
    check(positive(w.frequency) && w.frequency < 0.45 * sample_rate, at + "frequency", w.frequency,
          "> 0 and below 0.45 x sample_rate");
    check(positive(w.slow_period), at + "slow_period", w.slow_period, "> 0 s");
    check(positive(w.fast_period) && w.fast_period <= w.slow_period, at + "fast_period",
          w.fast_period, "> 0 and <= slow_period");
  }
}

DrillSynth::DrillSynth(const DrillSoundSpec& spec) : spec_(spec) {
  spec_.validate();
  reset();
}

void DrillSynth::reset() {
  tick_index_ = 0;
  motor_target_ = motor_ = phase_ = 0.0;
  motor_tau_ = spec_.spin_up;
  cut_target_ = cut_ = removal_ = 0.0;
  b0_ = b1_ = b2_ = a1_ = a2_ = 0.0;
  x1_ = x2_ = y1_ = y2_ = 0.0;
  // splitmix64 of the seed: a zero seed still gives a running xorshift state.
  std::uint64_t z = spec_.seed + 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  noise_state_ = (z ^ (z >> 31)) | 1;
  warning_ = -1;
  beep_period_ = beep_phase_ = tone_phase_ = tone_frequency_ = tone_env_ = 0.0;
}

int DrillSynth::next_tick_frames() const {
  const double r = spec_.frames_per_tick();
  const auto begin = static_cast<std::int64_t>(std::floor(tick_index_ * r));
  const auto end = static_cast<std::int64_t>(std::floor((tick_index_ + 1) * r));
  return static_cast<int>(end - begin);
}

float DrillSynth::next_noise() {
  // xorshift64*: uniform in [-1, 1).
  noise_state_ ^= noise_state_ >> 12;
  noise_state_ ^= noise_state_ << 25;
  noise_state_ ^= noise_state_ >> 27;
  const std::uint64_t r = noise_state_ * 0x2545f4914f6cdd1dull;
  return static_cast<float>(static_cast<double>(r >> 11) * (2.0 / 9007199254740992.0) - 1.0);
}

// The targets a tick sets: the motor's speed (droop under load), the cutting band and level,
// and the most urgent warning.
void DrillSynth::set_tick(const DrillTick& tick) {
  const double speed = std::clamp(std::isfinite(tick.speed) ? tick.speed : 0.0f, 0.0f, 1.0f);
  const double load = std::isfinite(tick.load) ? std::max(0.0f, tick.load) : 0.0;
  const double target =
      tick.on ? speed * (1.0 - spec_.droop * load / (load + spec_.load_reference)) : 0.0;
  motor_tau_ = target >= motor_ ? spec_.spin_up : spec_.spin_down;
  motor_target_ = target;

  // Energy follows the removal rate, averaged over removal_smoothing (whole voxels come off
  // in single ticks): amplitude as its square root.
  const double rate = std::isfinite(tick.removal_rate) ? std::max(0.0f, tick.removal_rate) : 0.0;
  removal_ += (rate - removal_) * (1.0 - std::exp(-spec_.tick_seconds / spec_.removal_smoothing));
  if (rate == 0.0 && removal_ < 1e-6 * spec_.removal_reference) removal_ = 0.0;
  cut_target_ = tick.on ? spec_.cut_gain * std::sqrt(removal_ / spec_.removal_reference) : 0.0;
  const double hardness = std::isfinite(tick.hardness) && tick.hardness > 0 ? tick.hardness : 1.0;
  const double fc = std::clamp(spec_.cut_frequency * std::pow(hardness, spec_.cut_spread), 150.0,
                               0.4 * spec_.sample_rate);
  // Band-pass biquad, 0 dB peak gain (RBJ's cookbook).
  const double w0 = 2 * kPi * fc / spec_.sample_rate;
  const double alpha = std::sin(w0) / (2 * spec_.cut_q);
  const double a0 = 1 + alpha;
  b0_ = alpha / a0;
  b1_ = 0.0;
  b2_ = -alpha / a0;
  a1_ = -2 * std::cos(w0) / a0;
  a2_ = (1 - alpha) / a0;

  // The most urgent structure: the largest share of its range from start to full.
  int best = -1;
  double urgency = -1.0;
  for (std::size_t i = 0; i < spec_.warnings.size(); ++i) {
    const WarningTone& w = spec_.warnings[i];
    const double d = tick.distances[i];
    if (!(d < w.start)) continue;
    const double u = std::clamp((w.start - d) / (w.start - w.full), 0.0, 1.0);
    if (u > urgency) {
      urgency = u;
      best = static_cast<int>(i);
    }
  }
  if (best < 0) {
    warning_ = -1;
    beep_period_ = 0.0;
    return;
  }
  const WarningTone& w = spec_.warnings[best];
  if (warning_ < 0) beep_phase_ = 0.0;  // the first beep starts at once
  warning_ = best;
  // Geometric between the periods: the rate rises evenly in octaves as the distance falls.
  beep_period_ = w.slow_period * std::pow(w.fast_period / w.slow_period, urgency);
  tone_frequency_ = w.frequency;
}

int DrillSynth::render_tick(const DrillTick& tick, float* out) {
  const int frames = next_tick_frames();
  set_tick(tick);
  const double rate = spec_.sample_rate;
  const double motor_alpha = smoothing(motor_tau_, spec_.sample_rate);
  const double cut_alpha = smoothing(kCutSmoothing, spec_.sample_rate);
  const double edge_alpha = smoothing(kBeepEdge, spec_.sample_rate);
  for (int n = 0; n < frames; ++n) {
    motor_ += (motor_target_ - motor_) * motor_alpha;
    if (motor_target_ == 0.0 && motor_ < kStopped) motor_ = 0.0;
    cut_ += (cut_target_ - cut_) * cut_alpha;
    if (cut_target_ == 0.0 && cut_ < 1e-6) cut_ = 0.0;

    double sample = 0.0;
    if (motor_ > 0.0) {
      phase_ += motor_ * spec_.motor_frequency / rate;
      phase_ -= std::floor(phase_);
      double whine = 0.0;
      for (int h = 0; h < 4; ++h) whine += kHarmonics[h] * std::sin(2 * kPi * (h + 1) * phase_);
      sample += spec_.motor_gain * motor_ * whine;
    }
    // The filter runs on, so the band is settled when cutting starts; silent at zero level.
    const double x = next_noise();
    const double y = b0_ * x + b1_ * x1_ + b2_ * x2_ - a1_ * y1_ - a2_ * y2_;
    x2_ = x1_;
    x1_ = x;
    y2_ = y1_;
    y1_ = y;
    if (cut_ > 0.0) sample += cut_ * y * 2.0;  // the band passes about half the noise's level

    const bool beeping = warning_ >= 0 && beep_phase_ - std::floor(beep_phase_) < 0.5;
    if (warning_ >= 0) beep_phase_ += 1.0 / (beep_period_ * rate);
    tone_env_ += ((beeping ? 1.0 : 0.0) - tone_env_) * edge_alpha;
    if (!beeping && tone_env_ < 1e-6) tone_env_ = 0.0;
    if (tone_env_ > 0.0) {
      tone_phase_ += tone_frequency_ / rate;
      tone_phase_ -= std::floor(tone_phase_);
      sample += spec_.warning_gain * tone_env_ * std::sin(2 * kPi * tone_phase_);
    } else {
      tone_phase_ = 0.0;
    }
    out[n] = static_cast<float>(std::clamp(sample, -1.0, 1.0));
  }
  ++tick_index_;
  return frames;
}

void DrillSynth::render(const std::vector<DrillTick>& ticks, std::vector<float>& out) {
  for (const DrillTick& tick : ticks) {
    const std::size_t at = out.size();
    out.resize(at + next_tick_frames());
    render_tick(tick, out.data() + at);
  }
}

std::vector<float> render_drill_sound(const DrillSoundSpec& spec,
                                      const std::vector<DrillTick>& ticks) {
  DrillSynth synth(spec);
  std::vector<float> out;
  out.reserve(static_cast<std::size_t>(ticks.size() * spec.frames_per_tick()) + 1);
  synth.render(ticks, out);
  return out;
}

}  // namespace ambfplus::audio
