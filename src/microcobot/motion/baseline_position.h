#pragma once
/// @file
/// Baselines for positioning, measured in the same runs as the hybrid controller:
///  - kOpenLoopCounting: what a controller without the model does: n = round(d / s_nominal)
///    sawtooth periods at the nominal amplitude (datasheet step), no feedback;
///  - kThesisPid: the thesis's scheme (§2.7, Fig. 2.18) applied to position: a PID on the
///    sawtooth amplitude from |error|, direction by the sign of the error, stepping only.
/// update() and next_drive() never allocate.

#include <cstdint>
#include <string>

#include "microcobot/motion/pid.h"
#include "microcobot/motion/sawtooth_generator.h"

namespace mc::motion {

enum class BaselineKind { kOpenLoopCounting, kThesisPid };
std::string to_string(BaselineKind k);

struct BaselinePositionParams {
  double frequency_Hz = 1000.0;        ///< sawtooth frequency (thesis §2.7)
  double nominal_amplitude_V = 100.0;  ///< open loop: amplitude used
  double nominal_step_m = 300e-9;      ///< open loop: assumed step at that amplitude (datasheet-like)
  /// Thesis PID on the amplitude [V per m of error]: saturates at 100 V beyond ~1 um.
  PidParams pid{1.0e8, 2.0e9, 0.0, 0.0, 0.0, 100.0};
  double deadband_m = 5e-9;  ///< thesis PID: no stepping when |error| is below this

  template <class V>
  void visit(V& v) {
    v("frequency_Hz", frequency_Hz);
    v("nominal_amplitude_V", nominal_amplitude_V);
    v("nominal_step_m", nominal_step_m);
    v("pid", pid);
    v("deadband_m", deadband_m);
  }
  void validate() const;
};

class BaselinePositionController {
 public:
  BaselinePositionController(const BaselinePositionParams& p, BaselineKind kind,
                             double slew_rate_V_s = 1.0e6);
  /// Starts a move to `target_m` from the measured position `start_m`.
  void set_target(double target_m, double start_m) noexcept;
  /// Moves the target of a running move (trajectory tracking) without restarting it.
  void track(double target_m) noexcept { target_ = target_m; }
  void update(double measured_position_m) noexcept;
  /// The drive over the next actuator step `dt_s` (the sawtooth's corners, the end voltage).
  stickslip::DriveSegment next_drive(double dt_s) noexcept;
  const SawtoothGenerator& generator() const noexcept { return gen_; }
  /// Open loop: periods still to run.
  std::int64_t remaining_periods() const noexcept { return remaining_; }

 private:
  BaselinePositionParams p_;
  BaselineKind kind_;
  Pid pid_;
  SawtoothGenerator gen_;
  double target_ = 0.0;
  std::int64_t remaining_ = 0, seen_ = 0;
  double last_sign_ = 0.0;
  bool active_ = false;
};

}  // namespace mc::motion
