#pragma once
/// @file
/// Open-loop stepping of one stick-slip axis: `n` sawtooth periods of a given
/// amplitude, frequency and direction played straight to the axis, the stage controller set
/// aside, as an open-loop controller (Attocube ANC300 `stepu`/`stepd`) drives its positioner.
/// The waveform is the motion::SawtoothGenerator's (thesis §2.2.2, Fig. 2.3: slow ramp, edge at
/// the amplifier's slew rate), so the axis sees exactly what `stickslip simulate --wave sawtooth`
/// feeds the model. Entry follows the run's own abrupt edge from the voltage the stage
/// controller left on the axis to where the run's slow edge starts (up: 0 V; down: the
/// amplitude), so the slider slips there and is not dragged; the run ends at a period boundary
/// (0 V).
/// Real-time safe: the drive buffer is allocated at construction.

#include <cstdint>
#include <vector>

#include "microcobot/devices/device.h"
#include "microcobot/motion/sawtooth_generator.h"

namespace mc::devices {

class OpenLoopStepper {
 public:
  /// `samples_per_tick` drive segments of `sample_period_s` make one loop tick; `slew_rate_V_s`
  /// is the amplifier's (stickslip drive.slew_rate_V_s).
  OpenLoopStepper(int samples_per_tick, double sample_period_s, double slew_rate_V_s);

  /// Starts `periods` (>= 1) periods of the sawtooth from the axis' present voltage `u_V`.
  /// `direction` +1 forward (up), -1 backward (down). Replaces a run in progress.
  void start(double amplitude_V, double frequency_Hz, int direction, std::int64_t periods,
             double u_V) noexcept;
  /// Stops at once (0 V): a `stop`, a halt, the e-stop.
  void halt() noexcept;
  bool running() const noexcept { return running_; }
  /// +1 forward, -1 backward (the last run's).
  int drive_direction() const noexcept { return direction_; }
  /// The voltage on the axis now [V].
  double output_V() const noexcept {
    return !running_ ? 0.0 : entry_V_ > 0.0 ? entry_V_ : generator_.output_V();
  }
  /// Periods completed since start().
  std::int64_t periods_done() const noexcept { return generator_.periods() - start_periods_; }
  /// The next loop tick's drive; after the last period, 0 V and running() turns false.
  DriveBlock drive() noexcept;

 private:
  motion::SawtoothGenerator generator_;
  std::vector<stickslip::DriveSegment> samples_;
  double sample_period_s_, slew_rate_V_s_;
  double entry_V_ = -1.0;  ///< the entry edge's voltage while it plays (< 0: none)
  std::int64_t start_periods_ = 0, periods_ = 0;
  int direction_ = 1;
  bool running_ = false;
};

}  // namespace mc::devices
