#include "microcobot/teleop/teleoperation.h"

#include <algorithm>
#include <cmath>

#include "microcobot/core/error.h"

namespace mc::teleop {

void TeleoperationParams::validate() const {
  require_positive(motion_scale, "motion_scale");
  require_non_negative(force_scale, "force_scale");
  require_positive(max_force_N, "max_force_N");
  require_positive(force_filter_Hz, "force_filter_Hz");
  require_positive(grip_position_scale, "grip_position_scale");
  require_non_negative(grip_force_scale, "grip_force_scale");
  require_positive(max_grip_force_N, "max_grip_force_N");
  require_positive(max_jog_m_s, "max_jog_m_s");
  require_positive(console_max_speed_m_s, "console_max_speed_m_s");
  require_positive(velocity_filter_s, "velocity_filter_s");
  require(workspace_min_m < workspace_max_m, "workspace_min_m", "must be below workspace_max_m",
          workspace_min_m);
  fixtures.validate();
}

Teleoperation::Teleoperation(const TeleoperationParams& params, double dt_s,
                             const Eigen::Vector3d& slave_start_m, double gripper_start_m,
                             const SafetyLimitParams& limits)
    : p_(params), limits_(limits), dt_(dt_s), fixtures_(params.fixtures) {
  p_.validate();
  require_positive(dt_s, "dt_s");
  out_.slave_target_m = slave_start_m;
  kept_from_m_ = slave_start_m;
  out_.gripper_opening_m = gripper_start_m;
  last_xy_m_ = slave_start_m.head<2>();
  raw_xy_m_ = last_xy_m_;
  raw_z_m_ = slave_start_m.z();
  scale_ = p_.motion_scale;
  force_alpha_ = 1.0 - std::exp(-2.0 * M_PI * p_.force_filter_Hz * dt_s);
  velocity_alpha_ = 1.0 - std::exp(-dt_s / p_.velocity_filter_s);
}

double Teleoperation::clamp_workspace(double v) const noexcept {
  return std::clamp(v, p_.workspace_min_m, p_.workspace_max_m);
}

void Teleoperation::console_tick(const TeleoperationInput& in) noexcept {
  const ConsoleInput& c = in.console;
  out_.engaged = c.deadman && c.fresh;
  out_.stale = !c.fresh;
  out_.slave_velocity_m_s.setZero();
  out_.haptic_force_N.setZero();
  force_filtered_N_.setZero();
  if (out_.engaged) {
    // The console moves the master's own target (before the fixtures), from where it is.
    const Eigen::Vector3d base(raw_xy_m_.x(), raw_xy_m_.y(), raw_z_m_);
    Eigen::Vector3d v = Eigen::Vector3d::Zero();
    if (c.has_goal && c.goal_m.allFinite()) {
      // Straight to the goal at the requested speed, landing on it exactly.
      const double speed = std::clamp(c.goal_speed_m_s, 0.0, p_.console_max_speed_m_s);
      Eigen::Vector3d goal = c.goal_m;
      for (int i = 0; i < 3; ++i) goal[i] = clamp_workspace(goal[i]);
      const Eigen::Vector3d d = goal - base;
      const double n = d.norm();
      v = n <= speed * dt_ ? Eigen::Vector3d(d / dt_) : Eigen::Vector3d(d * (speed / n));
    } else if (c.velocity_m_s.allFinite()) {
      // A joystick is a rate control: the fixtures' scaling gain is on its speed in the plane.
      // A rate control: the stage's pace, not a hand's workspace, limits coarse motion, so the
      // fixtures' coarse-far gain does not apply (a gain the person cannot see at the joystick
      // only made them overshoot); guidance and forbidden regions do.
      v = c.velocity_m_s;
      scale_ = p_.motion_scale;
      const double n = v.norm();
      if (n > p_.console_max_speed_m_s) v *= p_.console_max_speed_m_s / n;
    }
    Eigen::Vector3d raw;
    for (int i = 0; i < 3; ++i) raw[i] = clamp_workspace(base[i] + v[i] * dt_);
    raw_xy_m_ = raw.head<2>();
    raw_z_m_ = raw.z();
    const Eigen::Vector3d before = out_.slave_target_m;
    out_.slave_target_m.head<2>() = fixtures_.confined_xy(follow_fixtures(before.head<2>()), before.z());
    out_.slave_target_m.z() = follow_height(before.z(), out_.slave_target_m.head<2>());
    out_.slave_velocity_m_s = (out_.slave_target_m - before) / dt_;
  }
  // The gripper moves on the console's command only while the coupling is engaged (deadman
  // held, commands fresh); otherwise it holds its opening.
  const double requested = out_.engaged && c.has_gripper && std::isfinite(c.gripper_opening_m)
                               ? std::max(0.0, c.gripper_opening_m)
                               : out_.gripper_opening_m;
  apply_limits(in, requested);
  out_.gripper_shake = out_.engaged && c.has_gripper && c.gripper_shake;
  if (!out_.engaged) {
    raw_xy_m_ = out_.slave_target_m.head<2>();
    raw_z_m_ = out_.slave_target_m.z();
  }
  sync_raw_z();
  last_xy_m_ = out_.slave_target_m.head<2>();
  out_.finger_force_N = 0.0;
  console_had_control_ = true;
}

void Teleoperation::apply_limits(const TeleoperationInput& in, double requested_opening_m) noexcept {
  // The neighbours' keep-out regions first (virtual_fixtures.h): from where the target was at the
  // last tick; the master's own target goes with the correction (no wind-up).
  Eigen::Vector3d kept = out_.slave_target_m;
  if (fixtures_.keep_out(kept_from_m_, kept)) {
    const Eigen::Vector3d d = kept - out_.slave_target_m;
    offset_m_ += d.head<2>();
    raw_xy_m_ += d.head<2>();
    raw_z_m_ += d.z();
    for (int i = 0; i < 3; ++i)
      if (d[i] != 0.0) out_.slave_velocity_m_s[i] = 0.0;
    out_.slave_target_m = kept;
  }
  const Eigen::Vector3d before = out_.slave_target_m;
  limits_.limit_target(out_.slave_target_m, out_.slave_velocity_m_s, in.slave_position_m, in.contact_force_N);
  if (out_.slave_target_m.z() < floor_m_) {
    out_.slave_target_m.z() = floor_m_;
    out_.slave_velocity_m_s.z() = std::max(0.0, out_.slave_velocity_m_s.z());
  }
  if (out_.slave_target_m.z() > ceiling_m_) {
    out_.slave_target_m.z() = ceiling_m_;
    out_.slave_velocity_m_s.z() = std::min(0.0, out_.slave_velocity_m_s.z());
  }
  contact_limited_ = limits_.contact_over_limit(in.contact_force_N);
  // A hand that pushes on into a held contact slips like a clutch: when the force drops, the
  // slave does not jump to where the hand went meanwhile.
  offset_m_ += (out_.slave_target_m - before).head<2>();
  raw_xy_m_ += (out_.slave_target_m - before).head<2>();
  raw_z_m_ += out_.slave_target_m.z() - before.z();
  out_.gripper_opening_m = limits_.limit_opening_m(requested_opening_m, in.gripper_opening_m, in.grip_force_N,
                                                   out_.gripper_opening_m);
  kept_from_m_ = out_.slave_target_m;
}

void Teleoperation::hold_at(const Eigen::Vector3d& measured_m) noexcept {
  if (measured_m.allFinite()) out_.slave_target_m = measured_m;
  kept_from_m_ = out_.slave_target_m;
  out_.slave_velocity_m_s.setZero();
  out_.engaged = false;
  out_.haptic_force_N.setZero();
  force_filtered_N_.setZero();
  last_xy_m_ = out_.slave_target_m.head<2>();
  raw_xy_m_ = last_xy_m_;
  raw_z_m_ = out_.slave_target_m.z();
}

void Teleoperation::set_fixtures(const FixtureSet& set) noexcept {
  const FixtureSet before = fixtures_.fixtures();
  fixtures_.set(set);
  const FixtureSet& now = fixtures_.fixtures();
  if (now.guide != before.guide || now.guide_xy_m != before.guide_xy_m || now.path != before.path ||
      now.path_from_xy_m != before.path_from_xy_m)
    reindex_ = true;
  if (now.height != before.height || now.height_z_m != before.height_z_m) reindex_z_ = true;
}

double Teleoperation::follow_height(double from_z, const Eigen::Vector2d& xy) noexcept {
  const double lowest = fixtures_.lowest_z(xy, from_z);
  double z = raw_z_m_;
  if (fixtures_.height_active() || slewing_z_) {
    // As in the plane: toward the guided height no faster than the stage follows.
    const double want = fixtures_.guided_z(raw_z_m_), step = p_.fixtures.max_speed_m_s * dt_;
    slewing_z_ = std::abs(want - from_z) > step;
    z = slewing_z_ ? from_z + std::copysign(step, want - from_z) : want;
  }
  // The funnel holds the target up, and the master's height with it (no wind-up below the cone:
  // reaching the axis must not drop the target to where the input went meanwhile).
  if (z < lowest) {
    z = lowest;
    raw_z_m_ = std::max(raw_z_m_, lowest);
  }
  return z;
}

void Teleoperation::sync_raw_z() noexcept {
  if (!fixtures_.height_active() && !slewing_z_) raw_z_m_ = out_.slave_target_m.z();
}

Eigen::Vector2d Teleoperation::follow_fixtures(const Eigen::Vector2d& from) noexcept {
  const Eigen::Vector2d want = fixtures_.guided(raw_xy_m_);
  if (!fixtures_.active() && !slewing_) return want;
  // Where the fixtures act, the target moves toward the guided one no faster than the stage
  // follows: the guidance's map is steep at the capture radius' edge, and a target that steps
  // far ahead of the stick-slip stage makes its tracking controller overshoot.
  const Eigen::Vector2d d = want - from;
  const double step = p_.fixtures.max_speed_m_s * dt_, n = d.norm();
  slewing_ = n > step;
  return slewing_ ? Eigen::Vector2d(from + d * (step / n)) : want;
}

const TeleoperationOutput& Teleoperation::tick(const TeleoperationInput& in) noexcept {
  fixtures_.tick(dt_);
  out_.gripper_shake = false;  // the console's path below turns it on, engaged only
  if (reindex_) {
    // The master's own target becomes where the slave is sent now (like a clutch), so that the
    // new field starts from the slave's target, not from where the hand's mapping would put it.
    const Eigen::Vector2d shift = out_.slave_target_m.head<2>() - raw_xy_m_;
    raw_xy_m_ += shift;
    offset_m_ += shift;
    reindex_ = false;
  }
  if (reindex_z_) {
    raw_z_m_ = out_.slave_target_m.z();  // the new stop's field starts from the target
    reindex_z_ = false;
  }
  if (!in.slave_fresh) {
    // A silent slave (a remote one whose link went quiet): nothing to couple to. No force on
    // either master; the target is re-taken from the slave once it reports again.
    out_.engaged = false;
    out_.stale = true;
    out_.slave_velocity_m_s.setZero();
    out_.haptic_force_N.setZero();
    out_.finger_force_N = 0.0;
    force_filtered_N_.setZero();
    slave_was_stale_ = true;
    return out_;
  }
  if (slave_was_stale_ && in.slave_position_m.allFinite()) {
    // Back from silence (possibly a restarted slave, elsewhere): hold where it is now, so that
    // re-engaging never moves it (the haptic path below re-indexes its offset on engagement).
    out_.slave_target_m = in.slave_position_m;
    kept_from_m_ = out_.slave_target_m;
    last_xy_m_ = out_.slave_target_m.head<2>();
    raw_xy_m_ = last_xy_m_;
    raw_z_m_ = out_.slave_target_m.z();
    out_.engaged = false;
    slave_was_stale_ = false;
  }
  if (in.console.active) {
    console_tick(in);
    return out_;
  }
  const bool engage = in.deadman && !in.clutch && in.haptic_fresh && in.handle_m.allFinite();
  // The fixtures' scaling gain at the master's target; the offset absorbs a change of scale, so
  // that the slave never jumps with it (the increments are scaled, not the handle's position).
  const Eigen::Vector2d last_handle = last_handle_m_;
  const Eigen::Vector2d handle_v = (in.handle_m - last_handle) / dt_;
  if (in.handle_m.allFinite()) last_handle_m_ = in.handle_m;
  const double scale = p_.motion_scale * fixtures_.scale_gain(raw_xy_m_);
  if (engage && (!out_.engaged || console_had_control_)) {
    // Re-index: the slave target stays where it is whatever the hand position.
    scale_ = scale;
    offset_m_ = raw_xy_m_ - scale_ * in.handle_m;
    fixtures_.rebase_energy(raw_xy_m_, scale_);
  } else if (engage) {
    // Re-indexed at the last handle position: this tick's increment moves at the new scale.
    offset_m_ += (scale_ - scale) * last_handle;
    scale_ = scale;
  }
  console_had_control_ = false;
  out_.engaged = engage;
  out_.stale = !in.haptic_fresh || !in.tweezers_fresh;
  out_.slave_velocity_m_s.setZero();
  if (engage) {
    const Eigen::Vector2d raw = offset_m_ + scale_ * in.handle_m;
    for (int i = 0; i < 2; ++i) raw_xy_m_[i] = clamp_workspace(raw[i]);
    out_.slave_target_m.head<2>() =
        fixtures_.confined_xy(follow_fixtures(last_xy_m_), out_.slave_target_m.z());
    // The target's velocity, low-passed: a master read slower than this loop moves the target
    // in steps, and a feedforward of one tick's step (ten times the hand's speed for one tick
    // in ten) threw the stick-slip tracking controller into a limit cycle of millimetres.
    const Eigen::Vector2d v_tick = (out_.slave_target_m.head<2>() - last_xy_m_) / dt_;
    velocity_ff_ += velocity_alpha_ * (v_tick - velocity_ff_);
    // A still target is still: the filter's tail would otherwise keep the stage's controller
    // in its moving mode (its lead, no in-position hold) for ever.
    if (v_tick.isZero(0.0) && velocity_ff_.norm() < 1e-7) velocity_ff_.setZero();
    out_.slave_velocity_m_s.head<2>() = velocity_ff_;
    const double jog =
        std::isfinite(in.z_jog_m_s) ? std::clamp(in.z_jog_m_s, -p_.max_jog_m_s, p_.max_jog_m_s) : 0.0;
    const double before_z = out_.slave_target_m.z();
    raw_z_m_ = clamp_workspace(raw_z_m_ + jog * dt_);
    out_.slave_target_m.z() = follow_height(before_z, out_.slave_target_m.head<2>());
    // The wheel's rate, or what a height stop makes of it.
    out_.slave_velocity_m_s.z() =
        fixtures_.height_active() || slewing_z_ ? (out_.slave_target_m.z() - before_z) / dt_ : jog;
    // Slave forces back to the hand, in the handle's plane (slave XY = handle xy).
    Eigen::Vector2d f = p_.force_scale * in.contact_force_N.head<2>();
    if (!f.allFinite()) f.setZero();
    force_filtered_N_ += force_alpha_ * (f - force_filtered_N_);
    f = force_filtered_N_;
    const double n = f.norm();
    if (!(n <= p_.max_force_N))
      f = n > 0 && std::isfinite(n) ? Eigen::Vector2d(f * (p_.max_force_N / n)) : Eigen::Vector2d::Zero();
    // The guidance felt, under its own passivity controller and its own cap.
    f += fixtures_.display_force(raw_xy_m_, out_.slave_target_m.head<2>(), handle_v, scale_, dt_);
    out_.haptic_force_N = f;
  } else {
    out_.haptic_force_N.setZero();
    force_filtered_N_.setZero();
    velocity_ff_.setZero();
    raw_xy_m_ = out_.slave_target_m.head<2>();
    raw_z_m_ = out_.slave_target_m.z();
  }
  // The gripper follows the TéléTweez only while the deadman is held (and its readings are
  // fresh); otherwise it holds its opening.
  const bool tweezers_ok = in.tweezers_fresh && std::isfinite(in.tweezers_opening_m);
  const double requested =
      in.deadman && tweezers_ok ? p_.grip_position_scale * in.tweezers_opening_m : out_.gripper_opening_m;
  apply_limits(in, requested);
  sync_raw_z();
  last_xy_m_ = out_.slave_target_m.head<2>();
  if (tweezers_ok) {
    const double f = p_.grip_force_scale * in.grip_force_N;
    out_.finger_force_N = std::isfinite(f) ? std::clamp(f, -p_.max_grip_force_N, p_.max_grip_force_N) : 0.0;
  } else {
    out_.finger_force_N = 0.0;
  }
  return out_;
}

}  // namespace mc::teleop
