#include "microcobot/motion/parallel_stage.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "microcobot/core/error.h"
#include "microcobot/motion/closed_loop.h"
#include "microcobot/motion/parallel_workspace.h"

namespace mc::motion {

LegPositioner parse_leg_positioner(const std::string& name) {
  if (name == "radial") return LegPositioner::kRadial;
  if (name == "tangential") return LegPositioner::kTangential;
  throw UsageError("the positioner must be radial or tangential (got '" + name + "')");
}

ParallelStage::ParallelStage(const stickslip::ActuatorModel& model, const StepMap& map,
                             const ParallelStageParams& p)
    : model_(model), p_(p), kin_(p.geometry) {
  p_.validate();
  require(model.params().slider.stroke_m >= p_.geometry.stroke_m, "geometry.stroke_m",
          "must not exceed the actuator model's stroke", p_.geometry.stroke_m);
  ratio_ = steps_per_tick(model, p_.tracking.control_rate_Hz);
  for (std::size_t i = 0; i < axes_.size(); ++i) {
    PositionSensorParams sp = p_.sensor;
    sp.seed = p_.sensor.seed + static_cast<int>(i);  // independent noise per axis
    auto& ax = axes_[i];
    ax.state = model.initial_state();
    ax.sensor = PositionSensor(sp);
    ax.ctrl = std::make_unique<TrackingController>(p_.tracking, model.params(), map);
    ax.gen = SawtoothGenerator(model.params().drive.slew_rate_V_s);
  }
  spare_ = std::make_unique<PoseTrajectory>(PlatformTransform{}, PlatformTransform{}, p_.move);
  place(PlatformTransform{});
}

void ParallelStage::place(const PlatformTransform& T) {
  const ReachCheck c = check_pose(kin_, T);
  if (!c.ok()) throw PoseUnreachable(to_smarpod(T), c);
  for (std::size_t i = 0; i < axes_.size(); ++i) {
    auto& ax = axes_[i];
    const double q = c.q(static_cast<Eigen::Index>(i));
    ax.state = model_.initial_state();
    ax.state.x2_m = {q, q};
    ax.stepping = false;
    ax.gen.halt();
    ax.measured = ax.sensor.measure(q);
    ax.ctrl->reset(ax.measured, ax.state.u_V);
    ax.hold = q;
  }
  measured_T_ = true_T_ = ref_T_ = T;
  true_stale_ = false;
  moving_ = following_ = follow_blocked_ = false;
  fault_ = halted_ = false;
  t_move_ = 0.0;
}

MoveCheck ParallelStage::move_to(const PlatformTransform& goal) { return move_to(goal, p_.move); }

MoveCheck ParallelStage::move_to(const PlatformTransform& goal, const PoseMoveLimits& limits) {
  if (fault_) throw InvalidInput("the positioner is stopped on a fault: place it again");
  if (halted_) throw InvalidInput("the positioner is halted (emergency stop): rearm it first");
  for (std::size_t i = 0; i < axes_.size(); ++i) {
    if (axes_[i].stepping)
      throw InvalidInput("leg " + std::to_string(i / 2) + " is stepping open loop: wait for it or stop()");
  }
  if (following_) stop();  // a planned move takes over from a streamed target
  // The goal's own check first: a NaN or an unreachable goal is named as such.
  const ReachCheck g = check_pose(kin_, goal);
  if (!g.ok()) throw InvalidInput(std::string("goal: ") + PoseUnreachable(to_smarpod(goal), g).what());
  // The move starts where the legs are held (after a move: its goal; after stop() or stepping:
  // where they were measured).
  LegCoordinates q_hold;
  for (std::size_t i = 0; i < axes_.size(); ++i) q_hold(static_cast<Eigen::Index>(i)) = axes_[i].hold;
  const PlatformTransform start = kin_.forward(q_hold, ref_T_).T;
  auto traj = std::make_unique<PoseTrajectory>(start, goal, limits);
  const MoveCheck c = check_move(kin_, *traj);
  if (!c.ok) throw InvalidInput(c.reason);
  traj_ = std::move(traj);
  ref_T_ = start;
  t_move_ = 0.0;
  moving_ = true;
  return c;
}

bool ParallelStage::start_move(const PoseTrajectory& checked) noexcept {
  if (fault_ || halted_ || moving_ || following_) return false;
  for (const auto& ax : axes_)
    if (ax.stepping) return false;
  constexpr double kSame = 1e-9;
  if ((checked.start().R - ref_T_.R).cwiseAbs().maxCoeff() > kSame ||
      (checked.start().d - ref_T_.d).cwiseAbs().maxCoeff() > kSame)
    return false;
  if (!traj_) traj_ = std::move(spare_);
  if (!traj_) return false;
  *traj_ = checked;
  ref_T_ = checked.start();
  t_move_ = 0.0;
  moving_ = true;
  return true;
}

namespace {

// The velocity one tick of `h` later that pursues the error `e` (the target minus the reference):
// toward it at the speed from which `a_max` stops on it, at most `v_max` and no faster than
// reaching it within the tick, reached from `v` with at most `a_max` of acceleration.
Eigen::Vector3d pursue(const Eigen::Vector3d& e, const Eigen::Vector3d& v, double v_max, double a_max,
                       double h) noexcept {
  const double distance = e.norm();
  Eigen::Vector3d wanted = Eigen::Vector3d::Zero();
  if (distance > 0.0)
    wanted = e * (std::min({v_max, std::sqrt(2.0 * a_max * distance), distance / h}) / distance);
  const Eigen::Vector3d dv = wanted - v;
  const double dv_max = a_max * h, dv_norm = dv.norm();
  return dv_norm <= dv_max ? wanted : Eigen::Vector3d(v + dv * (dv_max / dv_norm));
}

}  // namespace

bool ParallelStage::follow(const PlatformTransform& target, const PoseMoveLimits& limits) noexcept {
  if (fault_ || halted_ || moving_) return false;
  for (const auto& ax : axes_)
    if (ax.stepping) return false;
  if (!target.R.allFinite() || !target.d.allFinite()) return false;
  for (double x : {limits.max_speed_m_s, limits.max_angular_speed_rad_s, limits.max_acceleration_m_s2,
                   limits.max_angular_acceleration_rad_s2, limits.max_leg_speed_m_s})
    if (!std::isfinite(x) || x < 0.0) return false;
  if (!following_) {
    // From the held pose, at rest: the legs' reference starts where they hold.
    for (std::size_t i = 0; i < axes_.size(); ++i) ref_.q(static_cast<Eigen::Index>(i)) = axes_[i].hold;
    ref_.v.setZero();
    ref_.a.setZero();
    follow_v_.setZero();
    follow_w_.setZero();
    follow_blocked_ = false;
    follow_still_ = true;
    following_ = true;
  }
  follow_target_ = target;
  follow_limits_ = limits;
  return true;
}

void ParallelStage::advance_follow() noexcept {
  const double h = tick_s();
  const PoseMoveLimits& lim = follow_limits_;
  const Eigen::Vector3d e_d = follow_target_.d - ref_T_.d;
  const Eigen::Vector3d e_r = log_so3(follow_target_.R * ref_T_.R.transpose());
  Eigen::Vector3d v = pursue(e_d, follow_v_, lim.max_speed_m_s, lim.max_acceleration_m_s2, h);
  Eigen::Vector3d w =
      pursue(e_r, follow_w_, lim.max_angular_speed_rad_s, lim.max_angular_acceleration_rad_s2, h);
  // On the target (within rounding) at a speed a tick's braking takes out: there, exactly, at rest.
  const bool arrive_d = e_d.norm() < kFollowArrival && follow_v_.norm() <= lim.max_acceleration_m_s2 * h;
  const bool arrive_r =
      e_r.norm() < kFollowArrival && follow_w_.norm() <= lim.max_angular_acceleration_rad_s2 * h;
  if (arrive_d) v.setZero();
  if (arrive_r) w.setZero();
  PlatformTransform next;
  LegCoordinates q;
  Reach reach = Reach::kReachable;
  const double stroke_left = 0.5 * p_.geometry.stroke_m - kFollowStrokeMargin_m;
  // The legs' speeds within their limit: the step scaled down once where one leg would go faster.
  for (int pass = 0; pass < 2; ++pass) {
    next.d = arrive_d ? follow_target_.d : Eigen::Vector3d(ref_T_.d + v * h);
    next.R = arrive_r ? follow_target_.R : Eigen::Matrix3d(exp_so3(w * h) * ref_T_.R);
    reach = reach_of(kin_, next, q);
    if (reach == Reach::kReachable && q.cwiseAbs().maxCoeff() > stroke_left) reach = Reach::kStrokeLimit;
    if (reach != Reach::kReachable) break;
    const double leg_speed = ((q - ref_.q) / h).cwiseAbs().maxCoeff();
    if (leg_speed <= lim.max_leg_speed_m_s || leg_speed == 0.0) break;
    const double scale = lim.max_leg_speed_m_s / leg_speed;
    v *= scale;
    w *= scale;
  }
  follow_blocked_ = reach != Reach::kReachable;
  if (follow_blocked_) {
    // The reference stays where it is, at rest: the workspace's edge is a wall.
    follow_v_.setZero();
    follow_w_.setZero();
    ref_.v.setZero();
    ref_.a.setZero();
    follow_still_ = true;
    return;
  }
  const LegCoordinates leg_v = (q - ref_.q) / h;
  ref_.a = (leg_v - ref_.v) / h;
  ref_.v = leg_v;
  ref_.q = q;
  ref_T_ = next;
  follow_v_ = v;
  follow_w_ = w;
  follow_still_ = v.isZero(0.0) && w.isZero(0.0);
}

void ParallelStage::check_step_leg(int leg, int steps, double frequency_Hz) {
  require(leg >= 0 && leg < kParallelLegs, "leg", "must be 0, 1 or 2", leg);
  require(steps != 0 && std::abs(steps) <= 100000, "steps", "must be non-zero, |steps| <= 100000", steps);
  require(std::isfinite(frequency_Hz) && frequency_Hz > 0.0 && frequency_Hz <= 20000.0, "frequency_Hz",
          "must be in (0, 20000] Hz", frequency_Hz);
}

void ParallelStage::step_leg(int leg, LegPositioner positioner, int steps, double frequency_Hz) {
  check_step_leg(leg, steps, frequency_Hz);
  if (fault_) throw InvalidInput("the positioner is stopped on a fault: place it again");
  if (halted_) throw InvalidInput("the positioner is halted (emergency stop): rearm it first");
  stop();
  auto& ax = axes_[static_cast<std::size_t>(2 * leg + static_cast<int>(positioner))];
  if (ax.stepping) throw InvalidInput("leg " + std::to_string(leg) + "'s positioner is already stepping");
  ax.gen.command(p_.tracking.high_V, frequency_Hz, steps > 0 ? Direction::kForward : Direction::kBackward);
  ax.gen.start(ax.state.u_V);
  ax.steps_left = std::abs(steps);
  ax.periods_at_start = ax.gen.periods();
  ax.stepping = true;
}

void ParallelStage::hold_here(LegAxis& ax) noexcept { ax.hold = ax.measured; }

void ParallelStage::stop() noexcept {
  bool stepping = false;
  for (const auto& ax : axes_) stepping = stepping || ax.stepping;
  // Already holding: the held pose stays exactly what it is (a move planned from it still starts).
  if (!moving_ && !stepping && !following_) return;
  moving_ = following_ = follow_blocked_ = false;
  for (auto& ax : axes_) {
    if (ax.stepping)
      ax.steps_left = 0;  // ends with the present period
    else
      hold_here(ax);
  }
  ref_T_ = measured_T_;
}

void ParallelStage::safe_stop() noexcept {
  fault_ = true;
  moving_ = following_ = false;
  for (auto& ax : axes_) {
    ax.ctrl->emergency_stop();
    ax.gen.halt();
    ax.stepping = false;
  }
}

void ParallelStage::emergency_stop() noexcept {
  halted_ = true;
  moving_ = following_ = false;
  for (auto& ax : axes_) {
    ax.ctrl->emergency_stop();
    ax.gen.halt();
    ax.stepping = false;
  }
}

void ParallelStage::rearm() {
  if (fault_)
    throw InvalidInput("the positioner stopped on a fault (a diverged leg or no pose for its legs)");
  // Never ticked since place(): the legs hold the placed pose exactly (a client plans its first
  // move from it); else where their sensors read now.
  const bool placed = t_ == 0.0;
  LegCoordinates qm;
  for (std::size_t i = 0; i < axes_.size(); ++i) qm(static_cast<Eigen::Index>(i)) = axes_[i].measured;
  if (!placed) measured_T_ = kin_.forward(qm, measured_T_).T;  // throws where the legs close on no pose
  for (auto& ax : axes_) {
    ax.stepping = false;
    ax.gen.halt();
    ax.ctrl->reset(ax.measured, ax.state.u_V);
    if (!placed) hold_here(ax);
  }
  if (!placed) ref_T_ = measured_T_;
  moving_ = following_ = follow_blocked_ = halted_ = false;
  t_move_ = 0.0;
}

void ParallelStage::tick() noexcept {
  const double dt = model_.dt_s();
  // The legs' reference: the move's, once every tracker has powered up.
  bool on_move = false;
  if (moving_) {
    bool ready = true;
    for (const auto& ax : axes_) ready = ready && ax.ctrl->ready();
    if (ready) {
      on_move = true;
      if (!traj_->legs_at(kin_, t_move_, ref_)) {
        on_move = false;
        safe_stop();
      } else {
        double s = 0.0, sd = 0.0, sdd = 0.0;
        traj_->profile(t_move_, s, sd, sdd);
        ref_T_ = traj_->at(s);
        t_move_ += tick_s();
        if (t_move_ > traj_->duration_s() + tick_s()) {
          moving_ = false;
          for (std::size_t i = 0; i < axes_.size(); ++i) axes_[i].hold = ref_.q(static_cast<Eigen::Index>(i));
          ref_T_ = traj_->goal();
        }
      }
    }
  }
  if (following_) {
    bool ready = true;
    for (const auto& ax : axes_) ready = ready && ax.ctrl->ready();
    if (ready) {
      on_move = true;
      advance_follow();
    }
  }
  for (std::size_t i = 0; i < axes_.size(); ++i) {
    auto& ax = axes_[i];
    ax.measured = ax.sensor.measure(model_.slider_position(ax.state));
    if (ax.stepping) {
      // Open loop: the sawtooth runs its periods; the last one ends at 0 V, then the leg holds.
      if (ax.gen.periods() - ax.periods_at_start >= ax.steps_left - 1) ax.gen.stop_at_period_end();
      if (!ax.gen.running()) {
        ax.stepping = false;
        ax.ctrl->reset(ax.measured, ax.state.u_V);
        hold_here(ax);
      } else {
        model_.set_operating_point(ax.state, ax.gen.amplitude_V(), ax.gen.frequency_Hz(), ax.gen.direction());
        for (int k = 0; k < ratio_; ++k) model_.step(ax.state, ax.gen.next(dt));
        if (ax.state.diverged) safe_stop();
        continue;
      }
    }
    const auto ki = static_cast<Eigen::Index>(i);
    ax.ctrl->set_reference(on_move ? ReferenceSample{ref_.q(ki), ref_.v(ki), ref_.a(ki)}
                                   : ReferenceSample{ax.hold, 0.0, 0.0});
    ax.ctrl->update(ax.measured);
    const auto& op = ax.ctrl->operating_point();
    model_.set_operating_point(ax.state, op.amplitude_V, op.frequency_Hz, op.direction);
    for (int k = 0; k < ratio_; ++k) model_.step(ax.state, ax.ctrl->next_drive(dt));
    if (ax.state.diverged) safe_stop();
  }
  if (!fault_) update_poses();
  t_ += tick_s();
}

void ParallelStage::update_poses() noexcept {
  LegCoordinates qm;
  for (std::size_t i = 0; i < axes_.size(); ++i) qm(static_cast<Eigen::Index>(i)) = axes_[i].measured;
  true_stale_ = true;
  try {
    measured_T_ = kin_.forward(qm, measured_T_).T;
  } catch (...) {
    // The legs stand where no pose of the positioner is (e.g. stepped beyond a joint limit).
    safe_stop();
  }
}

const PlatformTransform& ParallelStage::true_pose() const noexcept {
  if (!true_stale_) return true_T_;
  LegCoordinates qt;
  for (std::size_t i = 0; i < axes_.size(); ++i)
    qt(static_cast<Eigen::Index>(i)) = model_.slider_position(axes_[i].state);
  try {
    true_T_ = kin_.forward(qt, true_T_).T;
  } catch (...) {
    // The sliders fit no pose (a fault follows from the sensors' FK): the last true pose stands.
  }
  true_stale_ = false;
  return true_T_;
}

bool ParallelStage::at_rest() const noexcept {
  if (moving_ || following_ || fault_ || halted_) return false;
  for (const auto& ax : axes_) {
    if (ax.stepping || !ax.ctrl->ready() || !ax.ctrl->in_position()) return false;
  }
  return true;
}

LegAxisStatus ParallelStage::status(int axis) const noexcept {
  const auto& ax = axes_[static_cast<std::size_t>(axis)];
  LegAxisStatus s;
  s.position_m = model_.slider_position(ax.state);
  s.measured_m = ax.measured;
  s.reference_m = ax.stepping ? ax.measured : (moving_ || following_ ? ref_.q(axis) : ax.hold);
  s.voltage_V = ax.state.u_V;
  s.stepping = ax.stepping;
  return s;
}

}  // namespace mc::motion
