// The platform's rotary axis (issue #29 point 2; control/rotary_axis.h): its target from the
// console's theta commands under the console's deadman, its controller on the stage controller's
// fourth channel (the arc at the contact radius), its drive, its hold.
#include <algorithm>

#include "microcobot/platform/platform.h"

namespace mc::platform {

void Platform::build_rotary() {
  if (!devices_.rotary) return;
  const auto& r = config_.stage.rotary;
  // The actuator's end stops lie half a stroke either side of its middle (the axis' 0); the
  // target keeps 5 % of that away from them.
  const double reach_m = 0.45 * model_->params().slider.stroke_m;
  rotary_target_ = std::make_unique<control::RotaryTarget>(r, config_.loop.period_s(), r.home_rad,
                                                           r.angle_rad(-reach_m), r.angle_rad(reach_m));
}

double Platform::yaw_rad() const noexcept {
  return devices_.rotary ? config_.stage.rotary.angle_rad(devices_.rotary->position_m()) : 0.0;
}

double Platform::yaw_target_rad() const noexcept {
  return rotary_target_ ? rotary_target_->target_rad() : 0.0;
}

void Platform::rotary_command() noexcept {
  if (!rotary_target_) return;
  control::ConsoleInput c = console_;
  c.deadman = console_.deadman && !faulted_;
  rotary_target_->tick(c);
}

void Platform::rotary_control(std::array<double, StageController::kMaxAxes>& target,
                              std::array<double, StageController::kMaxAxes>& velocity,
                              std::array<double, StageController::kMaxAxes>& measured) noexcept {
  if (!devices_.rotary) return;
  const auto& r = config_.stage.rotary;
  measured[3] = devices_.rotary->position_m();
  target[3] = r.arc_m(rotary_target_->target_rad());
  velocity[3] = rotary_target_->velocity_rad_s() * r.radius_m;
}

void Platform::rotary_drive(double dt_s) noexcept {
  if (!devices_.rotary) return;
  if (!faulted_ && !position_controlled_)
    devices_.rotary->command_drive(stage_->drive(3, devices_.rotary->position_m()));
  devices_.rotary->update(dt_s);
}

}  // namespace mc::platform
