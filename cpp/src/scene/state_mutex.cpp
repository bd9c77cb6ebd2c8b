#include "ambfplus/scene/state_mutex.h"

#include <sched.h>

#include <cerrno>
#include <cstring>
#include <string>

#include "ambfplus/errors.h"

namespace ambfplus {
namespace {

void check(int rc, const char* what) {
  if (rc != 0) throw Error(std::string("world state lock: ") + what + ": " + std::strerror(rc));
}

}  // namespace

StateMutex::StateMutex() {
  pthread_mutexattr_t attributes;
  check(pthread_mutexattr_init(&attributes), "pthread_mutexattr_init");
  pthread_mutexattr_settype(&attributes, PTHREAD_MUTEX_RECURSIVE);
  // Without priority inheritance (a platform that lacks it) the lock still works, unboosted.
  pthread_mutexattr_setprotocol(&attributes, PTHREAD_PRIO_INHERIT);
  const int rc = pthread_mutex_init(&mutex_, &attributes);
  pthread_mutexattr_destroy(&attributes);
  check(rc, "pthread_mutex_init");
}

StateMutex::~StateMutex() { pthread_mutex_destroy(&mutex_); }

void StateMutex::lock() { check(pthread_mutex_lock(&mutex_), "lock"); }

bool StateMutex::try_lock() {
  const int rc = pthread_mutex_trylock(&mutex_);
  if (rc == EBUSY) return false;
  check(rc, "try_lock");
  return true;
}

void StateMutex::unlock() noexcept { pthread_mutex_unlock(&mutex_); }

ScopedPriority::ScopedPriority(int priority) {
  if (priority <= 0) return;
  const pthread_t self = pthread_self();
  if (pthread_getschedparam(self, &policy_, &param_) != 0) return;
  if ((policy_ == SCHED_FIFO || policy_ == SCHED_RR) && param_.sched_priority >= priority) return;
  sched_param raised{};
  raised.sched_priority = priority;
  raised_ = pthread_setschedparam(self, SCHED_FIFO, &raised) == 0;
}

ScopedPriority::~ScopedPriority() {
  if (raised_) pthread_setschedparam(pthread_self(), policy_, &param_);
}

}  // namespace ambfplus
