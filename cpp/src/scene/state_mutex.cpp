#include "ambfplus/scene/state_mutex.h"

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

}  // namespace ambfplus
