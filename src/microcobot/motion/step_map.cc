#include "microcobot/motion/step_map.h"

#include <algorithm>
#include <cmath>

#include "microcobot/core/error.h"

namespace mc::motion {

using stickslip::Direction;

void StepMapParams::validate() const {
  require(amplitudes_V.size() >= 2, "step_map.amplitudes_V", "needs at least 2 amplitudes");
  require(!frequencies_Hz.empty(), "step_map.frequencies_Hz", "must not be empty");
  for (std::size_t i = 0; i < amplitudes_V.size(); ++i) {
    require_in_range(amplitudes_V[i], 0.0, 100.0, "step_map.amplitudes_V");
    if (i > 0) require(amplitudes_V[i] > amplitudes_V[i - 1], "step_map.amplitudes_V", "must increase");
  }
  for (std::size_t i = 0; i < frequencies_Hz.size(); ++i) {
    require_positive(frequencies_Hz[i], "step_map.frequencies_Hz");
    if (i > 0) require(frequencies_Hz[i] > frequencies_Hz[i - 1], "step_map.frequencies_Hz", "must increase");
  }
  require(warmup_periods >= 0, "step_map.warmup_periods", "must be >= 0", warmup_periods);
  require(measure_periods >= 1, "step_map.measure_periods", "must be >= 1", measure_periods);
}

StepMeasurement measure_step(const stickslip::ActuatorModel& model, double amplitude_V, double frequency_Hz,
                             Direction direction, int warmup_periods, int measure_periods) {
  const auto wave = stickslip::make_waveform(stickslip::WaveKind::kSawtooth, amplitude_V, frequency_Hz,
                                             direction, model.params().drive);
  stickslip::ActuatorState s = model.initial_state();
  model.set_operating_point(s, amplitude_V, frequency_Hz, direction);
  const double dt = model.dt_s();
  const auto per = static_cast<long>(std::llround(1.0 / (frequency_Hz * dt)));
  const double period = static_cast<double>(per) * dt;  // whole steps per period
  stickslip::Waveform w = wave;
  w.frequency_Hz = 1.0 / period;
  const double sign = direction == Direction::kForward ? 1.0 : -1.0;
  long k = 0;
  double reach = 0.0;
  auto run = [&](int periods, bool measure) {
    for (int j = 0; j < periods; ++j) {
      const double x_start = model.slider_position(s);
      for (long i = 0; i < per; ++i) {
        ++k;
        model.step(s, w.segment(static_cast<double>(k - 1) * dt, dt));
        if (measure) reach = std::max(reach, sign * (model.slider_position(s) - x_start));
      }
    }
    if (s.diverged) throw ComputationFailed("step map: the stick-slip model diverged");
  };
  // The reach is also taken over the first periods from rest (the start of a move).
  run(warmup_periods, true);
  const double x0 = model.slider_position(s);
  run(measure_periods, true);
  const double step = (model.slider_position(s) - x0) / measure_periods;
  // A last period and then the stop (0 V for two periods): the slider coasts on after the
  // drive stops, which the next period would otherwise hide.
  const double x_last = model.slider_position(s);
  for (long i = 0; i < per; ++i) {
    ++k;
    model.step(s, w.segment(static_cast<double>(k - 1) * dt, dt));
    reach = std::max(reach, sign * (model.slider_position(s) - x_last));
  }
  for (long i = 0; i < 2 * per; ++i) {
    model.step(s, 0.0);
    reach = std::max(reach, sign * (model.slider_position(s) - x_last));
  }
  if (s.diverged) throw ComputationFailed("step map: the stick-slip model diverged");
  return {step, reach};
}

namespace {
void bracket(const std::vector<double>& axis, double v, std::size_t& i, double& t) noexcept {
  if (axis.size() == 1 || v <= axis.front()) {
    i = 0;
    t = 0.0;
  } else if (v >= axis.back()) {
    i = axis.size() - 2;
    t = 1.0;
  } else {
    i = static_cast<std::size_t>(std::upper_bound(axis.begin(), axis.end(), v) - axis.begin()) - 1;
    t = (v - axis[i]) / (axis[i + 1] - axis[i]);
  }
}
}  // namespace

StepMap::StepMap(const stickslip::ActuatorModel& model, const StepMapParams& p) : p_(p) {
  p_.validate();
  for (int d = 0; d < 2; ++d) {
    const Direction dir = d == 0 ? Direction::kForward : Direction::kBackward;
    auto& raw = d == 0 ? fwd_raw_ : bwd_raw_;
    auto& mono = d == 0 ? fwd_ : bwd_;
    auto& reach = d == 0 ? fwd_reach_ : bwd_reach_;
    const double sign = d == 0 ? 1.0 : -1.0;
    raw.assign(p_.amplitudes_V.size(), std::vector<double>(p_.frequencies_Hz.size(), 0.0));
    mono = raw;
    reach = raw;
    for (std::size_t j = 0; j < p_.frequencies_Hz.size(); ++j) {
      double best = 0.0, best_reach = 0.0;
      for (std::size_t i = 0; i < p_.amplitudes_V.size(); ++i) {
        const auto m = measure_step(model, p_.amplitudes_V[i], p_.frequencies_Hz[j], dir, p_.warmup_periods,
                                    p_.measure_periods);
        raw[i][j] = m.step_m;
        // Useful step in the wanted direction, made monotone in A (a running maximum); the reach too
        // (conservative).
        best = std::max(best, sign * m.step_m);
        best_reach = std::max(best_reach, m.reach_m);
        mono[i][j] = best;
        reach[i][j] = best_reach;
      }
    }
  }
}

double StepMap::step_m(double amplitude_V, double frequency_Hz, Direction direction) const noexcept {
  return lookup(direction == Direction::kForward ? fwd_ : bwd_, amplitude_V, frequency_Hz);
}

double StepMap::reach_m(double amplitude_V, double frequency_Hz, Direction direction) const noexcept {
  return lookup(direction == Direction::kForward ? fwd_reach_ : bwd_reach_, amplitude_V, frequency_Hz);
}

double StepMap::amplitude_for_reach(double room_m, double frequency_Hz, Direction direction) const noexcept {
  if (reach_m(p_.amplitudes_V.back(), frequency_Hz, direction) < room_m) return p_.amplitudes_V.back();
  double lo = 0.0, hi = p_.amplitudes_V.back();
  if (reach_m(lo, frequency_Hz, direction) >= room_m) return 0.0;
  for (int i = 0; i < 30; ++i) {
    const double mid = 0.5 * (lo + hi);
    (reach_m(mid, frequency_Hz, direction) < room_m ? lo : hi) = mid;
  }
  return lo;
}

double StepMap::lookup(const std::vector<std::vector<double>>& g, double amplitude_V,
                       double frequency_Hz) const noexcept {
  std::size_t i = 0, j = 0;
  double ta = 0.0, tf = 0.0;
  bracket(p_.amplitudes_V, amplitude_V, i, ta);
  bracket(p_.frequencies_Hz, frequency_Hz, j, tf);
  const std::size_t j1 = p_.frequencies_Hz.size() > 1 ? j + 1 : j;
  const double a = g[i][j] * (1.0 - tf) + g[i][j1] * tf;
  const double b = g[i + 1][j] * (1.0 - tf) + g[i + 1][j1] * tf;
  const double lo = p_.amplitudes_V.front();
  if (amplitude_V < lo) return lo > 0.0 ? a * std::max(amplitude_V, 0.0) / lo : a;
  return a * (1.0 - ta) + b * ta;
}

double StepMap::max_step_m(double frequency_Hz, Direction direction) const noexcept {
  return step_m(p_.amplitudes_V.back(), frequency_Hz, direction);
}

double StepMap::amplitude_for_step(double step, double frequency_Hz, Direction direction) const noexcept {
  const auto& a = p_.amplitudes_V;
  if (step <= 0.0) return 0.0;
  double prev = step_m(a.front(), frequency_Hz, direction);
  if (prev >= step) return a.front();
  for (std::size_t i = 1; i < a.size(); ++i) {
    const double cur = step_m(a[i], frequency_Hz, direction);
    if (cur >= step) {
      const double t = cur > prev ? (step - prev) / (cur - prev) : 1.0;
      return a[i - 1] + t * (a[i] - a[i - 1]);
    }
    prev = cur;
  }
  return a.back();
}

double StepMap::min_stepping_amplitude_V(double frequency_Hz, Direction direction,
                                         double min_fraction) const noexcept {
  return amplitude_for_step(min_fraction * max_step_m(frequency_Hz, direction), frequency_Hz, direction);
}

}  // namespace mc::motion
