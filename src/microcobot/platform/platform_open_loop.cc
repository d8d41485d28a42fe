// The platform's open-loop stepping (the ANC300's stepu/stepd) and open-loop velocity
// (x and y positioned by vision), with the safety rules every run obeys.
#include <cmath>

#include "microcobot/platform/platform.h"

namespace mc::platform {

bool Platform::start_open_loop_steps(int axis, double amplitude_V, double frequency_Hz, int direction,
                                     std::int64_t periods) noexcept {
  if (faulted_ || position_controlled_ || axis < 0 || axis > (has_rotary() ? 3 : 2)) return false;
  if (!(amplitude_V > 0.0 && amplitude_V <= model_->params().drive.max_V)) return false;
  if (!(frequency_Hz > 0.0 && frequency_Hz <= 10e3) || periods < 1 || periods > 1'000'000'000) return false;
  if (!(console_.active && console_.fresh && console_.deadman)) return false;
  const auto i = static_cast<std::size_t>(axis);
  // From the voltage on the axis: the controller's, or (x, y without sensors) the last run's.
  const double u_V = vision_xy_ && axis < 2 ? steppers_[i]->output_V() : stage_->last_voltage_V(axis);
  steppers_[i]->start(amplitude_V, frequency_Hz, direction, periods, u_V);
  return true;
}

bool Platform::command_open_loop_velocity(int axis, double velocity_m_s, double interval_s) noexcept {
  if (axis < 0 || axis > 2) return false;
  const devices::OpenLoopRun run = devices::plan_open_loop_run(*map_, devices::EncoderlessDriveParams{},
                                                               velocity_m_s * interval_s, interval_s);
  if (run.periods == 0) {
    steppers_[static_cast<std::size_t>(axis)]->halt();
    return !faulted_;
  }
  return start_open_loop_steps(axis, run.amplitude_V, run.frequency_Hz, run.direction, run.periods);
}

void Platform::stop_open_loop() noexcept {
  bool any = false;
  for (auto& st : steppers_) {
    any |= st->running();
    st->halt();
  }
  if (any) hold_axes();
}

bool Platform::open_loop_must_stop(std::size_t i) const noexcept {
  if (faulted_ || !(console_.active && console_.fresh && console_.deadman)) return true;
  const devices::Vec3 f = devices_.gripper->contact_force_N();
  if (std::hypot(f.x, f.y, f.z) > world_.params().contact_force_limit_N) return true;
  if (i == 3) {
    // The rotary axis: leaving its target's travel (the end stops less a margin) as it turns.
    const int dir = steppers_[i]->drive_direction();
    const double yaw = yaw_rad();
    return (dir > 0 && yaw >= yaw_max_rad()) || (dir < 0 && yaw <= yaw_min_rad());
  }
  // Without its sensor (x, y positioned by vision) an axis knows only its end stop.
  if (vision_xy_ && i < 2) return devices_.axes[i]->at_end_stop();
  // Leaving the workspace (or going below the floor) in the direction of travel.
  const double x = devices_.axes[i]->position_m();
  const int dir = steppers_[i]->drive_direction();
  const auto& tp = config_.teleop;
  if (dir > 0 && x >= tp.workspace_max_m) return true;
  if (dir < 0 && x <= tp.workspace_min_m) return true;
  if (i == 2 && dir < 0 && x <= teleop_->limits().params().floor_m) return true;
  return false;
}

}  // namespace mc::platform
