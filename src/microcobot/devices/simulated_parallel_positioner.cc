#include "microcobot/devices/simulated_parallel_positioner.h"

#include <algorithm>
#include <cmath>

#include "microcobot/core/error.h"

namespace mc::devices {

SimulatedParallelPositioner::SimulatedParallelPositioner(
    std::string name, const stickslip::ActuatorModel& model, const motion::StepMap& map,
    const motion::ParallelStageParams& params, double loop_period_s,
    std::optional<ParallelPositionerControllerParams> controller_thread)
    : ParallelPositioner(std::move(name)),
      stage_(model, map, params),
      thread_params_(std::move(controller_thread)) {
  const double n = loop_period_s / stage_.tick_s();
  require(std::isfinite(n) && n >= 1.0 - 1e-9 && std::abs(n - std::round(n)) < 1e-6 * n,
          "parallel_positioner.tracking.control_rate_Hz",
          "must be a whole multiple of the loop's rate (loop.base_rate_Hz)", params.tracking.control_rate_Hz);
  ticks_per_update_ = std::max(1, static_cast<int>(std::lround(n)));
  if (thread_params_) thread_params_->validate();
}

SimulatedParallelPositioner::~SimulatedParallelPositioner() = default;

void SimulatedParallelPositioner::on_configure() {
  if (!thread_params_) {
    stage_.rearm();
    return;
  }
  if (!controller_) {  // the stage is still this thread's: rearm it, then hand it over
    stage_.rearm();
    controller_ = std::make_unique<ParallelPositionerController>(stage_, *thread_params_);
    return;
  }
  controller_->exchange();
  if (controller_->view().fault)
    throw InvalidInput("the positioner stopped on a fault (a diverged leg or no pose for its legs)");
  if (!controller_->rearm()) throw InvalidInput("the positioner's controller takes no more commands");
}

void SimulatedParallelPositioner::update(double /*dt_s*/) noexcept {
  if (controller_) {
    controller_->exchange();
    if (controller_->view().fault && state() != Lifecycle::kFault) fault();
    return;
  }
  // The physics runs in every state; the drive is the trackers' while Active, 0 V otherwise.
  for (int k = 0; k < ticks_per_update_; ++k) stage_.tick();
  if (stage_.fault() && state() != Lifecycle::kFault) fault();
}

void SimulatedParallelPositioner::enter_safe_state() noexcept {
  if (controller_)
    controller_->emergency_stop();
  else
    stage_.emergency_stop();
}

bool SimulatedParallelPositioner::start_move(const motion::PoseTrajectory& checked) noexcept {
  if (!active()) return false;
  if (!controller_) return stage_.start_move(checked);
  // What the stage would refuse at once (its status as of the last exchange); a start that no
  // longer matches the held pose when it arrives is refused there (view().refused).
  const auto& v = controller_->view();
  if (controller_->moving() || controller_->following() || v.halted || v.fault) return false;
  return controller_->start_move(checked);
}

bool SimulatedParallelPositioner::follow(const motion::PlatformTransform& target,
                                         const motion::PoseMoveLimits& limits) noexcept {
  if (!active()) return false;
  if (!controller_) return stage_.follow(target, limits);
  const auto& v = controller_->view();
  const bool move_running = controller_->moving() && !controller_->following();
  if (move_running || v.halted || v.fault || !target.R.allFinite() || !target.d.allFinite()) return false;
  return controller_->follow(target, limits);
}

void SimulatedParallelPositioner::stop() noexcept {
  if (controller_)
    controller_->stop();
  else
    stage_.stop();
}

bool SimulatedParallelPositioner::following() const noexcept {
  return controller_ ? controller_->following() : stage_.following();
}

bool SimulatedParallelPositioner::follow_blocked() const noexcept {
  return controller_ ? controller_->view().follow_blocked : stage_.follow_blocked();
}

const motion::PlatformTransform& SimulatedParallelPositioner::measured_pose() const noexcept {
  return controller_ ? controller_->view().measured : stage_.measured_pose();
}

const motion::PlatformTransform& SimulatedParallelPositioner::reference_pose() const noexcept {
  return controller_ ? controller_->view().reference : stage_.reference_pose();
}

const motion::PlatformTransform& SimulatedParallelPositioner::true_pose() const noexcept {
  return controller_ ? controller_->view().truth : stage_.true_pose();
}

bool SimulatedParallelPositioner::moving() const noexcept {
  return controller_ ? controller_->moving() : stage_.moving();
}

bool SimulatedParallelPositioner::at_rest() const noexcept {
  return controller_ ? controller_->at_rest() : stage_.at_rest();
}

double SimulatedParallelPositioner::max_leg_voltage_V() const noexcept {
  if (controller_) return controller_->view().max_leg_voltage_V;
  double u = 0.0;
  for (int i = 0; i < motion::kParallelAxes; ++i) u = std::max(u, std::abs(stage_.status(i).voltage_V));
  return u;
}

void SimulatedParallelPositioner::step_leg(int leg, motion::LegPositioner positioner, int steps,
                                           double frequency_Hz) {
  if (!active()) throw InvalidInput("device '" + name() + "': steps only while active");
  if (!controller_) {
    stage_.step_leg(leg, positioner, steps, frequency_Hz);
    return;
  }
  // The stage's checks here, so that a bad argument is the caller's error at once.
  motion::ParallelStage::check_step_leg(leg, steps, frequency_Hz);
  if (!controller_->step_leg(leg, positioner, steps, frequency_Hz))
    throw InvalidInput("the positioner's controller takes no more commands");
}

}  // namespace mc::devices
