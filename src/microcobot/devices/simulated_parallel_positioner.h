#pragma once
/// @file
/// The simulated parallel positioner: a motion::ParallelStage (six SLC-1720 legs of the project's
/// stick-slip model, their sensors and trackers) behind the device lifecycle of device.h.
///
///   update(dt)          ParallelStage::tick() n times, n = dt / tick_s (the platform's 10 kHz
///                       loop: once per tick); a model fault (a diverged leg, legs where no pose
///                       is) latches the device's Fault, and the platform puts every device in its
///                       safe state (Platform::devices_task)
///   enter_safe_state()  ParallelStage::emergency_stop(): every leg at 0 V, idempotent
///   configure()         ParallelStage::rearm(): the legs hold where they are measured (refused
///                       after a model fault: it stays latched)
///
/// Nothing here allocates after construction (the stage makes its storage there).

#include "microcobot/devices/parallel_positioner.h"
#include "microcobot/motion/parallel_stage.h"

namespace mc::devices {

class SimulatedParallelPositioner final : public ParallelPositioner {
 public:
  /// `model` and `map` must outlive the device; `loop_period_s` must be a whole number of the
  /// stage's control periods (1 / params.tracking.control_rate_Hz). Throws mc::InvalidParams.
  SimulatedParallelPositioner(std::string name, const stickslip::ActuatorModel& model,
                              const motion::StepMap& map, const motion::ParallelStageParams& params,
                              double loop_period_s);

  void update(double dt_s) noexcept override;
  void enter_safe_state() noexcept override { stage_.emergency_stop(); }

  const motion::ParallelKinematics& kinematics() const noexcept override { return stage_.kinematics(); }
  bool start_move(const motion::PoseTrajectory& checked) noexcept override;
  bool follow(const motion::PlatformTransform& target,
              const motion::PoseMoveLimits& limits) noexcept override {
    return active() && stage_.follow(target, limits);
  }
  bool following() const noexcept override { return stage_.following(); }
  bool follow_blocked() const noexcept override { return stage_.follow_blocked(); }
  void stop() noexcept override { stage_.stop(); }
  const motion::PlatformTransform& measured_pose() const noexcept override { return stage_.measured_pose(); }
  const motion::PlatformTransform& reference_pose() const noexcept override {
    return stage_.reference_pose();
  }
  bool moving() const noexcept override { return stage_.moving(); }
  bool at_rest() const noexcept override { return stage_.at_rest(); }
  double max_leg_voltage_V() const noexcept override;

  /// Open-loop stepping of one leg's positioner (recovery; ParallelStage::step_leg): off the loop,
  /// while Active. Throws mc::InvalidParams or mc::InvalidInput (a fault, not Active).
  void step_leg(int leg, motion::LegPositioner positioner, int steps, double frequency_Hz);
  /// The simulation's truth: FK of the six sliders' true positions.
  const motion::PlatformTransform& true_pose() const noexcept { return stage_.true_pose(); }
  const motion::ParallelStage& stage() const noexcept { return stage_; }

 protected:
  void on_configure() override { stage_.rearm(); }

 private:
  motion::ParallelStage stage_;
  int ticks_per_update_ = 1;
};

}  // namespace mc::devices
