#pragma once
/// @file
/// Velocity control of a stick-slip axis (thesis §2.7, Fig. 2.18): a sawtooth at a fixed
/// frequency (1 kHz) whose amplitude is set by a PID on the velocity error; the velocity is
/// estimated from positions `delay_periods` whole sawtooth periods apart, so that the oscillation
/// within a step does not enter the loop. Three variants run the same loop:
///  - kModelBased: PID + feedforward amplitude A_ff = s^-1(v_ref / f) from the model's step map;
///  - kThesisPid: the thesis's PID alone (Fig. 2.18);
///  - kOpenLoop:  no feedback; a controller without the model assumes a step proportional to the
///                amplitude (nominal_step_m at nominal_amplitude_V, a datasheet figure).
/// update() (at control_rate_Hz) and next_drive() (at the actuator's step) never allocate.

#include <array>
#include <string>

#include "microcobot/motion/pid.h"
#include "microcobot/motion/sawtooth_generator.h"
#include "microcobot/motion/step_map.h"

namespace mc::motion {

enum class VelocityMode { kModelBased, kThesisPid, kOpenLoop };
VelocityMode parse_velocity_mode(const std::string& name);  ///< "model" | "pid" | "open-loop"
std::string to_string(VelocityMode m);

struct VelocityControlParams {
  double sawtooth_frequency_Hz = 1000.0;  ///< thesis §2.7: fixed to 1 kHz
  int delay_periods = 4;                  ///< N: v = (x_k - x_{k-N}) / (N T) (thesis §2.7)
  double control_rate_Hz = 10000.0;       ///< rate of update() (position sampling)
  /// PID on the amplitude [V per m/s]; tuned on the default model (docs/parameters.md).
  PidParams pid{2.0e4, 1.5e7, 0.0, 0.0, 0.0, 100.0};
  double nominal_step_m = 300e-9;  ///< open-loop baseline: step at nominal_amplitude_V (datasheet-like)
  double nominal_amplitude_V = 100.0;
  double stall_fraction = 0.1;  ///< end stop: |v| < stall_fraction |v_ref| ...
  int stall_periods = 20;       ///< ... for this many periods at full amplitude

  template <class V>
  void visit(V& v) {
    v("sawtooth_frequency_Hz", sawtooth_frequency_Hz);
    v("delay_periods", delay_periods);
    v("control_rate_Hz", control_rate_Hz);
    v("pid", pid);
    v("nominal_step_m", nominal_step_m);
    v("nominal_amplitude_V", nominal_amplitude_V);
    v("stall_fraction", stall_fraction);
    v("stall_periods", stall_periods);
  }
  void validate() const;
};

class VelocityController {
 public:
  static constexpr int kMaxDelay = 63;
  /// `map` (may be null for kThesisPid/kOpenLoop) must outlive the controller.
  VelocityController(const VelocityControlParams& p, VelocityMode mode, const StepMap* map,
                     double slew_rate_V_s = 1.0e6);

  /// Sets the reference velocity [m/s]; its sign picks the sawtooth direction. Re-arms after an
  /// end stop.
  void set_reference(double v_m_s) noexcept;
  /// One control tick with the measured slider position. Never allocates.
  void update(double measured_position_m) noexcept;
  /// Advances the sawtooth by the actuator step `dt_s` and returns U over it (corners and end
  /// voltage [V]). Never allocates.
  stickslip::DriveSegment next_drive(double dt_s) noexcept;
  /// Emergency stop: 0 V at once, integrator cleared.
  void emergency_stop() noexcept;

  double velocity_estimate_m_s() const noexcept { return v_est_; }
  double amplitude_V() const noexcept { return amp_; }
  bool end_stop() const noexcept { return end_stop_; }
  const SawtoothGenerator& generator() const noexcept { return gen_; }
  const VelocityControlParams& params() const noexcept { return p_; }

 private:
  VelocityControlParams p_;
  VelocityMode mode_;
  const StepMap* map_;
  Pid pid_;
  SawtoothGenerator gen_;
  double v_ref_ = 0.0, v_est_ = 0.0, amp_ = 0.0, last_x_ = 0.0;
  std::array<double, kMaxDelay + 1> ring_{};
  int count_ = 0;
  std::int64_t seen_periods_ = 0;
  int stall_count_ = 0;
  bool end_stop_ = false, started_ = false, have_x_ = false;
};

}  // namespace mc::motion
