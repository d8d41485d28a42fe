#include "microcobot/report/box_plot.h"

#include <algorithm>
#include <cmath>

#include "microcobot/core/error.h"

namespace mc::report {

namespace {

// The q-quantile of sorted values, linearly interpolated (type 7).
double sorted_quantile(const std::vector<double>& sorted, double q) {
  const double pos = q * static_cast<double>(sorted.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(pos));
  const std::size_t hi = std::min(lo + 1, sorted.size() - 1);
  return sorted[lo] + (pos - static_cast<double>(lo)) * (sorted[hi] - sorted[lo]);
}

}  // namespace

BoxStats box_stats(std::vector<double> samples) {
  require(!samples.empty(), "box plot", "needs at least one sample");
  require(std::all_of(samples.begin(), samples.end(), [](double v) { return std::isfinite(v); }), "box plot",
          "needs finite samples");
  std::sort(samples.begin(), samples.end());
  BoxStats b;
  b.n = samples.size();
  b.q1 = sorted_quantile(samples, 0.25);
  b.median = sorted_quantile(samples, 0.5);
  b.q3 = sorted_quantile(samples, 0.75);
  const double iqr = b.q3 - b.q1, lo_fence = b.q1 - 1.5 * iqr, hi_fence = b.q3 + 1.5 * iqr;
  // The whiskers end on samples, never on a fence: the box's own ends when nothing lies between.
  b.whisker_low = b.q1;
  b.whisker_high = b.q3;
  for (double v : samples) {
    if (v < lo_fence || v > hi_fence) {
      b.outliers.push_back(v);
    } else {
      b.whisker_low = std::min(b.whisker_low, v);
      b.whisker_high = std::max(b.whisker_high, v);
    }
  }
  return b;
}

Figure box_figure(std::string title, std::string caption, std::string group_label, Axis value_axis,
                  std::vector<std::pair<std::string, std::vector<double>>> groups) {
  Figure f{std::move(title), std::move(caption), {std::move(group_label), ""}, std::move(value_axis), {}};
  f.box = true;
  for (std::size_t i = 0; i < groups.size(); ++i) {
    auto& [name, samples] = groups[i];
    std::vector<double> x(samples.size(), static_cast<double>(i + 1));
    f.series.push_back({std::move(name), std::move(x), std::move(samples), true});
  }
  return f;
}

}  // namespace mc::report
