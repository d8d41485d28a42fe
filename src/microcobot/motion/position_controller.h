#pragma once
/// @file
/// Hybrid closed-loop positioning of a stick-slip axis (beyond the thesis, §2.7's "on-line switch
/// between hybrid states: stepping mode and scanning mode"):
///  - stepping while the target is out of the PE's reach: direction, amplitude and frequency
///    scheduled from the model's step map (z_ba surface): the step is at most half the remaining
///    distance, the velocity at most max_velocity_m_s, and forward periods never carry the slider
///    past the target during their slow rise (the PE stroke g H(A) is checked);
///  - scanning once the target is within the PE's reach: a continuous voltage whose feedforward
///    is the exact inverse of the Prandtl-Ishlinskii hysteresis (eq. 2.5) tracked by an observer
///    that sees every commanded voltage, plus an integral correction on the measured error;
///  - bumpless switching: stepping ends at a period boundary (U = 0 V); backward approaches first
///    raise U with the slew-limited edge (the slider mostly stays, as in a backward step) and then
///    scan down; scanning that saturates (0 or 100 V) hands back to stepping from the present U;
///  - hold: the scanning loop stays on (no stepping, hence no stick-slip limit cycle).
/// update() (control rate) and next_drive() (actuator step) never allocate.

#include <cstdint>
#include <string>

#include "microcobot/motion/reference.h"
#include "microcobot/motion/sawtooth_generator.h"
#include "microcobot/motion/step_map.h"
#include "microcobot/stickslip/prandtl_ishlinskii.h"

namespace mc::motion {

struct PositionControlParams {
  double control_rate_Hz = 10000.0;   ///< rate of update()
  double step_frequency_Hz = 2000.0;  ///< stepping frequency when not velocity limited
  /// Within this distance of the target the axis steps at approach_frequency_Hz: at 2 kHz the
  /// slider no longer sticks between steps and coasts ~1 um when the sawtooth stops.
  double approach_distance_m = 20e-6;
  double approach_frequency_Hz = 1000.0;
  /// A step is at most this fraction of the remaining distance: the step map is measured from
  /// rest, and a slider still moving from earlier steps goes further.
  double step_fraction = 0.25;
  double max_velocity_m_s = 1.5e-3;  ///< velocity limit in stepping (frequency lowered)
  /// Velocity and acceleration limits of the scanning reference: the slider rides on the friction
  /// contact's 600 Hz mode (erratum 2, docs/errata.md), which a velocity step v rings by ~v / omega.
  double scan_velocity_m_s = 2.0e-4;
  double scan_acceleration_m_s2 = 0.03;
  double scan_ki_1_s = 300.0;         ///< integral gain of the scanning loop [1/s]
  double hold_ki_1_s = 100.0;         ///< integral gain in hold [1/s]
  double reach_margin = 0.8;          ///< fraction of the PE stroke trusted for scanning
  double backward_window_m = 150e-9;  ///< backward stepping stops this close above the target
  double raise_voltage_V = 100.0;     ///< U after the raise that starts a backward scan
  double stroke_margin_m = 30e-9;     ///< forward: x + g H(A) + margin must stay below target
  double in_position_m = 3e-9;        ///< |error| (filtered) that counts as in position ...
  double settle_s = 2e-3;             ///< ... for this long
  double filter_s = 1e-3;             ///< time constant of the in-position filter
  int saturation_ticks = 20;          ///< scanning saturated this long -> back to stepping
  double stall_fraction = 0.1;        ///< end stop: step < fraction of the expected one ...
  int stall_periods = 10;             ///< ... for this many periods

  template <class V>
  void visit(V& v) {
    v("control_rate_Hz", control_rate_Hz);
    v("step_frequency_Hz", step_frequency_Hz);
    v("approach_distance_m", approach_distance_m);
    v("approach_frequency_Hz", approach_frequency_Hz);
    v("step_fraction", step_fraction);
    v("max_velocity_m_s", max_velocity_m_s);
    v("scan_velocity_m_s", scan_velocity_m_s);
    v("scan_acceleration_m_s2", scan_acceleration_m_s2);
    v("scan_ki_1_s", scan_ki_1_s);
    v("hold_ki_1_s", hold_ki_1_s);
    v("reach_margin", reach_margin);
    v("backward_window_m", backward_window_m);
    v("raise_voltage_V", raise_voltage_V);
    v("stroke_margin_m", stroke_margin_m);
    v("in_position_m", in_position_m);
    v("settle_s", settle_s);
    v("filter_s", filter_s);
    v("saturation_ticks", saturation_ticks);
    v("stall_fraction", stall_fraction);
    v("stall_periods", stall_periods);
  }
  void validate() const;
};

enum class AxisMode { kIdle, kStepping, kRaise, kScanning, kHold, kEndStop, kEmergencyStop };
std::string to_string(AxisMode m);

class PositionController {
 public:
  /// `model` gives the PE gain, the hysteresis and the drive limits; `map` the step lengths. Both
  /// must outlive the controller. Allocates (the hysteresis observer) here only.
  PositionController(const PositionControlParams& p, const stickslip::StickSlipParams& model,
                     const StepMap& map);

  /// New target [m]; `velocity_m_s` is the reference velocity (trajectory feedforward, 0 for a
  /// move). Clears an end stop. Never allocates.
  void set_target(double target_m, double velocity_m_s = 0.0) noexcept;
  /// One control tick. Never allocates.
  void update(double measured_position_m) noexcept;
  /// The drive over the actuator step `dt_s`: the sawtooth's corners while stepping, linear
  /// otherwise, and the voltage at its end [V]. Never allocates.
  stickslip::DriveSegment next_drive(double dt_s) noexcept;
  /// 0 V at once; the axis stays stopped until the next set_target().
  void emergency_stop() noexcept;

  AxisMode mode() const noexcept { return mode_; }
  bool in_position() const noexcept { return mode_ == AxisMode::kHold; }
  bool end_stop() const noexcept { return mode_ == AxisMode::kEndStop; }
  double target_m() const noexcept { return target_; }
  double voltage_V() const noexcept { return u_; }
  /// Sawtooth operating point for the model's z_ba (thesis §2.7: the generator passes it on).
  const SawtoothGenerator& generator() const noexcept { return gen_; }
  /// Count of stepping->scanning switches since construction.
  std::int64_t switches() const noexcept { return switches_; }
  const PositionControlParams& params() const noexcept { return p_; }
  /// The PE's static displacement g H(U) from the present hysteresis state at voltage U [m].
  double pe_displacement_m(double u_V) const noexcept;
  /// U that makes g H(U) = `y_m` from the present hysteresis state (exact PI inverse) [V].
  double inverse_V(double y_m) const noexcept;

 private:
  void decide(double x) noexcept;
  void enter_scan(double x) noexcept;
  void plan_period(double x) noexcept;
  double frequency_for(double distance_m) const noexcept {
    return distance_m > p_.approach_distance_m ? p_.step_frequency_Hz : p_.approach_frequency_Hz;
  }
  PositionControlParams p_;
  const StepMap& map_;
  stickslip::PiParams pi_;
  stickslip::PiState obs_;
  double g_, u_min_, u_max_, slew_;
  SawtoothGenerator gen_;
  ReferenceLimiter scan_ref_;
  AxisMode mode_ = AxisMode::kIdle;
  double dt_c_;
  double target_ = 0.0, v_ff_ = 0.0;
  double u_ = 0.0, u_cmd_ = 0.0, u_rate_ = 0.0;
  double x_entry_ = 0.0, y_entry_ = 0.0, ref_ = 0.0, integ_ = 0.0;
  double x_filt_ = 0.0, settled_s_ = 0.0;
  double x_last_ = 0.0, x_period_ = 0.0, expected_step_ = 0.0;
  std::int64_t seen_periods_ = 0, switches_ = 0;
  int sat_count_ = 0, stall_count_ = 0, raise_count_ = 0, raise_stalls_ = 0;
  double x_window_ = 0.0, expected_sum_ = 0.0, x_raise_ = 0.0;
  bool have_x_ = false, has_target_ = false;
};

}  // namespace mc::motion
