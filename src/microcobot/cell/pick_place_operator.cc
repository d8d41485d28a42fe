#include "microcobot/cell/pick_place_operator.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "microcobot/core/error.h"

namespace mc::cell {

void PickPlaceOperatorParams::validate() const {
  require_positive(transport_speed_m_s, "transport_speed_m_s");
  require_positive(approach_speed_m_s, "approach_speed_m_s");
  require_positive(fine_speed_m_s, "fine_speed_m_s");
  require_non_negative(fine_distance_m, "fine_distance_m");
  require_positive(visual_gain_1_s, "visual_gain_1_s");
  require_positive(resolution_m, "resolution_m");
  require_positive(jog_speed_m_s, "jog_speed_m_s");
  require_positive(grasp_z_m, "grasp_z_m");
  require(carry_z_m > grasp_z_m, "carry_z_m", "must be above grasp_z_m", carry_z_m);
  require_non_negative(set_down_press_m, "set_down_press_m");
  require(set_down_press_m < grasp_z_m, "set_down_press_m", "must be below grasp_z_m", set_down_press_m);
  require(retract_z_m > grasp_z_m, "retract_z_m", "must be above grasp_z_m", retract_z_m);
  require_positive(pinch_m, "pinch_m");
  require_positive(pinch_s, "pinch_s");
  require(max_pinch_m >= pinch_m, "max_pinch_m", "must be at least pinch_m", max_pinch_m);
  require_positive(felt_grip_N, "felt_grip_N");
  require_positive(hand_limit_m, "hand_limit_m");
  require_positive(hand_return_speed_m_s, "hand_return_speed_m_s");
  require_positive(phase_timeout_s, "phase_timeout_s");
}

std::string_view PickPlaceOperator::name(Phase p) {
  switch (p) {
    case Phase::kApproach:
      return "approach";
    case Phase::kDescend:
      return "descend";
    case Phase::kPinch:
      return "pinch";
    case Phase::kLift:
      return "lift";
    case Phase::kTransport:
      return "transport";
    case Phase::kSetDown:
      return "set_down";
    case Phase::kRelease:
      return "release";
    case Phase::kRetract:
      return "retract";
    case Phase::kDone:
      return "done";
    case Phase::kGaveUp:
      return "gave_up";
  }
  return "?";
}

std::string_view PickPlaceOperator::give_up_reason(Phase p) {
  switch (p) {
    case Phase::kApproach:
      return "the open gripper never settled over the part";
    case Phase::kDescend:
      return "the finger tips never reached the grasp height";
    case Phase::kPinch:
      return "the grip was never felt: the fingers did not close on the part";
    case Phase::kLift:
      return "the part could not be lifted to the carrying height";
    case Phase::kTransport:
      return "the part never settled over its target";
    case Phase::kSetDown:
      return "the part could not be set down";
    case Phase::kRelease:
      return "the fingers did not open to release the part";
    case Phase::kRetract:
      return "the gripper could not be raised clear of the part";
    case Phase::kDone:
    case Phase::kGaveUp:
      break;
  }
  return "";
}

PickPlaceOperator::PickPlaceOperator(platform::Platform& platform, const PickPlaceOperatorParams& params)
    : platform_(platform),
      sim_(platform.simulation()),
      p_(params),
      motion_scale_(platform.config().teleop.motion_scale) {
  p_.validate();
  require(sim_.gripper != nullptr, "microworld", "the scripted pick-and-place needs the pick-place scene");
  require(sim_.haptic != nullptr, "devices.haptic",
          "the scripted operator moves a simulated haptic master's hand");
  lift_m_ = sim_.gripper->world().params().hole_depth_m;
  std::fill(std::begin(started_), std::end(started_), std::numeric_limits<double>::quiet_NaN());
  started_[0] = 0.0;
}

void PickPlaceOperator::let_go() noexcept {
  hand_.deadman = false;
  hand_.clutch = false;
  hand_.jog_m_s = 0.0;
  clutching_ = false;
  sim_.haptic->set_operator(hand_);
}

void PickPlaceOperator::enter(Phase p, double t) noexcept {
  phase_ = p;
  phase_t0_ = t;
  settled_s_ = 0.0;
  started_[static_cast<int>(p)] = t;
}

double PickPlaceOperator::jog_to(double z_seen, double z_goal) const noexcept {
  return std::clamp(10.0 * (z_goal - z_seen), -p_.jog_speed_m_s, p_.jog_speed_m_s);
}

bool PickPlaceOperator::steer(const Eigen::Vector2d& seen, const Eigen::Vector2d& goal, double speed,
                              double dt) noexcept {
  const Eigen::Vector2d e = goal - seen;
  Eigen::Vector2d hand(hand_.hand_m.x, hand_.hand_m.y);
  if (clutching_) {
    // Clutch pressed: the slave holds while the hand goes back across the workspace.
    const Eigen::Vector2d d = clutch_aim_ - hand;
    const double step = p_.hand_return_speed_m_s * dt;
    if (d.norm() <= step) {
      hand = clutch_aim_;
      clutching_ = false;
      hand_.clutch = false;
    } else {
      hand += d * (step / d.norm());
    }
  } else {
    const double limit = e.norm() < p_.fine_distance_m ? std::min(speed, p_.fine_speed_m_s) : speed;
    Eigen::Vector2d v = p_.visual_gain_1_s * e;
    if (v.norm() > limit) v *= limit / v.norm();
    const Eigen::Vector2d next = hand + v / motion_scale_ * dt;
    if (next.cwiseAbs().maxCoeff() > p_.hand_limit_m) {
      clutching_ = true;
      hand_.clutch = true;
      ++clutches_;
      clutch_aim_ = hand;
      for (int i = 0; i < 2; ++i) {
        if (std::abs(next[i]) > p_.hand_limit_m)
          clutch_aim_[i] = -std::copysign(0.6 * p_.hand_limit_m, next[i]);
      }
    } else {
      hand = next;
    }
  }
  hand_.hand_m = {hand.x(), hand.y()};
  return !clutching_ && e.norm() < p_.resolution_m;
}

void PickPlaceOperator::act(const runtime::TickInfo& tick) noexcept {
  const double t = tick.t_s, dt = tick.dt_s;
  if (phase_ == Phase::kDone || phase_ == Phase::kGaveUp) return;
  if (t - phase_t0_ > p_.phase_timeout_s) {
    failed_phase_ = phase_;
    enter(Phase::kGaveUp, t);
    let_go();
    return;
  }
  const devices::SimulatedGripper& g = *sim_.gripper;
  const Eigen::Vector3d tip = g.tip_position_m();
  const Eigen::Vector3d part = g.world_state().part_m;
  const Eigen::Vector2d target = g.world().params().target_m.head<2>();
  hand_.deadman = true;
  hand_.jog_m_s = 0.0;
  // "Reached" means seen within the resolution for a moment (the slave still rings after a move).
  auto settle = [&](bool within) {
    settled_s_ = within ? settled_s_ + dt : 0.0;
    return settled_s_ >= 0.1;
  };

  switch (phase_) {
    case Phase::kApproach:
      if (settle(steer(tip.head<2>(), part.head<2>(), p_.approach_speed_m_s, dt))) enter(Phase::kDescend, t);
      break;
    case Phase::kDescend:
      hand_.jog_m_s = jog_to(tip.z(), p_.grasp_z_m + lift_m_);
      if (settle(std::abs(tip.z() - (p_.grasp_z_m + lift_m_)) < p_.resolution_m)) enter(Phase::kPinch, t);
      break;
    case Phase::kPinch: {
      // Closing until the grip is felt, as a person does: how far depends on the part's width.
      const bool felt = platform_.teleop().finger_force_N >= p_.felt_grip_N;
      if (!felt) pinch_ = std::min(p_.max_pinch_m, pinch_ + p_.pinch_m * dt / p_.pinch_s);
      if (settle(felt)) enter(Phase::kLift, t);
      break;
    }
    case Phase::kLift:
      hand_.jog_m_s = jog_to(tip.z(), p_.carry_z_m + lift_m_);
      if (settle(std::abs(tip.z() - (p_.carry_z_m + lift_m_)) < p_.resolution_m)) enter(Phase::kTransport, t);
      break;
    case Phase::kTransport:
      if (settle(steer(part.head<2>(), target, p_.transport_speed_m_s, dt))) enter(Phase::kSetDown, t);
      break;
    case Phase::kSetDown:
      hand_.jog_m_s = jog_to(tip.z(), p_.grasp_z_m - p_.set_down_press_m);
      if (settle(std::abs(tip.z() - (p_.grasp_z_m - p_.set_down_press_m)) < p_.resolution_m))
        enter(Phase::kRelease, t);
      break;
    case Phase::kRelease:
      pinch_ = std::max(0.0, pinch_ - p_.pinch_m * dt / p_.pinch_s);  // released as fast
      if (settle(pinch_ == 0.0 && g.opening_m() > 0.9 * g.world().params().gripper.max_opening_m)) {
        enter(Phase::kRetract, t);
      }
      break;
    case Phase::kRetract:
      hand_.jog_m_s = jog_to(tip.z(), p_.retract_z_m + lift_m_);
      if (settle(std::abs(tip.z() - (p_.retract_z_m + lift_m_)) < p_.resolution_m)) {
        enter(Phase::kDone, t);
        let_go();
        return;
      }
      break;
    case Phase::kDone:
    case Phase::kGaveUp:
      break;
  }
  sim_.haptic->set_operator(hand_);
  sim_.tweezers->set_operator_closing(pinch_);
}

}  // namespace mc::cell
