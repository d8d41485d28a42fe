#pragma once
/// @file
/// The slave stage's controller on the platform: one hybrid position controller per axis
/// (motion::PositionController, stepping + scanning) updated at the slave rate (1 kHz by
/// default) on the measured positions and the teleoperation targets, and, at every loop tick,
/// the drive-voltage samples each axis plays until the next tick (one per model step, from
/// the controller's sawtooth generator or scanning voltage). Buffers are allocated at
/// construction; update() and drive() never allocate.

#include <array>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "microcobot/devices/device.h"
#include "microcobot/motion/position_controller.h"
#include "microcobot/motion/step_map.h"
#include "microcobot/motion/tracking_controller.h"

namespace mc::platform {

class StageController {
 public:
  /// X, Y, Z and the rotary axis (the same actuator driving a rotor, its
  /// position the arc at the drive's contact radius, motion/rotary_axis.h).
  static constexpr int kMaxAxes = 4;
  /// `params.control_rate_Hz` is the slave rate; `samples_per_tick` drive samples of
  /// `sample_period_s` make one loop tick. `model` and `map` must outlive the controller.
  /// With `tracking` each axis runs a motion::TrackingController instead. `axes`:
  /// 3 (XYZ) or 4 (with the rotary axis, index 3).
  StageController(const motion::PositionControlParams& params, const stickslip::StickSlipParams& model,
                  const motion::StepMap& map, int samples_per_tick, double sample_period_s,
                  const motion::TrackingParams* tracking = nullptr, int axes = 3);

  /// One slave-rate tick: new targets (with their velocity feedforward) and measurements, per
  /// axis (the first axis_count() of each).
  void update(const std::array<double, kMaxAxes>& target_m, const std::array<double, kMaxAxes>& velocity_m_s,
              const std::array<double, kMaxAxes>& measured_m) noexcept;
  /// The same for X, Y and Z alone (a rotary axis, if any, is left as it was: a 3-axis stage's way).
  void update(const Eigen::Vector3d& target_m, const Eigen::Vector3d& velocity_m_s,
              const std::array<double, 3>& measured_m) noexcept;
  int axis_count() const noexcept { return axes_; }
  /// The drive samples of axis `i` for the next loop tick.
  devices::DriveBlock drive(int i) noexcept;
  /// The same with the axis' position measured now: a tracking controller whose rate is the loop's
  /// (tracking.control_rate_Hz = 1 / (samples_per_tick sample_period_s)) is updated at every loop
  /// tick on it, following the slave-rate target extrapolated with its velocity.
  devices::DriveBlock drive(int i, double measured_m) noexcept;
  /// The last voltage drive(i) produced (0 before the first and after emergency_stop()).
  double last_voltage_V(int i) const noexcept {
    const auto& buf = samples_[static_cast<std::size_t>(i)];
    return stopped_ || buf.empty() ? 0.0 : buf.back().end_V;
  }
  /// Every axis to 0 V; they stay stopped until the next update() with a target.
  void emergency_stop() noexcept;
  /// Parks axis i (tracking controllers only): its loop off, its drive held at the last voltage,
  /// which a stick-slip axis holds by friction alone (a controller's "hold time" ended, as in
  /// SmarAct's MCS2); update() leaves it alone until unpark(), which resumes the loop from
  /// `measured_m` at that voltage without a jump. Real-time safe.
  void park(int i) noexcept;
  void unpark(int i, double measured_m) noexcept;
  bool parked(int i) const noexcept { return parked_[static_cast<std::size_t>(i)]; }
  /// Restarts axis i's loop (tracking controllers only) from `measured_m` with the drive at `u_V`,
  /// the voltage on the axis now: an open-loop run's hand-back, so that the loop resumes from where
  /// the run left the axis, not from the state it kept while set aside. Real-time safe.
  void resume(int i, double measured_m, double u_V) noexcept;

  /// The hybrid controller of axis i (null when tracking).
  const motion::PositionController* axis(int i) const { return ctrl_[static_cast<std::size_t>(i)].get(); }
  /// The tracking controller of axis i (null unless tracking).
  const motion::TrackingController* tracker(int i) const { return track_[static_cast<std::size_t>(i)].get(); }

 private:
  void update_axes(const std::array<double, kMaxAxes>& target_m,
                   const std::array<double, kMaxAxes>& velocity_m_s,
                   const std::array<double, kMaxAxes>& measured_m, int count) noexcept;
  int axes_ = 3;
  std::array<std::unique_ptr<motion::PositionController>, kMaxAxes> ctrl_;
  std::array<std::unique_ptr<motion::TrackingController>, kMaxAxes> track_;
  std::array<motion::ReferenceSample, kMaxAxes> ref_{};  ///< slave-rate target and velocity
  std::array<double, kMaxAxes> since_update_s_{};        ///< time since that target (loop ticks)
  double tick_s_ = 0.0;                                  ///< the loop tick: samples x sample period
  bool fast_ = false;                                    ///< tracking at the loop's rate
  std::array<bool, kMaxAxes> parked_{};
  std::array<double, kMaxAxes> parked_V_{};
  bool started_ = false;
  std::array<std::vector<stickslip::DriveSegment>, kMaxAxes> samples_;
  double sample_period_s_;
  bool stopped_ = false;
};

}  // namespace mc::platform
