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
/// With a controller thread (parallel_positioner_controller.h) the stage is stepped there instead,
/// paced by the wall clock as a real controller's own processor steps its legs: update() exchanges
/// the commands and the newest status with it, the getters read that status, and the commands take
/// effect at its next wake (wake_period_s). For live sessions; studies and tests step it on the
/// loop, where a run is reproducible.
///
/// Nothing here allocates after construction (the stage makes its storage there; the controller
/// thread is started by the first configure()).

#include <memory>
#include <optional>

#include "microcobot/devices/parallel_positioner.h"
#include "microcobot/devices/parallel_positioner_controller.h"
#include "microcobot/motion/parallel_stage.h"

namespace mc::devices {

class SimulatedParallelPositioner final : public ParallelPositioner {
 public:
  /// `model` and `map` must outlive the device; `loop_period_s` must be a whole number of the
  /// stage's control periods (1 / params.tracking.control_rate_Hz). With `controller_thread`, the
  /// stage is stepped on a controller thread of its own. Throws mc::InvalidParams.
  SimulatedParallelPositioner(
      std::string name, const stickslip::ActuatorModel& model, const motion::StepMap& map,
      const motion::ParallelStageParams& params, double loop_period_s,
      std::optional<ParallelPositionerControllerParams> controller_thread = std::nullopt);
  ~SimulatedParallelPositioner() override;

  void update(double dt_s) noexcept override;
  void enter_safe_state() noexcept override;

  const motion::ParallelKinematics& kinematics() const noexcept override { return stage_.kinematics(); }
  bool start_move(const motion::PoseTrajectory& checked) noexcept override;
  bool follow(const motion::PlatformTransform& target,
              const motion::PoseMoveLimits& limits) noexcept override;
  bool following() const noexcept override;
  bool follow_blocked() const noexcept override;
  void stop() noexcept override;
  const motion::PlatformTransform& measured_pose() const noexcept override;
  const motion::PlatformTransform& reference_pose() const noexcept override;
  bool moving() const noexcept override;
  bool at_rest() const noexcept override;
  double max_leg_voltage_V() const noexcept override;

  /// Open-loop stepping of one leg's positioner (recovery; ParallelStage::step_leg): off the loop,
  /// while Active. Throws mc::InvalidParams or mc::InvalidInput (a fault, not Active). With a
  /// controller thread, the stepping is queued; one the stage then refuses counts in
  /// controller()->view().refused.
  void step_leg(int leg, motion::LegPositioner positioner, int steps, double frequency_Hz);
  /// The simulation's truth: FK of the six sliders' true positions.
  const motion::PlatformTransform& true_pose() const noexcept;
  /// The stage, for a loop that steps it: with a controller thread the stage is that thread's,
  /// and the getters above are what the host reads.
  const motion::ParallelStage& stage() const noexcept { return stage_; }
  /// The controller thread, or nullptr when the stage is stepped on the loop.
  const ParallelPositionerController* controller() const noexcept { return controller_.get(); }

 protected:
  void on_configure() override;

 private:
  motion::ParallelStage stage_;
  int ticks_per_update_ = 1;
  std::optional<ParallelPositionerControllerParams> thread_params_;
  std::unique_ptr<ParallelPositionerController> controller_;  ///< from the first configure()
};

}  // namespace mc::devices
