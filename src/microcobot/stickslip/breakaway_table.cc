#include "microcobot/stickslip/breakaway_table.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "microcobot/core/error.h"

namespace mc::stickslip {

namespace {
void check_axis(const std::vector<double>& axis, const std::string& name) {
  require(!axis.empty(), "breakaway." + name, "must not be empty");
  for (std::size_t i = 0; i < axis.size(); ++i) {
    require(std::isfinite(axis[i]) && axis[i] >= 0.0, "breakaway." + name + "[" + std::to_string(i) + "]",
            "must be finite and >= 0", axis[i]);
    if (i > 0) {
      require(axis[i] > axis[i - 1], "breakaway." + name + "[" + std::to_string(i) + "]",
              "must be strictly increasing", axis[i]);
    }
  }
}
void check_grid(const std::vector<std::vector<double>>& g, std::size_t rows, std::size_t cols,
                const std::string& name) {
  require(g.size() == rows, "breakaway." + name, "must have one row per amplitude",
          static_cast<double>(g.size()));
  for (std::size_t i = 0; i < rows; ++i) {
    require(g[i].size() == cols, "breakaway." + name + "[" + std::to_string(i) + "]",
            "must have one entry per frequency", static_cast<double>(g[i].size()));
    for (std::size_t j = 0; j < cols; ++j) {
      require(std::isfinite(g[i][j]) && g[i][j] > 0.0,
              "breakaway." + name + "[" + std::to_string(i) + "][" + std::to_string(j) + "]", "must be > 0",
              g[i][j]);
    }
  }
}

/// Index i and weight t of `v` between axis[i] and axis[i+1] (t linear in `key`), clamped.
template <class Key>
inline void bracket(const std::vector<double>& axis, double v, std::size_t& i, double& t, Key key) noexcept {
  const std::size_t n = axis.size();
  if (n == 1 || !(v > axis.front())) {  // also NaN: clamp to the first row
    i = 0;
    t = 0.0;
    return;
  }
  if (v >= axis.back()) {
    i = n - 2;
    t = 1.0;
    return;
  }
  const auto it = std::upper_bound(axis.begin(), axis.end(), v);
  i = static_cast<std::size_t>(it - axis.begin()) - 1;
  t = (key(v) - key(axis[i])) / (key(axis[i + 1]) - key(axis[i]));
}
}  // namespace

void BreakawayTable::validate() const {
  check_axis(amplitudes_V, "amplitudes_V");
  check_axis(frequencies_Hz, "frequencies_Hz");
  // Interpolated in log f: a frequency must be > 0.
  require(frequencies_Hz.front() > 0.0, "breakaway.frequencies_Hz[0]", "must be > 0", frequencies_Hz.front());
  check_grid(forward_m, amplitudes_V.size(), frequencies_Hz.size(), "forward_m");
  check_grid(backward_m, amplitudes_V.size(), frequencies_Hz.size(), "backward_m");
}

double BreakawayTable::lookup(double amplitude_V, double frequency_Hz, Direction direction) const noexcept {
  const auto& g = direction == Direction::kForward ? forward_m : backward_m;
  std::size_t i = 0, j = 0;
  double ta = 0.0, tf = 0.0;
  bracket(amplitudes_V, amplitude_V, i, ta, [](double a) { return a; });
  bracket(frequencies_Hz, frequency_Hz, j, tf, [](double f) { return std::log(f); });
  const std::size_t i1 = amplitudes_V.size() > 1 ? i + 1 : i;
  const std::size_t j1 = frequencies_Hz.size() > 1 ? j + 1 : j;
  const double a = g[i][j] * (1.0 - tf) + g[i][j1] * tf;
  const double b = g[i1][j] * (1.0 - tf) + g[i1][j1] * tf;
  return a * (1.0 - ta) + b * ta;
}

BreakawayTable default_breakaway_table() {
  BreakawayTable t;
  t.amplitudes_V = {0, 10, 20, 30, 40, 50, 60, 70, 80, 90, 100};
  t.frequencies_Hz = {50, 100, 500, 1000, 2000};
  const double z0_fwd = 365e-9, slope_fwd = 2e-9, z0_bwd = 372e-9, slope_bwd = 2e-9;
  const double freq_slope = 0.03;
  for (double a : t.amplitudes_V) {
    std::vector<double> f_row, b_row;
    for (double f : t.frequencies_Hz) {
      const double k = 1.0 - freq_slope * std::log10(f / 50.0);
      f_row.push_back((z0_fwd + slope_fwd * a) * k);
      b_row.push_back((z0_bwd + slope_bwd * a) * k);
    }
    t.forward_m.push_back(f_row);
    t.backward_m.push_back(b_row);
  }
  return t;
}

}  // namespace mc::stickslip
