#include "microcobot/runtime/timing_stats.h"

#include <algorithm>
#include <cmath>

namespace mc::runtime {

void TimingStats::add(double seconds) noexcept {
  if (!(seconds >= 0.0)) seconds = 0.0;
  const double bin = seconds / bin_width_s_;
  const std::size_t i = bin >= static_cast<double>(kBins) ? kBins : static_cast<std::size_t>(bin);
  ++bins_[i];
  ++count_;
  sum_ += seconds;
  max_ = std::max(max_, seconds);
}

void TimingStats::reset() noexcept { *this = TimingStats(bin_width_s_); }

double TimingStats::quantile_s(double q) const {
  if (count_ == 0) return 0.0;
  const auto target = static_cast<std::uint64_t>(std::ceil(q * static_cast<double>(count_)));
  std::uint64_t seen = 0;
  for (std::size_t i = 0; i < kBins; ++i) {
    seen += bins_[i];
    if (seen >= target) return std::min(max_, static_cast<double>(i + 1) * bin_width_s_);
  }
  return max_;
}

}  // namespace mc::runtime
