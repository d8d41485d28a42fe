#pragma once
/// @file
/// The newest value of a state one thread publishes and another reads: how a loop's state leaves
/// it when only the latest matters (a ring would fill while nobody reads, and then hold the
/// oldest). A triple buffer: the writer fills its own slot and swaps it with the middle one; the
/// reader swaps the middle slot with its own when it holds something newer. publish() and read()
/// are wait-free, never allocate and never lock; one thread may publish, one other may read, and
/// neither ever sees a slot the other is writing (no torn values, no data race).

#include <array>
#include <atomic>
#include <cstdint>
#include <type_traits>

namespace mc::runtime {

template <class T>
class LatestValue {
  // Plain data whose copy neither allocates nor throws (fixed-size Eigen types qualify, though
  // their assignment is not declared noexcept).
  static_assert(std::is_default_constructible_v<T> && std::is_copy_assignable_v<T>,
                "LatestValue holds plain data");

 public:
  explicit LatestValue(const T& initial = T{}) { slots_.fill(initial); }

  /// Writer side: `value` becomes the newest.
  void publish(const T& value) noexcept {
    slots_[write_] = value;
    const std::uint8_t previous =
        middle_.exchange(static_cast<std::uint8_t>(write_ | kFresh), std::memory_order_acq_rel);
    write_ = previous & kIndex;
  }

  /// Reader side: the newest value published (the initial one before any).
  T read() noexcept {
    if (middle_.load(std::memory_order_relaxed) & kFresh) {
      const std::uint8_t previous = middle_.exchange(read_, std::memory_order_acq_rel);
      read_ = previous & kIndex;
    }
    return slots_[read_];
  }

 private:
  static constexpr std::uint8_t kIndex = 0x3, kFresh = 0x4;
  std::array<T, 3> slots_{};
  std::uint8_t write_ = 0;               // the writer's slot
  std::uint8_t read_ = 1;                // the reader's slot
  std::atomic<std::uint8_t> middle_{2};  // the slot between them, and whether it is newer
};

}  // namespace mc::runtime
