#pragma once
/// @file
/// A bounded single-producer single-consumer ring buffer: how telemetry leaves the real-time
/// loop. push() and pop() are wait-free, never allocate and never lock; the storage is
/// allocated once at construction. One thread may push, one other thread may pop.

#include <atomic>
#include <cstddef>
#include <vector>

namespace mc::runtime {

template <class T>
class SpscRing {
 public:
  /// Holds up to `capacity` elements.
  explicit SpscRing(std::size_t capacity) : buffer_(capacity + 1) {}

  /// Producer side. Returns false (and counts a drop) when full: the loop never waits.
  bool push(const T& value) noexcept {
    const std::size_t head = head_.load(std::memory_order_relaxed);
    const std::size_t next = increment(head);
    if (next == tail_.load(std::memory_order_acquire)) {
      dropped_.fetch_add(1, std::memory_order_relaxed);
      return false;
    }
    buffer_[head] = value;
    head_.store(next, std::memory_order_release);
    return true;
  }

  /// Consumer side. Returns false when empty.
  bool pop(T& out) noexcept {
    const std::size_t tail = tail_.load(std::memory_order_relaxed);
    if (tail == head_.load(std::memory_order_acquire)) return false;
    out = buffer_[tail];
    tail_.store(increment(tail), std::memory_order_release);
    return true;
  }

  std::size_t capacity() const { return buffer_.size() - 1; }
  /// Elements pushed but not yet popped (approximate while both sides run).
  std::size_t size() const {
    const std::size_t h = head_.load(std::memory_order_acquire), t = tail_.load(std::memory_order_acquire);
    return h >= t ? h - t : h + buffer_.size() - t;
  }
  std::size_t dropped() const { return dropped_.load(std::memory_order_relaxed); }

 private:
  std::size_t increment(std::size_t i) const noexcept { return i + 1 == buffer_.size() ? 0 : i + 1; }

  std::vector<T> buffer_;
  alignas(64) std::atomic<std::size_t> head_{0};
  alignas(64) std::atomic<std::size_t> tail_{0};
  alignas(64) std::atomic<std::size_t> dropped_{0};
};

}  // namespace mc::runtime
