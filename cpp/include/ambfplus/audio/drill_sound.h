#pragma once

// Live drill sound: a player that runs the synthesiser (audio/drill_synth.h) on the audio
// library's thread, fed tick by tick without locks, and DrillSound, which feeds a player from a
// drill at every step of its world (the haptic thread of a real-time loop).
//
// The audio library is miniaudio (cpp/third_party/miniaudio/README.md says why): its null
// backend plays at the real rate without a sound card, for tests and the latency benchmark.

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "ambfplus/audio/drill_synth.h"
#include "ambfplus/export.h"

namespace ambfplus {
class Drill;
class World;
}  // namespace ambfplus

namespace ambfplus::audio {

struct SoundFeed;

/// Where a player's samples go.
enum class AudioOutput {
  kNone,    ///< nowhere: silent, nothing opened
  kDevice,  ///< the default output device (PulseAudio, ALSA or JACK, the first that opens)
  kNull,    ///< the library's null device: consumed at the real rate, heard by nobody
  /// A virtual sound card (miniaudio's custom backend): no hardware, a clock of its own that
  /// asks for one period at each period's deadline, as a card's interrupt does; heard by nobody.
  kVirtual,
};

/// How a player plays.
struct AMBFPLUS_API PlayerOptions {
  AudioOutput output = AudioOutput::kDevice;
  /// Without a device, throw ResourceError instead of saying so once and carrying on silent.
  bool require_device = false;
  bool muted = false;
  /// Frames per audio callback asked of the device (a hint some devices round).
  int period_frames = 128;
  /// Ticks that may wait for the audio thread beyond what its next callback needs; older ones
  /// are dropped (a world stepped faster than real time), so the latency stays bounded. Enough
  /// for a device that asks in bursts (miniaudio's null device wakes every 10 ms).
  int max_backlog_ticks = 16;
  /// Drops a backlog that never drains (the fewest ticks left waiting after a callback, over
  /// about 0.17 s of callbacks): a queue that only grew once is delay for nothing.
  bool trim_backlog = true;
  /// Opens the device without starting it (set_paused(false) starts it); ticks queue meanwhile.
  bool paused = false;
  /// Capacity of the tick queue (ticks).
  int queue_ticks = 4096;
  /// Samples played that are kept for take_capture() (tests, benchmarks); 0 keeps none.
  int capture_frames = 0;
};

/// Counters of a player since it started.
struct AMBFPLUS_API PlayerStats {
  std::int64_t pushed = 0;     ///< ticks accepted
  std::int64_t rejected = 0;   ///< ticks refused: the queue was full
  std::int64_t played = 0;     ///< ticks rendered
  std::int64_t dropped = 0;    ///< ticks skipped to keep the latency bounded
  std::int64_t held = 0;       ///< ticks the audio thread repeated while none had arrived
  std::int64_t callbacks = 0;  ///< audio callbacks
  std::int64_t frames = 0;     ///< frames delivered to the device
};

/// Plays a drill's sound live. push() (one producer thread) never blocks or allocates; the
/// audio thread renders each tick's frames with a DrillSynth as the device asks for them,
/// repeats the last tick when none has arrived (silence before the first), and drops the
/// oldest when too many wait. Without drops or repeats it plays exactly render_drill_sound().
class AMBFPLUS_API DrillSoundPlayer {
 public:
  /// Opens the output. Throws ArgumentError for a bad spec or option, ResourceError when there
  /// is no device and options.require_device is set; otherwise a missing device is logged once
  /// per process (a warning) and the player carries on silent (device_error() says why).
  DrillSoundPlayer(const DrillSoundSpec& spec, const PlayerOptions& options = {});
  ~DrillSoundPlayer();
  DrillSoundPlayer(const DrillSoundPlayer&) = delete;
  DrillSoundPlayer& operator=(const DrillSoundPlayer&) = delete;

  const DrillSoundSpec& spec() const;
  const PlayerOptions& options() const;

  /// Queues one tick (stamped with the time now); false when the queue is full. Lock-free; one
  /// producer thread at a time.
  bool push(DrillTick tick);
  /// Stops or restarts the device (ticks queue while paused, up to the queue's capacity).
  void set_paused(bool paused);
  bool paused() const;
  /// Silences the output (the synthesiser keeps running, so unmuting resumes in step).
  void set_muted(bool muted);
  bool muted() const;
  /// Whether a device (or the null or virtual device) is playing.
  bool playing() const;
  /// Why no device plays ("" when one does, or when none was asked for).
  const std::string& device_error() const;
  /// The backend playing ("pulseaudio", "alsa", "jack", "null", "virtual"), "" for none.
  const std::string& backend() const;
  /// Frames per callback the device settled on (0 without a device).
  int period_frames() const;

  /// Stops the device (pushes are then refused); idempotent.
  void close();

  /// Latencies since the last take, seconds: for each tick played, from its push to the moment
  /// the audio thread writes its first sample into the device's buffer (what the device then
  /// adds, its own buffering, is not in it). One consumer thread at a time.
  std::vector<double> take_latencies();
  /// The samples played since the last take (after muting), up to options().capture_frames.
  std::vector<float> take_capture();
  PlayerStats stats() const;

  /// The audio thread's work for one callback: fills out with frames samples. Public so that a
  /// caller without a device (a test) can run the same path by hand; never call it while a
  /// device plays.
  void fill(float* out, std::uint32_t frames);

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

/// A drill's live sound: a player fed from the drill at every step of its world, after the
/// drills have ticked (on the haptic thread of a real-time loop): the burr's state, its force,
/// the tissue it removed in that step and the distances to the warning list's structures. It
/// must not outlive the world (Python's handles keep the world alive); if its drill leaves the
/// world it stops being fed.
class AMBFPLUS_API DrillSound {
 public:
  /// Starts feeding a player from the drill. spec.tick_seconds is set to the world's step; the
  /// warnings' labels pick the drill's critical distances (a label the drill does not track
  /// stays silent). hardness[label] is the tissue's hardness (1 for labels beyond it).
  DrillSound(Drill& drill, DrillSoundSpec spec, const PlayerOptions& options = {},
             std::vector<double> hardness = {});
  /// Stops feeding and closes the player.
  ~DrillSound();
  DrillSound(const DrillSound&) = delete;
  DrillSound& operator=(const DrillSound&) = delete;

  Drill& drill() const { return *drill_; }
  DrillSoundPlayer& player() const { return *player_; }
  /// Stops feeding (under the world's lock) and closes the player; idempotent.
  void close();
  bool closed() const { return closed_; }

  /// The tick the drill's state gives now (what a step feeds the player).
  DrillTick tick_now(std::int64_t step) const;

 private:
  Drill* drill_;
  World* world_;
  std::shared_ptr<DrillSoundPlayer> player_;
  std::shared_ptr<SoundFeed> feed_;
  bool closed_ = false;
};

}  // namespace ambfplus::audio
