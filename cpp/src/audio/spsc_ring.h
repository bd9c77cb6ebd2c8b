#pragma once

// A bounded single-producer single-consumer queue without locks: the haptic thread pushes, the
// audio thread pops, neither ever waits for the other.

#include <atomic>
#include <cstddef>
#include <vector>

namespace ambfplus::audio {

template <typename T>
class SpscRing {
 public:
  /// Holds up to capacity values (rounded up to a power of two).
  explicit SpscRing(std::size_t capacity) {
    std::size_t n = 2;
    while (n < capacity) n <<= 1;
    slots_.resize(n);
    mask_ = n - 1;
  }
  std::size_t capacity() const { return slots_.size(); }

  /// Producer: false (nothing stored) when full.
  bool push(const T& value) {
    const std::size_t head = head_.load(std::memory_order_relaxed);
    if (head - tail_.load(std::memory_order_acquire) == slots_.size()) return false;
    slots_[head & mask_] = value;
    head_.store(head + 1, std::memory_order_release);
    return true;
  }
  /// Consumer: false when empty.
  bool pop(T& value) {
    const std::size_t tail = tail_.load(std::memory_order_relaxed);
    if (head_.load(std::memory_order_acquire) == tail) return false;
    value = slots_[tail & mask_];
    tail_.store(tail + 1, std::memory_order_release);
    return true;
  }
  /// Values waiting (exact for the consumer; a lower bound for the producer).
  std::size_t size() const {
    return head_.load(std::memory_order_acquire) - tail_.load(std::memory_order_acquire);
  }

 private:
  std::vector<T> slots_;
  std::size_t mask_ = 0;
  alignas(64) std::atomic<std::size_t> head_{0};
  alignas(64) std::atomic<std::size_t> tail_{0};
};

}  // namespace ambfplus::audio
