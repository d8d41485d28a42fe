#pragma once
/// @file
/// The XY stage with its position sensors off (`sensor: vision`): two
/// stick-slip axes (the platform's model, thesis ch. 2) driven open loop, as a controller without
/// encoders drives them (Attocube ANC300 `stepu`/`stepd`, devices/open_loop_stepper.h). A velocity
/// asked for an interval T becomes, per axis, a displacement d = v T played as n sawtooth periods
/// spread over T (frequency n / T, at least min_frequency_Hz) at the amplitude whose step the
/// model's step map (motion/step_map.h, a calibration of the drive, not a sensor) says gives
/// d / n; the run ends within T (the caller's next look sees the axis at rest). The true step differs
/// (hysteresis, the break-away strain's operating point, direction): that is the open-loop error a visual
/// loop corrects.
///
/// The sliders' true positions are this simulation's ground truth: the camera renders from them
/// and the benchmark judges against them; the drive never reads them. Buffers are allocated at
/// construction; command() and advance() never allocate.

#include <array>
#include <cstdint>
#include <memory>

#include <Eigen/Core>

#include "microcobot/devices/open_loop_stepper.h"
#include "microcobot/motion/step_map.h"
#include "microcobot/stickslip/actuator.h"

namespace mc::devices {

struct EncoderlessDriveParams {
  double min_frequency_Hz = 20.0;  ///< a run of few periods is spread over T at no less than this
  /// The sawtooth frequency of velocity control (thesis §2.7: 1 kHz); above it the default axis
  /// steps backward less, or the wrong way (1.3-1.5 kHz runs of 17-19 periods moved it back).
  double max_frequency_Hz = 1000.0;
  int samples_per_tick = 10;  ///< model steps per advance() tick

  void validate() const;
};

/// One axis' open-loop run: `periods` sawtooth periods (0: none, the axis holds at rest).
struct OpenLoopRun {
  double amplitude_V = 0.0;
  double frequency_Hz = 0.0;
  int direction = 1;  ///< +1 forward, -1 backward
  std::int64_t periods = 0;
};

/// The run that moves an axis by `d_m` within `interval_s`: as many periods as the largest step
/// needs at the nominal 1 kHz (at most max_frequency_Hz x T), spread over T (frequency n / T, at
/// least min_frequency_Hz), at the amplitude whose step the map gives as d / n (at least the
/// smallest that steps). None for a displacement under half the finest step, a non-finite one,
/// or T <= 0. Never allocates or throws.
OpenLoopRun plan_open_loop_run(const motion::StepMap& map, const EncoderlessDriveParams& params, double d_m,
                               double interval_s) noexcept;

class EncoderlessStage {
 public:
  /// `model` and `map` must outlive the stage. The sliders start at rest at `start_m` (x, y).
  EncoderlessStage(const stickslip::ActuatorModel& model, const motion::StepMap& map,
                   const EncoderlessDriveParams& params = {}, const Eigen::Vector2d& start_m = {0.0, 0.0});

  /// The velocity wanted over the next `interval_s`: each axis' run replaces the one in progress
  /// (from where its voltage is). Never allocates.
  void command(const Eigen::Vector2d& velocity_m_s, double interval_s) noexcept;
  /// Every axis stops at once (0 V).
  void halt() noexcept;
  /// Steps the model by whole ticks covering `dt_s` (rounded). Never allocates.
  void advance(double dt_s) noexcept;
  double tick_s() const noexcept;
  double time_s() const noexcept { return t_s_; }
  /// Ground truth (rendering and judging only).
  Eigen::Vector2d true_position_m() const noexcept;
  Eigen::Vector2d true_velocity_m_s() const noexcept;
  bool moving() const noexcept { return steppers_[0]->running() || steppers_[1]->running(); }
  bool diverged() const noexcept { return states_[0].diverged || states_[1].diverged; }
  /// The last run asked of axis i: periods and amplitude (for the report).
  int last_periods(int i) const noexcept { return last_periods_[static_cast<std::size_t>(i)]; }
  double last_amplitude_V(int i) const noexcept { return last_amplitude_[static_cast<std::size_t>(i)]; }

 private:
  const stickslip::ActuatorModel& model_;
  const motion::StepMap& map_;
  EncoderlessDriveParams p_;
  std::array<stickslip::ActuatorState, 2> states_;
  std::array<std::unique_ptr<OpenLoopStepper>, 2> steppers_;
  std::array<int, 2> last_periods_{};
  std::array<double, 2> last_amplitude_{};
  double t_s_ = 0.0;
};

}  // namespace mc::devices
