// The simulated person's aimed movements (person_operator.h): steering the tool in the plane
// (the haptic hand with its clutch, the joystick's rate, the console's clicks), turning the dial,
// bringing the tool to a height. Each waits for the person to see the last movement end.
#include <algorithm>
#include <cmath>

#include "microcobot/cell/person_operator.h"
#include "microcobot/microworld/pick_place_world.h"

namespace mc::cell {

bool PersonOperator::click_steer(const Eigen::Vector2d& error_m, double tolerance_m, double t) noexcept {
  if (click_goal_.active) {
    // The stage on its way to the click: the person watches it arrive, and reacts.
    if (t - click_goal_.since_s < p_.still_window_s || !tool_still()) return false;
    click_goal_.active = false;
    cursor_.reset(cursor_.end(), t);
    return false;
  }
  if (!cursor_.ready(t) || !tool_still()) return false;
  const Eigen::Vector2d e = seen(error_m);
  if (e.norm() <= tolerance_m) return true;
  // A target narrower than min_click_px on the screen is clicked zoomed in.
  const double scale = std::max(p_.screen_px_per_m, p_.min_click_px / tolerance_m);
  if (scale != cursor_scale_) {
    cursor_.reset(cursor_.end() * (scale / cursor_scale_), t);  // the same point, another zoom: a look
    cursor_scale_ = scale;
    return false;
  }
  // The cursor onto the target as seen (tool + e), within the target's width on the screen.
  const Eigen::Vector2d target_px = (tool_xy_ + e) * scale;
  if (!cursor_.aim(target_px - cursor_.end(), std::max(tolerance_m * scale, p_.min_click_px), t))
    return false;
  const Eigen::Vector2d at = cursor_.end() / scale;
  click_goal_.at_m = {at.x(), at.y(), tips_.back(0).z()};
  click_goal_.active = true;
  click_goal_.since_s = t;
  return false;
}

bool PersonOperator::steer(const Eigen::Vector2d& error_m, double tolerance_m, double t,
                           double width_m) noexcept {
  if (click_) return click_steer(error_m, tolerance_m, t);
  if (clutching_) {
    if (xy_.moving(t)) return false;
    clutching_ = false;  // the hand back: clutch released, and a look before going on
    hand_.clutch = false;
    xy_.reset(xy_.end(), t);
    return false;
  }
  if (!xy_.ready(t) || !tool_still()) return false;
  const Eigen::Vector2d e = seen(error_m);
  // The person knows how the master maps to the stage, the shared control's coarse-far,
  // fine-near scaling included: over a move from scale s0 to s1 (linear in the distance) the
  // hand travels D ln(s0/s1) / (s0 - s1), the scale's log-mean.
  const double s0 = platform_.motion_scale(), s1 = platform_.motion_scale_at(tool_xy_ + e);
  const double scale = std::abs(s0 - s1) < 1e-9 * s0 ? s0 : (s0 - s1) / std::log(s0 / s1);
  // Alone, the person keeps the slave to the stage's pace (a target run ahead makes the stick-slip
  // stage overshoot); with shared control the platform paces the target itself (the fixtures'
  // max_speed_m_s), so the person moves faster and the stage runs at its pace the whole way.
  const double pace = assisted_ ? p_.assisted_pace_m_s : p_.person.stage_pace_m_s;
  if (!haptic_) {
    const double gain = scale / base_scale_;
    return xy_.aim(e / gain, tolerance_m / gain, t, pace / gain, width_m / gain);
  }
  const double hand_max = pace / scale;
  Eigen::Vector2d move = e / scale;
  const Eigen::Vector2d from = xy_.end();
  const Eigen::Vector2d to = from + move;
  if (to.cwiseAbs().maxCoeff() > p_.hand_limit_m) {
    bool at_edge = false;
    for (int i = 0; i < 2; ++i)
      at_edge |= std::abs(to[i]) > p_.hand_limit_m && std::abs(from[i]) > 0.7 * p_.hand_limit_m;
    if (at_edge) {
      // Clutch: the slave holds while the hand goes back across the workspace.
      Eigen::Vector2d back = from;
      for (int i = 0; i < 2; ++i)
        if (std::abs(to[i]) > p_.hand_limit_m) back[i] = -std::copysign(0.5 * p_.hand_limit_m, move[i]);
      hand_.clutch = true;
      clutching_ = true;
      ++clutches_;
      xy_.move(back, p_.person.movement_time_s((back - from).norm(), 5e-3), t);
      return false;
    }
    // As far as the workspace lets the hand go.
    double f = 1.0;
    for (int i = 0; i < 2; ++i)
      if (std::abs(to[i]) > p_.hand_limit_m)
        f = std::min(f, (std::copysign(0.95 * p_.hand_limit_m, move[i]) - from[i]) / move[i]);
    move *= std::max(f, 0.0);
    xy_.aim(move, tolerance_m / scale, t, hand_max, width_m / scale);
    return false;
  }
  return xy_.aim(move, tolerance_m / scale, t, hand_max, width_m / scale);
}

bool PersonOperator::turn_by(double delta_rad, double t) noexcept {
  // The rotor still where the dial put it before the person judges again.
  if (!yaw_.ready(t) || std::abs(platform_.yaw_rad() - platform_.yaw_target_rad()) > 2e-3) return false;
  const double seen_delta = delta_rad + rng_.normal(0.0, p_.yaw_vision_sd_rad);
  return yaw_.aim({seen_delta, 0.0}, p_.yaw_tolerance_rad, t,
                  platform_.config().stage.rotary.max_speed_rad_s);
}

bool PersonOperator::turn(double misalignment, double t) noexcept {
  const double fingers = platform_.yaw_rad();
  const auto to_square = [&](double seen_misalignment) {
    return square_yaw_goal(fingers + seen_misalignment, fingers, goal_.yaw_min_rad, goal_.yaw_max_rad);
  };
  if (assisted_) {
    // The cell's vision measures the misalignment once; the platform turns there.
    if (!turn_.under_way) {
      turn_.goal_rad = to_square(misalignment + rng_.normal(0.0, p_.assist_yaw_sd_rad));
      turn_.under_way = true;
    }
    if (std::abs(fingers - turn_.goal_rad) > turn_.arrived_rad) return false;
    turn_.under_way = false;
    yaw_.reset({turn_.goal_rad, 0.0}, t);  // the dial where the rotor now is
    return true;
  }
  // The rotor still where the dial put it before the person judges again.
  if (!yaw_.ready(t) || std::abs(fingers - platform_.yaw_target_rad()) > 2e-3) return false;
  const double goal = to_square(misalignment + rng_.normal(0.0, p_.yaw_vision_sd_rad));
  return yaw_.aim({goal - fingers, 0.0}, p_.yaw_tolerance_rad, t,
                  platform_.config().stage.rotary.max_speed_rad_s);
}

double PersonOperator::bore_misalignment() const noexcept {
  return microworld::wrap_quarter_turn(goal_.target_yaw_rad - sim_.gripper->world_state().part_yaw_rad);
}

bool PersonOperator::climb(double z_goal, double tip_z, double tolerance_m, double t,
                           double width_m) noexcept {
  if (!z_.ready(t) || !tool_still()) return false;
  const double e = z_goal - tip_z + rng_.normal(0.0, p_.person.vision_sd_m);
  const double v_max =
      haptic_ ? platform_.config().teleop.max_jog_m_s : platform_.config().teleop.console_max_speed_m_s;
  return z_.aim({e, 0.0}, tolerance_m, t, v_max, width_m > 0.0 ? width_m : tolerance_m);
}

}  // namespace mc::cell
