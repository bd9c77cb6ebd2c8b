#include "ambfplus/scene/realtime.h"
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
#include "ambfplus/plugin/registry.h"
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

// Asks for the scheduling the options want and says what the thread got.
std::string schedule_this_thread(const RealTimeOptions& options) {
  std::string how = "SCHED_OTHER";
  bool fifo = false;
  if (options.fifo_priority > 0) {
    sched_param p{};
    p.sched_priority = std::clamp(options.fifo_priority, sched_get_priority_min(SCHED_FIFO),
                                  sched_get_priority_max(SCHED_FIFO));
    const int rc = pthread_setschedparam(pthread_self(), SCHED_FIFO, &p);
    if (rc == 0) {
      fifo = true;
      how = "SCHED_FIFO priority " + std::to_string(p.sched_priority);
    } else {
      how += std::string(" (SCHED_FIFO refused: ") + std::strerror(rc) + ")";
    }
  }
  const long cpus = sysconf(_SC_NPROCESSORS_ONLN);
  int cpu = options.cpu;
  if (cpu == -1) cpu = (!fifo && cpus > 1) ? static_cast<int>(cpus - 1) : -2;
  if (cpu >= 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(cpu, &set);
    const int rc = pthread_setaffinity_np(pthread_self(), sizeof(set), &set);
    how += rc == 0 ? ", pinned to CPU " + std::to_string(cpu)
                   : std::string(", pinning to CPU ") + std::to_string(cpu) +
                         " refused: " + std::strerror(rc);
  }
  return how;
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
    std::lock_guard<std::mutex> lock(mutex_);
    periods_.clear();
    step_cpu_.clear();
    step_wall_.clear();
    lock_wait_.clear();
    max_period_ = max_cpu_ = max_wall_ = max_wait_ = 0.0;
    over_2ms_ = 0;
    late_.clear();
    late_wall_.clear();
    late_cpu_.clear();
    steps_ = 0;
    error_.clear();
    scheduling_.clear();
  }
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
  {
    std::lock_guard<std::mutex> lock(mutex_);
    scheduling_ = schedule_this_thread(options_);
  }
  wake_.notify_all();
  const long period_ns = std::lround(1e9 / options_.rate);
  const double period = 1e-9 * static_cast<double>(period_ns);
  timespec deadline{};
  clock_gettime(CLOCK_MONOTONIC, &deadline);
  double previous = -1.0;
  while (!stopping_) {
    advance(deadline, period_ns);
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &deadline, nullptr) == EINTR) {
    }
    const double start = now();
    const double cpu = thread_cpu();
    double waited = 0.0;
    try {
      // The step takes the lock again (it is recursive): this measures the wait alone.
      auto state = world_.lock_state();
      waited = now() - start;
      world_.step(1);
    } catch (const std::exception& e) {
      std::lock_guard<std::mutex> lock(mutex_);
      error_ = e.what();
      stopping_ = true;
      break;
    }
    const double used = thread_cpu() - cpu;
    const double wall = now() - start;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (previous >= 0) {
        const double period = start - previous;
        periods_.push(period);
        max_period_ = std::max(max_period_, period);
        // Period n ends at step n + 1: the step before it ran late, or the wait for it did.
        if (period > 2e-3) {
          ++over_2ms_;
          if (late_.size() < RealTimeStats::kLateListed) {
            late_.push_back(steps_ - 1);
            late_wall_.push_back(last_wall_);
            late_cpu_.push_back(last_cpu_);
          }
        }
      }
      if (steps_ == 0) first_ = start;
      last_ = start;
      ++steps_;
      step_cpu_.push(used);
      step_wall_.push(wall);
      lock_wait_.push(waited);
      max_cpu_ = std::max(max_cpu_, used);
      max_wall_ = std::max(max_wall_, wall);
      max_wait_ = std::max(max_wait_, waited);
      last_wall_ = wall;
      last_cpu_ = used;
    }
    previous = start;
    // Far behind (a stall): start afresh from now rather than racing to catch up.
    if (start > seconds(deadline) + 50 * period) clock_gettime(CLOCK_MONOTONIC, &deadline);
  }
  wake_.notify_all();
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
      auto state = world_.lock_state();
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

void RealTimeLoop::Window::push(double v) {
  if (values.size() < RealTimeStats::kWindow) {
    values.push_back(v);
  } else {
    values[next] = v;
  }
  next = (next + 1) % RealTimeStats::kWindow;
}

std::vector<double> RealTimeLoop::Window::in_order() const {
  if (values.size() < RealTimeStats::kWindow) return values;
  std::vector<double> out(values.begin() + static_cast<std::ptrdiff_t>(next), values.end());
  out.insert(out.end(), values.begin(), values.begin() + static_cast<std::ptrdiff_t>(next));
  return out;
}

RealTimeStats RealTimeLoop::stats() const {
  RealTimeStats s;
  std::lock_guard<std::mutex> lock(mutex_);
  s.steps = steps_;
  s.periods = periods_.in_order();
  s.seconds = last_ - first_;
  s.step_p99 = percentile(step_cpu_.values, 0.99);
  s.step_cpu_max = max_cpu_;
  s.step_wall_max = max_wall_;
  s.lock_wait_max = max_wait_;
  s.lock_wait_p99 = percentile(lock_wait_.values, 0.99);
  s.late = late_;
  s.late_step_wall = late_wall_;
  s.late_step_cpu = late_cpu_;
  if (steps_ < 2) return s;
  s.mean_rate = s.seconds > 0 ? static_cast<double>(s.steps - 1) / s.seconds : 0.0;
  s.max = max_period_;
  s.p99 = percentile(periods_.values, 0.99);
  s.over_2ms = over_2ms_;
  return s;
}

}  // namespace ambfplus
