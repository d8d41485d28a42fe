#include "microcobot/devices/encoderless_stage.h"

#include <algorithm>
#include <cmath>

#include "microcobot/core/error.h"

namespace mc::devices {

void EncoderlessDriveParams::validate() const {
  require(std::isfinite(min_frequency_Hz) && min_frequency_Hz > 0.0, "min_frequency_Hz", "must be > 0",
          min_frequency_Hz);
  require(std::isfinite(max_frequency_Hz) && max_frequency_Hz >= min_frequency_Hz, "max_frequency_Hz",
          "must be >= min_frequency_Hz", max_frequency_Hz);
  require(samples_per_tick >= 1 && samples_per_tick <= 1000, "samples_per_tick", "must be within [1, 1000]",
          samples_per_tick);
}

EncoderlessStage::EncoderlessStage(const stickslip::ActuatorModel& model, const motion::StepMap& map,
                                   const EncoderlessDriveParams& params, const Eigen::Vector2d& start_m)
    : model_(model), map_(map), p_(params) {
  p_.validate();
  for (std::size_t i = 0; i < 2; ++i) {
    states_[i] = model_.initial_state();
    const double x = start_m[static_cast<Eigen::Index>(i)];
    require(std::isfinite(x) && std::abs(x) < 0.5 * model_.params().slider.stroke_m, "start_m",
            "must lie within the stroke", x);
    states_[i].x2_m = {x, x};
    steppers_[i] = std::make_unique<OpenLoopStepper>(p_.samples_per_tick, model_.dt_s(),
                                                     model_.params().drive.slew_rate_V_s);
  }
}

double EncoderlessStage::tick_s() const noexcept { return p_.samples_per_tick * model_.dt_s(); }

OpenLoopRun plan_open_loop_run(const motion::StepMap& map, const EncoderlessDriveParams& p, double d,
                               double interval_s) noexcept {
  OpenLoopRun run;
  if (!std::isfinite(d) || !(interval_s > 0.0) || !std::isfinite(interval_s) || d == 0.0) return run;
  const auto dir = d >= 0.0 ? stickslip::Direction::kForward : stickslip::Direction::kBackward;
  // Periods: as many as the largest step needs at the nominal 1 kHz, then spread over T.
  const double ref_f = std::clamp(1000.0, p.min_frequency_Hz, p.max_frequency_Hz);
  const double big = map.step_m(map.params().amplitudes_V.back(), ref_f, dir);
  const double smallest_A = map.min_stepping_amplitude_V(ref_f, dir);
  const double small = map.step_m(smallest_A, ref_f, dir);
  if (!(big > 0.0) || std::abs(d) < 0.5 * small) return run;  // under half the finest step
  const auto max_periods = static_cast<std::int64_t>(std::floor(p.max_frequency_Hz * interval_s));
  std::int64_t n = std::max<std::int64_t>(1, static_cast<std::int64_t>(std::ceil(std::abs(d) / big)));
  n = std::min(n, std::max<std::int64_t>(1, max_periods));
  run.frequency_Hz = std::clamp(static_cast<double>(n) / interval_s, p.min_frequency_Hz, p.max_frequency_Hz);
  run.amplitude_V = std::max(
      map.amplitude_for_step(std::abs(d) / static_cast<double>(n), run.frequency_Hz, dir), smallest_A);
  run.direction = d >= 0.0 ? 1 : -1;
  run.periods = n;
  return run;
}

void EncoderlessStage::command(const Eigen::Vector2d& velocity_m_s, double interval_s) noexcept {
  for (std::size_t i = 0; i < 2; ++i) {
    OpenLoopStepper& st = *steppers_[i];
    const double u_now = states_[i].u_V;
    const OpenLoopRun run =
        plan_open_loop_run(map_, p_, velocity_m_s[static_cast<Eigen::Index>(i)] * interval_s, interval_s);
    last_periods_[i] = static_cast<int>(run.periods);
    last_amplitude_[i] = run.amplitude_V;
    if (run.periods == 0)
      st.start(0.0, p_.min_frequency_Hz, 1, 0, u_now);  // no run: the axis holds at rest
    else
      st.start(run.amplitude_V, run.frequency_Hz, run.direction, run.periods, u_now);
  }
}

void EncoderlessStage::halt() noexcept {
  for (auto& st : steppers_) st->halt();
}

void EncoderlessStage::advance(double dt_s) noexcept {
  const long ticks = std::max(0L, std::lround(dt_s / tick_s()));
  for (long k = 0; k < ticks; ++k) {
    for (std::size_t i = 0; i < 2; ++i) {
      const DriveBlock b = steppers_[i]->drive();
      if (b.frequency_Hz > 0.0 && b.direction != 0)
        model_.set_operating_point(
            states_[i], b.amplitude_V, b.frequency_Hz,
            b.direction < 0 ? stickslip::Direction::kBackward : stickslip::Direction::kForward);
      for (int j = 0; j < b.count; ++j) model_.step(states_[i], b.segments[j]);
    }
    t_s_ += tick_s();
  }
}

Eigen::Vector2d EncoderlessStage::true_position_m() const noexcept {
  return {model_.slider_position(states_[0]), model_.slider_position(states_[1])};
}

Eigen::Vector2d EncoderlessStage::true_velocity_m_s() const noexcept {
  return {model_.slider_velocity(states_[0]), model_.slider_velocity(states_[1])};
}

}  // namespace mc::devices
