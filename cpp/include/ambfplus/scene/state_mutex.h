#pragma once

#include <pthread.h>

#include "ambfplus/export.h"

namespace ambfplus {

/// A world's state lock: recursive, and with priority inheritance, so a thread holding it runs
/// at the priority of the most urgent thread waiting for it. A real-time loop's SCHED_FIFO
/// thread that finds a capture copying the scene then waits for the copy alone, never for the
/// scheduler to get round to the copying thread. Meets the standard Lockable requirements.
class AMBFPLUS_API StateMutex {
 public:
  StateMutex();
  ~StateMutex();
  StateMutex(const StateMutex&) = delete;
  StateMutex& operator=(const StateMutex&) = delete;

  void lock();
  bool try_lock();
  void unlock() noexcept;

 private:
  pthread_mutex_t mutex_;
};

}  // namespace ambfplus
