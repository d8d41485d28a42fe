#include "microcobot/dsp/peaks.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "microcobot/core/error.h"

namespace mc::dsp {

ParabolicVertex parabolic_vertex(double ym, double y0, double yp) {
  const double den = ym - 2.0 * y0 + yp;
  if (!(den < 0.0)) return {0.0, y0};  // flat or not a maximum: no refinement
  double d = 0.5 * (ym - yp) / den;
  d = std::clamp(d, -0.5, 0.5);
  return {d, y0 - 0.25 * (ym - yp) * d};
}

std::vector<Peak> find_peaks(std::span<const double> y, const PeakOptions& options) {
  require(options.min_distance >= 1, "min_distance", "must be >= 1");
  const std::size_t n = y.size();
  std::vector<Peak> peaks;
  for (double v : y) {
    if (!std::isfinite(v)) throw InvalidInput("find_peaks: the data hold a non-finite value");
  }
  // Local maxima, plateaus at their middle (scipy's _local_maxima_1d).
  std::size_t i = 1;
  while (n >= 3 && i + 1 < n) {
    if (y[i - 1] < y[i]) {
      std::size_t ahead = i + 1;
      while (ahead + 1 < n && y[ahead] == y[i]) ++ahead;
      if (y[ahead] < y[i]) {
        Peak p;
        p.index = (i + ahead - 1) / 2;
        peaks.push_back(p);
        i = ahead;
        continue;
      }
    }
    ++i;
  }
  // Prominence: height above the higher of the two lowest points reached before a higher sample.
  for (auto& p : peaks) {
    const double h = y[p.index];
    double left_min = h, right_min = h;
    for (std::size_t j = p.index; j-- > 0;) {
      if (y[j] > h) break;
      left_min = std::min(left_min, y[j]);
    }
    for (std::size_t j = p.index + 1; j < n; ++j) {
      if (y[j] > h) break;
      right_min = std::min(right_min, y[j]);
    }
    p.prominence = h - std::max(left_min, right_min);
  }
  std::erase_if(peaks, [&](const Peak& p) {
    return y[p.index] < options.min_height || p.prominence < options.min_prominence;
  });
  // Distance: visit peaks from the highest, drop lower neighbours closer than min_distance.
  if (options.min_distance > 1 || options.max_peaks > 0) {
    std::vector<std::size_t> order(peaks.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return y[peaks[a].index] > y[peaks[b].index]; });
    std::vector<bool> keep(peaks.size(), true);
    std::size_t kept = 0;
    for (std::size_t a : order) {
      if (!keep[a]) continue;
      if (options.max_peaks > 0 && kept == options.max_peaks) {
        keep[a] = false;
        continue;
      }
      ++kept;
      for (std::size_t b = 0; b < peaks.size(); ++b) {
        if (b != a && keep[b]) {
          const std::size_t d = peaks[a].index > peaks[b].index ? peaks[a].index - peaks[b].index
                                                                : peaks[b].index - peaks[a].index;
          if (d < options.min_distance && y[peaks[b].index] <= y[peaks[a].index]) keep[b] = false;
        }
      }
    }
    std::vector<Peak> kept_peaks;
    for (std::size_t a = 0; a < peaks.size(); ++a) {
      if (keep[a]) kept_peaks.push_back(peaks[a]);
    }
    peaks = std::move(kept_peaks);
  }
  for (auto& p : peaks) {
    const std::size_t k = p.index;
    if (options.log_interpolation) {
      if (y[k - 1] > 0 && y[k] > 0 && y[k + 1] > 0) {
        const auto v = parabolic_vertex(std::log(y[k - 1]), std::log(y[k]), std::log(y[k + 1]));
        p.position = static_cast<double>(k) + v.offset;
        p.height = std::exp(v.value);
      } else {
        p.position = static_cast<double>(k);
        p.height = y[k];
      }
    } else {
      const auto v = parabolic_vertex(y[k - 1], y[k], y[k + 1]);
      p.position = static_cast<double>(k) + v.offset;
      p.height = v.value;
    }
    p.x = p.position;
  }
  return peaks;
}

std::vector<Peak> find_peaks_xy(std::span<const double> x, std::span<const double> y,
                                const PeakOptions& options) {
  require(x.size() == y.size(), "x", "must have the length of y", static_cast<double>(x.size()));
  auto peaks = find_peaks(y, options);
  if (x.size() >= 2) {
    const double dx = x[1] - x[0];
    for (auto& p : peaks) p.x = x[0] + p.position * dx;
  }
  return peaks;
}

}  // namespace mc::dsp
