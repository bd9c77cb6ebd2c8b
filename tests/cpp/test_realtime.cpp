#include <gtest/gtest.h>
#include <pthread.h>
#include <sched.h>
#include <time.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <thread>

#include "ambfplus/engine/engine.h"
#include "ambfplus/engine/realtime.h"
#include "ambfplus/scene/simulator.h"
#include "ambfplus/scene/state_mutex.h"

namespace ambfplus {
namespace {

double monotonic() {
  timespec t{};
  clock_gettime(CLOCK_MONOTONIC, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * t.tv_nsec;
}

int policy_of_this_thread(int* priority) {
  int policy = 0;
  sched_param p{};
  pthread_getschedparam(pthread_self(), &policy, &p);
  *priority = p.sched_priority;
  return policy;
}

// Whether this process may use SCHED_FIFO up to priority 90 (root, CAP_SYS_NICE or an rtprio
// limit).
bool fifo_allowed() {
  bool allowed = false;
  std::thread([&] {
    sched_param p{};
    p.sched_priority = 90;
    allowed = pthread_setschedparam(pthread_self(), SCHED_FIFO, &p) == 0;
  }).join();
  return allowed;
}

TEST(ScopedPriority, RaisesForItsLifetimeAndRestores) {
  if (!fifo_allowed()) GTEST_SKIP() << "no right to SCHED_FIFO here";
  std::thread([] {
    int priority = -1;
    ASSERT_EQ(policy_of_this_thread(&priority), SCHED_OTHER);
    {
      ScopedPriority raised(7);
      EXPECT_TRUE(raised.raised());
      EXPECT_EQ(policy_of_this_thread(&priority), SCHED_FIFO);
      EXPECT_EQ(priority, 7);
      // Already at or above: nothing to do, and nothing undone on the way out.
      ScopedPriority lower(5);
      EXPECT_FALSE(lower.raised());
    }
    EXPECT_EQ(policy_of_this_thread(&priority), SCHED_OTHER);
    EXPECT_EQ(priority, 0);
    ScopedPriority none(0);
    EXPECT_FALSE(none.raised());
  }).join();
}

TEST(World, LocksForACopyJustBelowARunningLoop) {
  auto sim = engine::create_simulator();
  World& world = sim->world();
  std::thread([&] {
    // No loop: an ordinary lock.
    EXPECT_FALSE(world.lock_state_for_copy().raised());
  }).join();
  if (!fifo_allowed()) GTEST_SKIP() << "no right to SCHED_FIFO here";
  RealTimeLoop loop(world, RealTimeOptions{});
  loop.start();
  EXPECT_EQ(world.realtime_priority(), 80);
  std::thread([&] {
    auto lock = world.lock_state_for_copy();
    EXPECT_TRUE(lock.raised());
    int priority = 0;
    EXPECT_EQ(policy_of_this_thread(&priority), SCHED_FIFO);
    EXPECT_EQ(priority, 79);
  }).join();
  loop.stop();
  EXPECT_EQ(world.realtime_priority(), 0);
}

// A thread holding the world's lock for 5 ms delays one step: the period it begins is long
// because that step waited for the lock (its wall time), not because a wake-up came late.
TEST(RealTimeLoop, LatePeriodsSayWhetherTheStepOrTheWakeUpWasLate) {
  auto sim = engine::create_simulator();
  World& world = sim->world();
  RealTimeLoop loop(world);
  const double before = monotonic();
  loop.start();
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  double held_from = 0.0, held_to = 0.0;
  {
    auto lock = world.lock_state();
    held_from = monotonic();
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    held_to = monotonic();
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  loop.stop();
  const RealTimeStats s = loop.stats();
  EXPECT_GE(s.first_start, before);
  EXPECT_LE(s.first_start, held_from);
  EXPECT_GE(s.lock_wait_max, 3e-3);
  EXPECT_GE(s.over_2ms, 1);
  ASSERT_EQ(s.late.size(), static_cast<std::size_t>(s.over_2ms));
  for (const auto* v :
       {&s.late_step_wall, &s.late_step_cpu, &s.late_step_lock_wait, &s.late_start, &s.late_wake}) {
    EXPECT_EQ(v->size(), s.late.size());
  }
  // The period that began with the waiting step: it began while the lock was held, waited,
  // and the step after it began as soon as it could (no lateness of its own to speak of).
  bool found = false;
  for (std::size_t i = 0; i < s.late.size(); ++i) {
    if (s.late_step_lock_wait[i] < 3e-3) continue;
    found = true;
    EXPECT_GE(s.late_start[i], held_from - 1.5e-3);
    EXPECT_LE(s.late_start[i], held_to);
    EXPECT_GE(s.late_step_wall[i], s.late_step_lock_wait[i]);
    EXPECT_LT(s.late_step_cpu[i], s.late_step_lock_wait[i]);
    EXPECT_LT(s.late_wake[i], 1e-3);
  }
  EXPECT_TRUE(found);
  // Percentiles and maxima of the wake-ups are filled and consistent.
  EXPECT_GE(s.wake_late_max, s.wake_late_p99);
  EXPECT_GT(s.steps, 50);
}

// A thread that keeps the loop's CPU from it (here a busy thread of a higher priority, as a
// host that takes the virtual CPU away would) shows as time the loop's thread was kept from
// running: a late wake-up, or (if it struck mid-step) a step's wall time beyond its CPU time
// that was no lock wait.
TEST(RealTimeLoop, ACpuTakenAwayShowsAsTimeOffTheCpu) {
  if (!fifo_allowed()) GTEST_SKIP() << "no right to SCHED_FIFO here";
  auto sim = engine::create_simulator();
  World& world = sim->world();
  RealTimeOptions options;
  options.cpu = 0;
  RealTimeLoop loop(world, options);
  loop.start();
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  std::thread([&] {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(0, &set);
    pthread_setaffinity_np(pthread_self(), sizeof(set), &set);
    sched_param p{};
    p.sched_priority = 90;
    ASSERT_EQ(pthread_setschedparam(pthread_self(), SCHED_FIFO, &p), 0);
    const double from = monotonic();
    while (monotonic() < from + 5e-3) {
    }
  }).join();
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  loop.stop();
  const RealTimeStats s = loop.stats();
  bool found = false;
  for (std::size_t i = 0; i < s.late.size(); ++i) {
    const double off_cpu =
        s.late_wake[i] + s.late_step_wall[i] - s.late_step_cpu[i] - s.late_step_lock_wait[i];
    if (off_cpu < 3e-3) continue;
    found = true;
    EXPECT_LT(s.late_step_cpu[i], 1e-3);
    EXPECT_LT(s.late_step_lock_wait[i], 1e-3);
  }
  EXPECT_TRUE(found);
}

}  // namespace
}  // namespace ambfplus
