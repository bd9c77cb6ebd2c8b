#pragma once

// The calling thread's CPU time: what a tick costs, whatever else the machine is doing.

#include <time.h>

namespace ambfplus::util {

inline double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

}  // namespace ambfplus::util
