#include "ambfplus/engine/realtime.h"
#include "ambfplus/errors.h"

#include <pthread.h>
#include <sched.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "ambfplus/haptics/input_device.h"
#include "ambfplus/log.h"
#include "ambfplus/scene/world.h"

namespace ambfplus {
namespace {

double seconds(const timespec& t) { return static_cast<double>(t.tv_sec) + 1e-9 * t.tv_nsec; }

double now() {
  timespec t{};
  clock_gettime(CLOCK_MONOTONIC, &t);
  return seconds(t);
}

double thread_cpu() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return seconds(t);
}

void advance(timespec& t, long nanoseconds) {
  t.tv_nsec += nanoseconds;
  while (t.tv_nsec >= 1000000000L) {
    t.tv_nsec -= 1000000000L;
    ++t.tv_sec;
  }
}

// How a thread was scheduled: in words, and the SCHED_FIFO priority it got (0: none).
struct Scheduling {
  std::string how;
  int fifo_priority = 0;
};

// Asks for the scheduling the options want and says what the thread got.
Scheduling schedule_this_thread(const RealTimeOptions& options) {
  Scheduling got{"SCHED_OTHER"};
  if (options.fifo_priority > 0) {
    sched_param p{};
    p.sched_priority = std::clamp(options.fifo_priority, sched_get_priority_min(SCHED_FIFO),
                                  sched_get_priority_max(SCHED_FIFO));
    const int rc = pthread_setschedparam(pthread_self(), SCHED_FIFO, &p);
    if (rc == 0) {
      got.fifo_priority = p.sched_priority;
      got.how = "SCHED_FIFO priority " + std::to_string(p.sched_priority);
    } else {
      got.how += std::string(" (SCHED_FIFO refused: ") + std::strerror(rc) + ")";
    }
  }
  const long cpus = sysconf(_SC_NPROCESSORS_ONLN);
  int cpu = options.cpu;
  if (cpu == -1) cpu = (got.fifo_priority == 0 && cpus > 1) ? static_cast<int>(cpus - 1) : -2;
  if (cpu >= 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(cpu, &set);
    const int rc = pthread_setaffinity_np(pthread_self(), sizeof(set), &set);
    got.how += rc == 0 ? ", pinned to CPU " + std::to_string(cpu)
                       : std::string(", pinning to CPU ") + std::to_string(cpu) +
                             " refused: " + std::strerror(rc);
  }
  return got;
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  const std::size_t k =
      std::min(v.size() - 1, static_cast<std::size_t>(std::ceil(q * v.size())) - 1);
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

}  // namespace

RealTimeLoop::RealTimeLoop(World& world, const RealTimeOptions& options)
    : world_(world), options_(options) {
  if (!(options.rate > 0 && options.rate <= 100000)) {
    throw ArgumentError("real-time loop: rate must be in (0, 100000] steps/s");
  }
  if (!(options.poll_rate > 0 && options.poll_rate <= options.rate)) {
    throw ArgumentError("real-time loop: poll_rate must be in (0, rate]");
  }
  if (options.fifo_priority < 0 || options.fifo_priority > 99) {
    throw ArgumentError(
        "real-time loop: fifo_priority must be 0 (do not ask) or 1..99 "
        "(Linux's SCHED_FIFO range), got " +
        std::to_string(options.fifo_priority));
  }
  const long cpus = sysconf(_SC_NPROCESSORS_CONF);
  if (options.cpu < -2 || (cpus > 0 && options.cpu >= cpus)) {
    throw ArgumentError(
        "real-time loop: cpu must be -2 (never pin), -1 (the last CPU when "
        "SCHED_FIFO is refused) or a CPU of this machine, 0.." +
        std::to_string(cpus - 1) + ", got " + std::to_string(options.cpu));
  }
}

RealTimeLoop::~RealTimeLoop() {
  try {
    stop();
  } catch (const std::exception& e) {
    log(LogLevel::kError, std::string("real-time loop: ") + e.what());
  }
}

void RealTimeLoop::start() {
  if (running_) throw StateError("the real-time loop is already running");
  if (!world_.enter_realtime()) {
    throw StateError("world '" + world_.name() + "' already has a running real-time loop");
  }
  {
    // Storage for the whole run, allocated here so that the loop's thread never allocates.
    std::lock_guard<std::mutex> lock(mutex_);
    for (Window* w : {&periods_, &step_cpu_, &step_wall_, &lock_wait_, &wake_late_}) w->reset();
    max_period_ = max_cpu_ = max_wall_ = max_wait_ = max_wake_ = 0.0;
    over_2ms_ = 0;
    for (std::vector<double>* v :
         {&late_wall_, &late_cpu_, &late_wait_, &late_start_, &late_wake_}) {
      v->clear();
      v->reserve(RealTimeStats::kLateListed);
    }
    late_.clear();
    late_.reserve(RealTimeStats::kLateListed);
    steps_ = 0;
    first_ = last_ = 0.0;
    last_record_ = StepRecord{};
    error_.clear();
    scheduling_.clear();
  }
  pending_count_ = 0;
  stopping_ = false;
  running_ = true;
  steps_thread_ = std::thread([this] { run_steps(); });
  polls_thread_ = std::thread([this] { run_polls(); });
  // Report the scheduling once the thread has it.
  std::unique_lock<std::mutex> lock(mutex_);
  wake_.wait(lock, [this] { return !scheduling_.empty(); });
}

void RealTimeLoop::stop() {
  if (!running_) return;
  stopping_ = true;
  wake_.notify_all();
  if (steps_thread_.joinable()) steps_thread_.join();
  if (polls_thread_.joinable()) polls_thread_.join();
  running_ = false;
  world_.leave_realtime();
  std::lock_guard<std::mutex> lock(mutex_);
  if (!error_.empty()) {
    const std::string error = error_;
    error_.clear();
    throw StateError("real-time loop stopped by an error in a step: " + error);
  }
}

std::string RealTimeLoop::scheduling() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return scheduling_;
}

void RealTimeLoop::set_poll_hook(std::function<void(double)> hook) {
  std::lock_guard<std::mutex> lock(mutex_);
  poll_hook_ = std::move(hook);
}

void RealTimeLoop::run_steps() {
  const Scheduling scheduling = schedule_this_thread(options_);
  // Threads copying out of the world run just below this one while they hold its lock.
  world_.set_realtime_priority(scheduling.fifo_priority);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    scheduling_ = scheduling.how;
  }
  wake_.notify_all();
  const long period_ns = std::lround(1e9 / options_.rate);
  const double period = 1e-9 * static_cast<double>(period_ns);
  timespec deadline{};
  clock_gettime(CLOCK_MONOTONIC, &deadline);
  while (!stopping_) {
    advance(deadline, period_ns);
    // When the thread could begin the next step: its deadline, or now if that has passed.
    const double ready = now();
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &deadline, nullptr) == EINTR) {
    }
    StepRecord r;
    r.start = now();
    r.wake_late = std::max(0.0, r.start - std::max(seconds(deadline), ready));
    const double cpu = thread_cpu();
    try {
      // The step takes the lock again (it is recursive): this measures the wait alone.
      const double asked = now();
      auto state = world_.lock_state();
      r.lock_wait = now() - asked;
      world_.step(1);
    } catch (const std::exception& e) {
      std::lock_guard<std::mutex> lock(mutex_);
      error_ = e.what();
      stopping_ = true;
      break;
    }
    r.cpu = thread_cpu() - cpu;
    r.wall = now() - r.start;
    record(r);
    // Far behind (a stall): start afresh from now rather than racing to catch up.
    if (r.start > seconds(deadline) + 50 * period) clock_gettime(CLOCK_MONOTONIC, &deadline);
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    flush_records();
  }
  wake_.notify_all();
}

void RealTimeLoop::record(const StepRecord& r) {
  pending_[pending_count_++] = r;
  if (pending_count_ == kPending) {
    std::lock_guard<std::mutex> lock(mutex_);
    flush_records();
  } else if (mutex_.try_lock()) {
    flush_records();
    mutex_.unlock();
  }
}

void RealTimeLoop::flush_records() {
  for (std::size_t i = 0; i < pending_count_; ++i) {
    const StepRecord& r = pending_[i];
    if (steps_ > 0) {
      const double period = r.start - last_;
      periods_.push(period);
      max_period_ = std::max(max_period_, period);
      // Period n ends at step n + 1: the step before it ran long, or this one began late.
      if (period > 2e-3) {
        ++over_2ms_;
        if (late_.size() < RealTimeStats::kLateListed) {
          late_.push_back(steps_ - 1);
          late_wall_.push_back(last_record_.wall);
          late_cpu_.push_back(last_record_.cpu);
          late_wait_.push_back(last_record_.lock_wait);
          late_start_.push_back(last_record_.start);
          late_wake_.push_back(r.wake_late);
        }
      }
    } else {
      first_ = r.start;
    }
    last_ = r.start;
    ++steps_;
    step_cpu_.push(r.cpu);
    step_wall_.push(r.wall);
    lock_wait_.push(r.lock_wait);
    wake_late_.push(r.wake_late);
    max_cpu_ = std::max(max_cpu_, r.cpu);
    max_wall_ = std::max(max_wall_, r.wall);
    max_wait_ = std::max(max_wait_, r.lock_wait);
    max_wake_ = std::max(max_wake_, r.wake_late);
    last_record_ = r;
  }
  pending_count_ = 0;
}

void RealTimeLoop::run_polls() {
  const auto period = std::chrono::duration<double>(1.0 / options_.poll_rate);
  double previous = 0.0;
  {
    auto state = world_.lock_state();
    previous = world_.time();
  }
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stopping_) {
    wake_.wait_for(lock, period, [this] { return stopping_.load(); });
    if (stopping_) break;
    std::function<void(double)> hook = poll_hook_;
    lock.unlock();
    // Polled devices' samplers run without the world's lock: they compute a reading.
    std::vector<InputDevice*> devices;
    double time = 0.0;
    {
      auto state = world_.lock_state_for_copy();
      devices = world_.objects_of_kind<InputDevice>();
      time = world_.time();
    }
    for (InputDevice* d : devices) {
      if (d->device()->polled()) d->device()->poll(time);
    }
    if (hook) hook(time - previous);
    previous = time;
    lock.lock();
  }
}

void RealTimeLoop::Window::reset() {
  values.assign(RealTimeStats::kWindow, 0.0);
  size = next = 0;
}

void RealTimeLoop::Window::push(double v) {
  values[next] = v;
  next = (next + 1) % RealTimeStats::kWindow;
  size = std::min(size + 1, RealTimeStats::kWindow);
}

std::vector<double> RealTimeLoop::Window::in_order() const {
  if (size < RealTimeStats::kWindow) return held();
  std::vector<double> out(values.begin() + static_cast<std::ptrdiff_t>(next), values.end());
  out.insert(out.end(), values.begin(), values.begin() + static_cast<std::ptrdiff_t>(next));
  return out;
}

std::vector<double> RealTimeLoop::Window::held() const {
  return std::vector<double>(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(size));
}

RealTimeStats RealTimeLoop::stats() const {
  RealTimeStats s;
  std::vector<double> cpu, waits, wakes;
  {
    // Copies only: the loop's thread keeps its records while this holds the lock.
    std::lock_guard<std::mutex> lock(mutex_);
    s.steps = steps_;
    s.periods = periods_.in_order();
    s.seconds = last_ - first_;
    s.first_start = first_;
    s.step_cpu_max = max_cpu_;
    s.step_wall_max = max_wall_;
    s.lock_wait_max = max_wait_;
    s.wake_late_max = max_wake_;
    s.late = late_;
    s.late_step_wall = late_wall_;
    s.late_step_cpu = late_cpu_;
    s.late_step_lock_wait = late_wait_;
    s.late_start = late_start_;
    s.late_wake = late_wake_;
    s.max = max_period_;
    s.over_2ms = over_2ms_;
    cpu = step_cpu_.held();
    waits = lock_wait_.held();
    wakes = wake_late_.held();
  }
  s.step_p99 = percentile(std::move(cpu), 0.99);
  s.lock_wait_p99 = percentile(std::move(waits), 0.99);
  s.wake_late_p99 = percentile(std::move(wakes), 0.99);
  if (s.steps < 2) {
    s.max = 0.0;
    s.over_2ms = 0;
    return s;
  }
  s.mean_rate = s.seconds > 0 ? static_cast<double>(s.steps - 1) / s.seconds : 0.0;
  s.p99 = percentile(s.periods, 0.99);
  return s;
}

}  // namespace ambfplus
