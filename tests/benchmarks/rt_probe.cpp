// A witness for the real-time benchmark: one thread per CPU asked for, pinned there at
// SCHED_FIFO, waking every millisecond at absolute deadlines (CLOCK_MONOTONIC) and noting every
// wake-up later than a threshold. A thread of the highest priority on its CPU that wakes late
// was not run by that CPU: the host had taken the virtual CPU away (steal time), or the kernel
// held it (interrupts, code that cannot be preempted). A late period of the physics loop during
// which this witness, on the same CPU, also waited is the machine's; one during which it ran on
// time is ours.
//
//   rt_probe PRIORITY THRESHOLD_US CPU [CPU ...]
//
// Prints "ready" once every thread runs, then probes until its standard input closes, then
// prints one JSON object: per CPU, the scheduling it got, its wake-ups, the median, 99th
// percentile and largest lateness (us), and its late wake-ups as [deadline s, lateness s].
// A line "phase SECONDS" on standard input (a CLOCK_MONOTONIC time the loop woke at) moves the
// deadlines half a period away from the loop's, so that the witness rarely preempts a step.

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <time.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

namespace {

constexpr long kPeriodNs = 1000000;
constexpr int kBuckets = 100001;  // lateness histogram, 1 us buckets up to 100 ms

std::atomic<bool> stopping{false};
std::atomic<long long> phase_ns{-1};  // the loop's wake-ups, mod the period; -1: unknown

long long nanoseconds(const timespec& t) { return t.tv_sec * 1000000000LL + t.tv_nsec; }
timespec from_nanoseconds(long long ns) {
  return timespec{static_cast<time_t>(ns / 1000000000LL), static_cast<long>(ns % 1000000000LL)};
}

double seconds(const timespec& t) { return static_cast<double>(t.tv_sec) + 1e-9 * t.tv_nsec; }

struct Probe {
  int cpu = 0;
  int priority = 0;
  double threshold = 0.0;
  std::string scheduling;
  std::atomic<bool> ready{false};
  long wakes = 0;
  std::vector<unsigned> histogram = std::vector<unsigned>(kBuckets, 0);
  std::vector<double> late;  // deadline, lateness, ...

  void run() {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(cpu, &set);
    int rc = pthread_setaffinity_np(pthread_self(), sizeof(set), &set);
    scheduling =
        rc == 0 ? "CPU " + std::to_string(cpu) : std::string("unpinned: ") + std::strerror(rc);
    sched_param p{};
    p.sched_priority = priority;
    rc = pthread_setschedparam(pthread_self(), SCHED_FIFO, &p);
    scheduling += rc == 0 ? ", SCHED_FIFO priority " + std::to_string(priority)
                          : std::string(", SCHED_OTHER: ") + std::strerror(rc);
    late.reserve(1 << 20);
    timespec deadline{};
    clock_gettime(CLOCK_MONOTONIC, &deadline);
    ready = true;
    long long phased = -1;
    while (!stopping) {
      const long long phase = phase_ns;
      if (phase != phased) {
        // Half a period after one of the loop's deadlines, the first still ahead.
        const long long target = (phase + kPeriodNs / 2) % kPeriodNs;
        long long next = nanoseconds(deadline) - nanoseconds(deadline) % kPeriodNs + target;
        while (next <= nanoseconds(deadline)) next += kPeriodNs;
        deadline = from_nanoseconds(next - kPeriodNs);
        phased = phase;
      }
      deadline.tv_nsec += kPeriodNs;
      while (deadline.tv_nsec >= 1000000000L) {
        deadline.tv_nsec -= 1000000000L;
        ++deadline.tv_sec;
      }
      while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &deadline, nullptr) == EINTR) {
      }
      timespec woke{};
      clock_gettime(CLOCK_MONOTONIC, &woke);
      const double due = seconds(deadline);
      const double lateness = seconds(woke) - due;
      ++wakes;
      const long us = static_cast<long>(lateness * 1e6);
      ++histogram[us < 0 ? 0 : us >= kBuckets ? kBuckets - 1 : us];
      if (lateness > threshold && late.size() + 2 <= late.capacity()) {
        late.push_back(due);
        late.push_back(lateness);
      }
      // After a stall, the next deadline still ahead (missed ones are one late wake-up).
      while (seconds(deadline) + 1e-9 * kPeriodNs < seconds(woke)) {
        deadline.tv_nsec += kPeriodNs;
        while (deadline.tv_nsec >= 1000000000L) {
          deadline.tv_nsec -= 1000000000L;
          ++deadline.tv_sec;
        }
      }
    }
  }

  // Lateness at quantile q of the wake-ups, us.
  long quantile(double q) const {
    const double want = q * static_cast<double>(wakes);
    double seen = 0;
    for (int b = 0; b < kBuckets; ++b) {
      seen += histogram[b];
      if (seen >= want && seen > 0) return b;
    }
    return 0;
  }
};

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: rt_probe PRIORITY THRESHOLD_US CPU [CPU ...]\n");
    return 2;
  }
  // Page faults must not make the witness late.
  mlockall(MCL_CURRENT | MCL_FUTURE);
  std::vector<Probe> probes(static_cast<std::size_t>(argc - 3));
  for (std::size_t i = 0; i < probes.size(); ++i) {
    probes[i].priority = std::atoi(argv[1]);
    probes[i].threshold = 1e-6 * std::atof(argv[2]);
    probes[i].cpu = std::atoi(argv[3 + i]);
  }
  std::vector<std::thread> threads;
  for (Probe& p : probes) threads.emplace_back([&p] { p.run(); });
  for (Probe& p : probes) {
    while (!p.ready) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  std::printf("ready\n");
  std::fflush(stdout);
  char line[256];
  while (std::fgets(line, sizeof line, stdin) != nullptr) {
    double seconds = 0.0;
    if (std::sscanf(line, "phase %lf", &seconds) == 1) {
      phase_ns = static_cast<long long>(seconds * 1e9) % kPeriodNs;
    }
  }
  stopping = true;
  for (std::thread& t : threads) t.join();
  std::printf("{\"probes\": [");
  for (std::size_t i = 0; i < probes.size(); ++i) {
    const Probe& p = probes[i];
    long max_us = 0;
    for (int b = 0; b < kBuckets; ++b) {
      if (p.histogram[b] > 0) max_us = b;
    }
    std::printf(
        "%s{\"cpu\": %d, \"scheduling\": \"%s\", \"wakes\": %ld, \"p50_us\": %ld, "
        "\"p99_us\": %ld, \"max_us\": %ld, \"late\": [",
        i ? ", " : "", p.cpu, p.scheduling.c_str(), p.wakes, p.quantile(0.5), p.quantile(0.99),
        max_us);
    for (std::size_t k = 0; k + 1 < p.late.size(); k += 2) {
      std::printf("%s[%.9f, %.9f]", k ? ", " : "", p.late[k], p.late[k + 1]);
    }
    std::printf("]}");
  }
  std::printf("]}\n");
  return 0;
}
