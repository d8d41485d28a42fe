#pragma once
/// @file
/// Tick-time statistics of a real-time loop, kept without allocation: count, mean, max and
/// percentiles from a fixed histogram (0.1 us bins up to 1 ms, then one overflow bin).

#include <array>
#include <cstddef>
#include <cstdint>

namespace mc::platform {

class TimingStats {
 public:
  static constexpr double kBinWidth_s = 1e-7;
  static constexpr std::size_t kBins = 10000;  // 0 .. 1 ms

  /// Adds one duration (seconds). Real-time safe.
  void add(double seconds) noexcept;
  void reset() noexcept;

  std::uint64_t count() const { return count_; }
  double mean_s() const { return count_ ? sum_ / static_cast<double>(count_) : 0.0; }
  double max_s() const { return max_; }
  /// The q-quantile (0 < q < 1), to the bin's upper edge; durations over 1 ms report max_s().
  double quantile_s(double q) const;

 private:
  std::array<std::uint32_t, kBins + 1> bins_{};
  std::uint64_t count_ = 0;
  double sum_ = 0.0;
  double max_ = 0.0;
};

}  // namespace mc::platform
