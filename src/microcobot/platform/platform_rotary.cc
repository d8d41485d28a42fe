// The platform's rotary axis (motion/rotary_axis.h): its target from the
// console's theta commands under the console's deadman, its controller on the stage controller's
// fourth channel (the arc at the contact radius), its drive (or an open-loop run's), its hold.
#include <algorithm>
#include <cmath>

#include "microcobot/platform/platform.h"

namespace mc::platform {

void Platform::build_rotary() {
  if (!devices_.rotary) return;
  const auto& r = config_.stage.rotary;
  // The actuator's end stops lie half a stroke either side of its middle (the axis' 0); the
  // target keeps 5 % of that away from them.
  const double reach_m = 0.45 * model_->params().slider.stroke_m;
  rotary_target_ = std::make_unique<teleop::RotaryTarget>(r, config_.loop.period_s(), r.home_rad,
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
  teleop::ConsoleInput c = console_;
  c.deadman = console_.deadman && !faulted_;
  if (coupling_.master_on) c.theta_rate_rad_s = 0.0;  // the dial turns the part's positioner
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

void Platform::park_still_axes(const std::array<double, StageController::kMaxAxes>& target,
                               const std::array<double, StageController::kMaxAxes>& measured) noexcept {
  const auto& st = config_.stage;
  const int after = static_cast<int>(std::lround(st.park_after_s * config_.loop.slave_rate_Hz()));
  for (std::size_t i = 0; i < static_cast<std::size_t>(stage_->axis_count()); ++i) {
    const int axis = static_cast<int>(i);
    // Open-loop runs and vision's x, y are not the controller's to park.
    const bool parkable = after > 0 && !(steppers_[i]->running() || (vision_xy_ && i < 2));
    const bool still = target[i] == last_target_m_[i];
    last_target_m_[i] = target[i];
    if (!parkable || !still) {
      still_ticks_[i] = 0;
      stage_->unpark(axis, measured[i]);
      continue;
    }
    if (stage_->parked(axis)) continue;
    still_ticks_[i] = std::abs(measured[i] - target[i]) <= st.park_tolerance_m ? still_ticks_[i] + 1 : 0;
    if (still_ticks_[i] >= after) stage_->park(axis);
  }
}

bool Platform::rotary_drive(double dt_s) noexcept {
  if (!devices_.rotary) return false;
  // An open-loop run (the ANC300's stepu/stepd on the rotary axis) plays straight to it, as on
  // the linear axes (devices_task()).
  devices::OpenLoopStepper& st = *steppers_[3];
  const bool was_running = st.running();
  if (was_running && open_loop_must_stop(3)) st.halt();
  if (!faulted_ && !position_controlled_) {
    if (st.running()) {
      const devices::DriveBlock open_loop = st.drive();
      stage_->drive(3, devices_.rotary->position_m());  // keeps the controller's clock
      devices_.rotary->command_drive(open_loop);
    } else {
      devices_.rotary->command_drive(stage_->drive(3, devices_.rotary->position_m()));
    }
  }
  devices_.rotary->update(dt_s);
  const bool ended = was_running && !st.running();
  // The loop resumes from the run's end (0 V, halted or at a period boundary): the state it kept
  // while set aside made it run away on the rotor (the linear axes' hand-back does not need this).
  if (ended && !faulted_) stage_->resume(3, devices_.rotary->position_m(), 0.0);
  return ended;
}

}  // namespace mc::platform
