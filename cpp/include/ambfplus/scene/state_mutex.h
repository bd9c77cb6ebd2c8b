#pragma once

#include <pthread.h>

#include <mutex>

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

/// Runs the calling thread at SCHED_FIFO `priority` while it lives and then restores the
/// thread's scheduling. Does nothing for a priority <= 0, for a thread already at that
/// priority or above, or where the system refuses (no right to real-time scheduling).
class AMBFPLUS_API ScopedPriority {
 public:
  explicit ScopedPriority(int priority);
  ~ScopedPriority();
  ScopedPriority(const ScopedPriority&) = delete;
  ScopedPriority& operator=(const ScopedPriority&) = delete;
  /// Whether the thread runs raised now.
  bool raised() const { return raised_; }

 private:
  bool raised_ = false;
  int policy_ = 0;
  sched_param param_{};
};

/// A world's state lock held for a short copy, the thread's priority raised for the hold (see
/// World::lock_state_for_copy). The lock is released before the priority is restored.
class AMBFPLUS_API StateCopyLock {
 public:
  StateCopyLock(StateMutex& mutex, int priority) : priority_(priority), lock_(mutex) {}
  bool raised() const { return priority_.raised(); }

 private:
  ScopedPriority priority_;  // raised first, restored last
  std::unique_lock<StateMutex> lock_;
};

}  // namespace ambfplus
