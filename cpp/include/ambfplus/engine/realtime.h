#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "ambfplus/export.h"

namespace ambfplus {

class World;

/// How a real-time loop runs.
struct AMBFPLUS_API RealTimeOptions {
  double rate = 1000.0;  ///< steps per wall-clock second (each advances the world's time step)
  /// Ask for SCHED_FIFO at this priority (1..99; 0: do not ask). Refused without the right
  /// (CAP_SYS_NICE or an rtprio limit), which the loop reports and survives.
  int fifo_priority = 80;
  /// Pin the loop's thread to this CPU; -1: the last CPU, but only when SCHED_FIFO was refused
  /// and there is more than one; -2: never.
  int cpu = -1;
  double poll_rate = 100.0;  ///< Hz of the polling thread (devices and plugins of Python)
};

/// Periods of a real-time loop, seconds between consecutive step starts. Counts and maxima
/// cover the whole run; percentiles and the periods listed cover the last kWindow steps (a
/// minute at 1 kHz), so a session of any length keeps flat memory.
struct AMBFPLUS_API RealTimeStats {
  static constexpr std::size_t kWindow = 65536;
  /// Late periods listed at most (the count over 2 ms covers them all).
  static constexpr std::size_t kLateListed = 1024;
  std::int64_t steps = 0;
  double seconds = 0.0;         ///< wall time from the first step to the last
  double first_start = 0.0;     ///< CLOCK_MONOTONIC time the first step began, s
  std::vector<double> periods;  ///< the last periods (up to kWindow), oldest first
  double mean_rate = 0.0;       ///< steps per second
  double p99 = 0.0, max = 0.0;  ///< s
  std::int64_t over_2ms = 0;    ///< periods longer than 2 ms
  double step_p99 = 0.0;        ///< s of thread CPU time per step, 99th percentile
  double step_cpu_max = 0.0;    ///< s of thread CPU time of the costliest step
  double step_wall_max = 0.0;   ///< s of wall time of the longest step (lock waits included)
  /// s the loop's thread waited for the world's state lock before a step: the longest, and the
  /// 99th percentile (other threads hold it only to copy or change the scene).
  double lock_wait_max = 0.0, lock_wait_p99 = 0.0;
  /// s a step began after it was due (its deadline, or the end of the step before it when that
  /// one ran past the deadline): the time the kernel, or the host of a virtual machine, took to
  /// run the thread, which no step of ours can cause. The longest, and the 99th percentile.
  double wake_late_max = 0.0, wake_late_p99 = 0.0;
  /// Periods over 2 ms (the first kLateListed): their index; the wall time, CPU time and lock
  /// wait of the step that began them; the CLOCK_MONOTONIC time they began (s, to line them up
  /// with other clocks); and how late the step that ended them began (as wake_late). A period
  /// is step wall + the sleep to the deadline + the wake-up's lateness: a long wall time is the
  /// step's, a large lateness the machine's.
  std::vector<std::int64_t> late;
  std::vector<double> late_step_wall, late_step_cpu, late_step_lock_wait, late_start, late_wake;
};

/// Steps a world in real time on a thread of its own: one world step per period at absolute
/// deadlines (clock_nanosleep on CLOCK_MONOTONIC, so lateness does not accumulate; a loop more
/// than 50 periods behind gives up catching up). Each step takes the world's state lock, so
/// cameras may capture from other threads meanwhile. Devices and plugins that call into Python
/// are served by a second, low-rate thread (poll_rate), never by the loop's: polled devices are
/// polled there, and other-language plugins get their physics update there with the time since
/// the last one. Everything else about a step is what World::step does, so a session's logged
/// device readings replay exactly in scripted mode.
class AMBFPLUS_API RealTimeLoop {
 public:
  explicit RealTimeLoop(World& world, const RealTimeOptions& options = {});
  /// Stops the loop.
  ~RealTimeLoop();
  RealTimeLoop(const RealTimeLoop&) = delete;
  RealTimeLoop& operator=(const RealTimeLoop&) = delete;

  /// Starts the threads; throws StateError if running or if the world has another loop.
  void start();
  /// Stops after the step in progress and joins the threads. A step that threw ends the loop;
  /// stop() then throws its error again.
  void stop();
  bool running() const { return running_; }
  World& world() const { return world_; }

  /// How the loop's thread was scheduled: "SCHED_FIFO priority 80", or "SCHED_OTHER (SCHED_FIFO
  /// refused: ...), pinned to CPU 1", and so on.
  std::string scheduling() const;
  /// Periods so far (also after stop()).
  RealTimeStats stats() const;
  /// Called on the polling thread at poll_rate after devices were polled (the Python bindings
  /// use it to run Python plugins); runs without the world's lock unless it takes it.
  void set_poll_hook(std::function<void(double dt)> hook);

 private:
  /// What one step measured, s.
  struct StepRecord {
    double start = 0.0, cpu = 0.0, wall = 0.0, lock_wait = 0.0, wake_late = 0.0;
  };
  /// The last kWindow values of something measured every step, in storage allocated by
  /// reset() (off the loop's thread) and never reallocated.
  struct Window {
    std::vector<double> values;
    std::size_t size = 0, next = 0;
    void reset();
    void push(double v);
    std::vector<double> in_order() const;  // oldest first
    std::vector<double> held() const;      // in storage order
  };
  /// Steps a loop's thread measured but has not yet added to the statistics: it adds them
  /// when mutex_ is free, so it never waits for a thread reading them.
  static constexpr std::size_t kPending = 256;

  void run_steps();
  void run_polls();
  /// Keeps a step's record (the loop's thread only).
  void record(const StepRecord& r);
  /// Adds the pending records to the statistics (mutex_ held).
  void flush_records();

  World& world_;
  RealTimeOptions options_;
  std::atomic<bool> running_{false};
  std::atomic<bool> stopping_{false};
  std::thread steps_thread_, polls_thread_;
  StepRecord pending_[kPending];  // the loop's thread only
  std::size_t pending_count_ = 0;
  mutable std::mutex mutex_;  // guards what follows
  std::condition_variable wake_;
  std::string scheduling_;
  Window periods_, step_cpu_, step_wall_, lock_wait_, wake_late_;
  double max_period_ = 0.0, max_cpu_ = 0.0, max_wall_ = 0.0, max_wait_ = 0.0, max_wake_ = 0.0;
  std::int64_t over_2ms_ = 0;
  std::vector<std::int64_t> late_;
  std::vector<double> late_wall_, late_cpu_, late_wait_, late_start_, late_wake_;
  std::int64_t steps_ = 0;
  double first_ = 0.0, last_ = 0.0;
  StepRecord last_record_;  // the step before the current period
  std::string error_;
  std::function<void(double)> poll_hook_;
};

}  // namespace ambfplus
