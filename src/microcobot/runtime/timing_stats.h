#pragma once
/// @file
/// Duration statistics kept without allocation: count, mean, max and percentiles from a fixed
/// histogram of kBins bins (0.1 us wide by default: tick times up to 1 ms; 10 us wide for
/// latencies up to 100 ms), then one overflow bin.

#include <array>
#include <cstddef>
#include <cstdint>

namespace mc::runtime {

class TimingStats {
 public:
  static constexpr std::size_t kBins = 10000;
  explicit TimingStats(double bin_width_s = 1e-7) : bin_width_s_(bin_width_s) {}

  /// Adds one duration (seconds). Real-time safe.
  void add(double seconds) noexcept;
  void reset() noexcept;

  std::uint64_t count() const { return count_; }
  double mean_s() const { return count_ ? sum_ / static_cast<double>(count_) : 0.0; }
  double max_s() const { return max_; }
  /// The q-quantile (0 < q < 1), to the bin's upper edge; beyond the last bin, max_s().
  double quantile_s(double q) const;

 private:
  double bin_width_s_;
  std::array<std::uint32_t, kBins + 1> bins_{};
  std::uint64_t count_ = 0;
  double sum_ = 0.0;
  double max_ = 0.0;
};

}  // namespace mc::runtime
