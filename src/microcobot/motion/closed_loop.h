#pragma once
/// @file
/// Closed-loop simulations of one axis: the stick-slip model stepped at its own step, the
/// position sensor and a controller updated at the controller rate, the sawtooth's operating
/// point passed to the model's z_ba at every tick (thesis §2.7). These runners allocate only their
/// records; the controllers inside never allocate. Divergence throws mc::ComputationFailed.

#include <functional>
#include <string>
#include <vector>

#include "microcobot/motion/baseline_position.h"
#include "microcobot/motion/position_controller.h"
#include "microcobot/motion/position_sensor.h"
#include "microcobot/motion/reference.h"
#include "microcobot/motion/velocity_controller.h"

namespace mc::motion {

struct VelocityMetrics {
  double mean_velocity_m_s = 0.0;       ///< true mean velocity over the second half of the run
  double steady_state_error_rel = 0.0;  ///< (mean - reference) / reference
  /// When the 5-period mean entered +-5 % of the reference and then stayed there for
  /// kSettleHoldPeriods periods: the loop's convergence. The model steps intermittently at some
  /// operating points (bursts of +-10-20 % per period at a constant amplitude, docs/errata.md):
  /// those later excursions are the plant's, counted below, not a later settling time.
  double settling_time_s = 0.0;
  bool settled = false;
  double ripple_m_s = 0.0;         ///< std of the one-period velocity over the second half
  int excursions = 0;              ///< 5-period means outside +-5 % after settling
  double max_excursion_rel = 0.0;  ///< largest |5-period mean / reference - 1| after settling
  static constexpr std::size_t kSettleWindowPeriods = 5;
  static constexpr std::size_t kSettleHoldPeriods = 20;
};

struct VelocityRun {
  std::vector<double> t_s;          ///< one sample per sawtooth period
  std::vector<double> v_true_m_s;   ///< true velocity over the last period
  std::vector<double> v_est_m_s;    ///< the controller's N-period estimate
  std::vector<double> amplitude_V;  ///< sawtooth amplitude commanded
  VelocityMetrics metrics;
};

/// The metrics of a velocity record (one sample per sawtooth period) against `reference_m_s`:
/// mean and ripple over the second half, settling and the excursions after it (VelocityMetrics).
VelocityMetrics velocity_metrics(const VelocityRun& run, double reference_m_s);

VelocityRun run_velocity(const stickslip::ActuatorModel& model, const StepMap* map,
                         const VelocityControlParams& p, VelocityMode mode, double reference_m_s,
                         double duration_s, const PositionSensorParams& sensor, double start_m = 0.0);

struct PositionMetrics {
  double final_error_m = 0.0;  ///< |x - target| at the end (true position)
  double overshoot_m = 0.0;    ///< largest excursion past the target in the direction of the move
  double move_time_s = 0.0;    ///< time to hold (in position); the run length when never
  bool in_position = false;
  double hold_pp_m = 0.0;  ///< peak-to-peak true position during the hold window
  double hold_voltage_pp_V = 0.0;
  bool stepped_in_hold = false;  ///< the axis left hold for stepping (a limit cycle)
  long switches = 0;             ///< stepping -> scanning switches
  bool end_stop = false;
};

struct PositionRun {
  std::vector<double> t_s, x_m, u_V, mode;  ///< mode: AxisMode as a number (0 idle ... 6 e-stop)
  PositionMetrics metrics;
};

/// A hybrid move from `start_m` to `target_m`, then `hold_s` of hold. The run stops at
/// `max_time_s` (default: from the step map's speed) when the axis never gets in position.
PositionRun run_position(const stickslip::ActuatorModel& model, const StepMap& map,
                         const PositionControlParams& p, const PositionSensorParams& sensor, double start_m,
                         double target_m, double hold_s = 0.03, double max_time_s = 0.0,
                         int max_records = 20000);

/// The same move by a baseline, for `duration_s`.
PositionRun run_baseline_position(const stickslip::ActuatorModel& model, const BaselinePositionParams& p,
                                  BaselineKind kind, const PositionSensorParams& sensor, double start_m,
                                  double target_m, double duration_s, int max_records = 20000);

struct TrackingRun {
  std::vector<double> t_s, ref_m, x_m, u_V;
  double rms_error_m = 0.0, max_error_m = 0.0;
};

/// Tracks `reference(t, dt)` (called once per control tick, in time order) with the hybrid
/// controller for `duration_s`; the errors are of the true position.
TrackingRun run_tracking(const stickslip::ActuatorModel& model, const StepMap& map,
                         const PositionControlParams& p, const PositionSensorParams& sensor, double start_m,
                         const std::function<ReferenceSample(double, double)>& reference, double duration_s,
                         int max_records = 20000);

/// Model steps per control tick (the control period must be a whole number of model steps).
int steps_per_tick(const stickslip::ActuatorModel& model, double control_rate_Hz);

}  // namespace mc::motion
