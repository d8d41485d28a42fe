#include "microcobot/cell/assembly_task.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "microcobot/core/error.h"
#include "microcobot/microworld/pick_place_world.h"

namespace mc::cell {

void AssemblyTaskParams::validate() const {
  require_positive(travel_speed_m_s, "travel_speed_m_s");
  require_positive(z_speed_m_s, "z_speed_m_s");
  require_positive(insert_speed_m_s, "insert_speed_m_s");
  require_positive(clearance_height_m, "clearance_height_m");
  require_positive(grip_above_m, "grip_above_m");
  require_positive(grip_force_N, "grip_force_N");
  require_positive(close_rate_m_s, "close_rate_m_s");
  require_positive(contact_threshold_N, "contact_threshold_N");
  require_positive(search_retreat_m, "search_retreat_m");
  // Steps of at most twice the clearance leave no gap between the fits (|dy| <= clearance).
  require(search_step_factor > 0.0 && search_step_factor < 2.0, "search_step_factor",
          "must be within (0, 2): the fits of |dy| <= clearance must overlap", search_step_factor);
  require_non_negative(search_range_m, "search_range_m");
  require_positive(position_tolerance_m, "position_tolerance_m");
  require_non_negative(settle_s, "settle_s");
  require_positive(step_timeout_s, "step_timeout_s");
  require_positive(verify_tolerance_m, "verify_tolerance_m");
  require(std::isfinite(rotate_speed_rad_s) && rotate_speed_rad_s > 0.0 && rotate_speed_rad_s <= 10.0,
          "rotate_speed_rad_s", "must be within (0, 10] rad/s", rotate_speed_rad_s);
  require(std::isfinite(yaw_tolerance_rad) && yaw_tolerance_rad > 0.0 && yaw_tolerance_rad <= 0.1,
          "yaw_tolerance_rad", "must be within (0, 0.1] rad", yaw_tolerance_rad);
  require(std::isfinite(shake_s) && shake_s > 0.0 && shake_s <= 5.0, "shake_s", "must be within (0, 5] s",
          shake_s);
  require(std::isfinite(roll_rad) && roll_rad > 0.0 && roll_rad <= 0.5, "roll_rad",
          "must be within (0, 0.5] rad", roll_rad);
  require(align_max_looks >= 1 && align_max_looks <= 20, "align_max_looks", "must be within [1, 20]",
          align_max_looks);
}

double AssemblyTask::grasp_height_m(const AssemblyTaskParams& p, const AssemblyGoal& goal) noexcept {
  return goal.flat_seat ? 0.5 * goal.part_height_m : goal.hole_depth_m + p.grip_above_m;
}

double square_yaw_goal(double square_yaw_rad, double from_rad, double min_rad, double max_rad) noexcept {
  const double quarter = 0.5 * M_PI;
  const double nearest = from_rad + microworld::wrap_quarter_turn(square_yaw_rad - from_rad);
  double best = std::clamp(nearest, min_rad, max_rad);
  double best_turn = std::numeric_limits<double>::infinity();
  for (int k = -4; k <= 4; ++k) {
    const double c = nearest + k * quarter;
    if (c >= min_rad && c <= max_rad && std::abs(c - from_rad) < best_turn) {
      best = c;
      best_turn = std::abs(c - from_rad);
    }
  }
  return best;
}

AssemblyTask::AssemblyTask(const AssemblyTaskParams& params, const AssemblyGoal& goal)
    : p_(params), goal_(goal) {
  p_.validate();
  require(goal.part_m.allFinite() && goal.target_m.allFinite(), "goal", "positions must be finite");
  require_positive(goal.part_height_m, "goal.part_height_m");
  if (goal.flat_seat) {
    require(goal.hole_depth_m == 0.0, "goal.hole_depth_m", "must be 0 on a flat seat", goal.hole_depth_m);
  } else {
    require_positive(goal.hole_depth_m, "goal.hole_depth_m");
  }
  require_positive(goal.clearance_m, "goal.clearance_m");
  require_positive(goal.open_m, "goal.open_m");
  require(std::isfinite(goal.part_yaw_rad) && std::isfinite(goal.target_yaw_rad), "goal",
          "orientations must be finite");
  require(std::isfinite(goal.tallest_neighbour_m) && goal.tallest_neighbour_m >= 0.0,
          "goal.tallest_neighbour_m", "must be finite and non-negative", goal.tallest_neighbour_m);
  require(goal.yaw_min_rad < goal.yaw_max_rad, "goal.yaw_min_rad", "must be below goal.yaw_max_rad",
          goal.yaw_min_rad);
  grasp_z_ = grasp_height_m(p_, goal);
  rim_z_ = surface_z_ = grasp_z_;
  require(grasp_z_ < goal.part_height_m, "grip_above_m", "must grasp below the pin's top (part_height_m)",
          p_.grip_above_m);
  safe_z_ = std::max(goal.part_height_m, goal.tallest_neighbour_m) + p_.clearance_height_m;
  carry_z_ = grasp_z_ + goal.tallest_neighbour_m + p_.clearance_height_m;
  opening_command_ = goal.open_m;
  out_.active = true;
  out_.fresh = true;
  out_.has_gripper = true;
  out_.gripper_opening_m = opening_command_;
  enter(Step::kApproach);
}

void AssemblyTask::enter(Step s) noexcept {
  step_ = s;
  assist_yaw_ = std::numeric_limits<double>::quiet_NaN();
  assist_from_known_ = false;
  step_s_ = 0.0;
  settled_s_ = 0.0;
  search_.set_phase(InsertionSearch::Phase::kDescend);
  release_ = Release::kOpen;
  release_s_ = 0.0;
  out_.gripper_shake = false;
  if (s == Step::kInsert) {      // a fresh search, however the insertion was reached
    search_.restart(last_yaw_);  // along the fingers as they are
    looks_.new_insertion();
  }
  supervisor_.begin(s);
}

void AssemblyTask::hand_back(bool step_done) noexcept {
  if (!operator_drives()) return;
  if (step_done) {
    enter(next_step(step_));
    return;
  }
  // The step again, from where the operator left the stage: its goals are absolute, and a move
  // starts from the coupling's current target; a turn, from where the operator left it.
  yaw_goal_ = std::numeric_limits<double>::quiet_NaN();
  step_s_ = 0.0;
  settled_s_ = 0.0;
  assist_from_known_ = false;
  if (step_ == Step::kInsert) search_.retreat_from_tip();  // clear of the rim before searching on
  supervisor_.run();
}

void AssemblyTask::set_autonomy(Step step, Autonomy a) noexcept {
  if (step == Step::kDone) return;
  supervisor_.set_autonomy(step, a);
  const Status st = status();
  const bool fresh =
      step_s_ == 0.0 && (st == Status::kRunning || st == Status::kAwaitingConfirm || operator_drives());
  if (step == step_ && fresh) supervisor_.begin(step_);
}

void AssemblyTask::skip() noexcept {
  if (finished()) return;
  const bool paused = status() == Status::kPaused;
  yaw_goal_ = std::numeric_limits<double>::quiet_NaN();  // the fingers stay as they are
  enter(next_step(step_));
  if (paused) supervisor_.pause();  // a running next step stays paused; another level holds anyway
}

bool AssemblyTask::move_to(const Eigen::Vector3d& goal, double speed, const TaskSensors& s,
                           double dt) noexcept {
  out_.has_goal = true;
  out_.goal_m = goal;
  out_.goal_speed_m_s = speed;
  settled_s_ = (s.tip_m - goal).norm() <= p_.position_tolerance_m ? settled_s_ + dt : 0.0;
  return settled_s_ >= p_.settle_s;
}

void AssemblyTask::turn_to(double yaw) noexcept {
  yaw_goal_ = yaw;
  out_.has_theta_goal = true;
  out_.theta_goal_rad = yaw;
  out_.theta_speed_rad_s = p_.rotate_speed_rad_s;
}

double AssemblyTask::align_yaw(double from) const noexcept {
  return square_yaw_goal(goal_.part_yaw_rad, from, goal_.yaw_min_rad, goal_.yaw_max_rad);
}

double AssemblyTask::rotate_yaw(double from) const noexcept {
  return square_yaw_goal(goal_.target_yaw_rad, from, goal_.yaw_min_rad, goal_.yaw_max_rad);
}

Eigen::Vector3d AssemblyTask::move_goal(Step s, const Eigen::Vector3d& tip) const noexcept {
  switch (s) {
    case Step::kApproach:
      return {goal_.part_m.x(), goal_.part_m.y(), safe_z_};
    case Step::kDescend:
      return {goal_.part_m.x(), goal_.part_m.y(), grasp_z_};
    case Step::kLift:
      return {goal_.part_m.x(), goal_.part_m.y(), carry_z_};
    case Step::kTransport:
      return {goal_.target_m.x(), goal_.target_m.y(), carry_z_};
    case Step::kRetract:
      return {search_xy().x(), search_xy().y(), safe_z_};
    default:
      return tip;
  }
}

void AssemblyTask::assisted_tick(const TaskSensors& s, double dt) noexcept {
  // The operator's master drives (the deadman and the gripper are theirs); the task holds the
  // fixtures on the step's goal and the neighbours' keep-outs, and watches. No step timeout: the
  // person sets the pace.
  fixtures_.level = 1.0;
  fixtures_.keep_outs = goal_.keep_outs;
  fixtures_.keep_out_count = goal_.keep_out_count;
  fixtures_.guide = true;
  bool there = false;
  switch (step_) {
    case Step::kGrasp:  // held over the pin at the grasp height while the operator closes
      fixtures_.guide_xy_m = goal_.part_m;
      fixtures_.height = true;
      fixtures_.height_z_m = grasp_z_;
      there = s.grip_N >= p_.grip_force_N;
      break;
    case Step::kInsert:  // down the funnel, on the bore's axis; the platform's limits on the force
      fixtures_.guide_xy_m = search_xy();
      fixtures_.funnel = true;
      fixtures_.rim_z_m = rim_z_;
      fixtures_.funnel_radius_m = 0.5 * goal_.clearance_m;
      // Judged at the first contact, as the robot's descent is (a pin pressed on goes on sliding
      // in the fingers, so a later contact says nothing of its depth): down in the bore, the
      // release; on the rim, the robot's search takes the insertion over from here.
      if (s.contact_N.z() > p_.contact_threshold_N) {
        search_.record_contact(s.tip_m.z());
        fixtures_ = {};
        if (s.tip_m.z() < rim_z_ - 0.5 * goal_.hole_depth_m) {
          enter(Step::kRelease);
        } else {
          search_.count_try();
          search_.retreat_from_tip();
          supervisor_.run();
        }
        return;
      }
      break;
    case Step::kRelease:  // on the axis while the operator opens
      fixtures_.guide_xy_m = search_xy();
      there = s.opening_m >= 0.9 * goal_.open_m;
      break;
    case Step::kAlign:  // held over the pin (or the bore) while the operator turns into the yaw stop
    case Step::kRotate: {
      const bool align = step_ == Step::kAlign;
      if (!std::isfinite(assist_yaw_)) assist_yaw_ = align ? align_yaw(s.yaw_rad) : rotate_yaw(s.yaw_rad);
      fixtures_.guide_xy_m = align ? goal_.part_m : goal_.target_m;
      fixtures_.height = true;
      fixtures_.height_z_m = align ? safe_z_ : carry_z_;
      fixtures_.yaw = true;
      fixtures_.yaw_rad = assist_yaw_;
      there = std::abs(s.yaw_rad - assist_yaw_) <= p_.yaw_tolerance_rad;
      break;
    }
    default: {
      const Eigen::Vector3d goal = move_goal(step_, s.tip_m);
      fixtures_.guide_xy_m = goal.head<2>();
      if (step_ == Step::kApproach || step_ == Step::kTransport) {
        // Across the plate: guidance along the path from where the step began to its goal.
        if (!assist_from_known_) assist_from_ = s.tip_m.head<2>();
        assist_from_known_ = true;
        fixtures_.path = true;
        fixtures_.path_from_xy_m = assist_from_;
      }
      fixtures_.height = true;
      fixtures_.height_z_m = goal.z();
      there = (s.tip_m - goal).norm() <= p_.position_tolerance_m;
      break;
    }
  }
  step_s_ += dt;
  settled_s_ = there ? settled_s_ + dt : 0.0;
  if (settled_s_ < p_.settle_s) return;
  if (step_ == Step::kGrasp) rim_z_ = s.tip_m.z();
  fixtures_ = {};
  enter(next_step(step_));
}

const teleop::ConsoleInput& AssemblyTask::tick(const TaskSensors& s, double dt_s) noexcept {
  out_.deadman = false;
  out_.has_goal = false;
  last_yaw_ = s.yaw_rad;
  last_tip_ = s.tip_m;
  // The rotary axis holds its last goal (none yet: it stays where it is).
  out_.has_theta_goal = std::isfinite(yaw_goal_);
  out_.theta_goal_rad = std::isfinite(yaw_goal_) ? yaw_goal_ : 0.0;
  out_.theta_rate_rad_s = 0.0;
  out_.velocity_m_s.setZero();
  // While the operator drives, the gripper is theirs: the task follows its command, to take the
  // stage back without opening or closing the fingers.
  if (operator_drives() && std::isfinite(s.gripper_command_m)) opening_command_ = s.gripper_command_m;
  out_.gripper_opening_m = opening_command_;
  fixtures_ = {};
  if (status() == Status::kAssisted) {
    // The slot or the bore seen before the guide is set.
    if (const Look l = look_before_moving(); l != Look::kNone) {
      looks_.await(l);
      supervisor_.await_look();
      return out_;
    }
    assisted_tick(s, dt_s);
    return out_;
  }
  if (status() != Status::kRunning) return out_;  // holding: paused, awaiting, operator, finished
  // The camera's looks before the approach, the transport and the insertion (verify's is its own):
  // holding.
  if (const Look l = look_before_moving(); l != Look::kNone) {
    looks_.await(l);
    supervisor_.await_look();
    return out_;
  }
  step_s_ += dt_s;
  if (step_s_ > p_.step_timeout_s) {
    fail("a step took longer than step_timeout_s");
    return out_;
  }
  out_.deadman = true;
  const Eigen::Vector3d over_part(goal_.part_m.x(), goal_.part_m.y(), safe_z_);
  switch (step_) {
    case Step::kApproach:
      // Up first where the tips are, then across: the open fingers never sweep into the pin.
      if (s.tip_m.z() < safe_z_ - p_.position_tolerance_m &&
          (s.tip_m.head<2>() - goal_.part_m).norm() > 1e-6) {
        move_to({s.tip_m.x(), s.tip_m.y(), safe_z_}, p_.z_speed_m_s, s, dt_s);
        settled_s_ = 0.0;
      } else {
        // Clear of the pins: the fingers turn on the way when align is the robot's.
        if (autonomy(Step::kAlign) == Autonomy::kAuto)
          turn_to(align_yaw(std::isfinite(yaw_goal_) ? yaw_goal_ : s.yaw_rad));
        if (move_to(over_part, p_.travel_speed_m_s, s, dt_s)) enter(Step::kAlign);
      }
      break;
    case Step::kAlign:
      turn_to(align_yaw(std::isfinite(yaw_goal_) ? yaw_goal_ : s.yaw_rad));
      move_to(over_part, p_.travel_speed_m_s, s, dt_s);
      if (std::abs(s.yaw_rad - yaw_goal_) > p_.yaw_tolerance_rad) settled_s_ = 0.0;
      if (settled_s_ >= p_.settle_s) enter(Step::kDescend);
      break;
    case Step::kDescend:
      if (move_to({goal_.part_m.x(), goal_.part_m.y(), grasp_z_}, p_.z_speed_m_s, s, dt_s))
        enter(Step::kGrasp);
      break;
    case Step::kGrasp: {
      move_to({goal_.part_m.x(), goal_.part_m.y(), grasp_z_}, p_.z_speed_m_s, s, dt_s);
      if (s.grip_N < p_.grip_force_N) {
        settled_s_ = 0.0;
        opening_command_ = std::max(0.0, opening_command_ - p_.close_rate_m_s * dt_s);
        if (opening_command_ <= 0.0 && s.grip_N <= 0.0) fail("the fingers closed on nothing");
      } else if (settled_s_ >= p_.settle_s) {
        rim_z_ = s.tip_m.z();  // the pin stood on the surface: its bottom this far below the tips
        enter(Step::kLift);
      }
      out_.gripper_opening_m = opening_command_;
      break;
    }
    case Step::kLift:
      if (move_to({goal_.part_m.x(), goal_.part_m.y(), carry_z_}, p_.z_speed_m_s, s, dt_s))
        enter(Step::kTransport);
      break;
    case Step::kTransport:
      if (autonomy(Step::kRotate) == Autonomy::kAuto)
        turn_to(rotate_yaw(std::isfinite(yaw_goal_) ? yaw_goal_ : s.yaw_rad));
      if (move_to({goal_.target_m.x(), goal_.target_m.y(), carry_z_}, p_.travel_speed_m_s, s, dt_s))
        enter(Step::kRotate);
      break;
    case Step::kRotate:
      turn_to(rotate_yaw(std::isfinite(yaw_goal_) ? yaw_goal_ : s.yaw_rad));
      move_to({goal_.target_m.x(), goal_.target_m.y(), carry_z_}, p_.travel_speed_m_s, s, dt_s);
      if (std::abs(s.yaw_rad - yaw_goal_) > p_.yaw_tolerance_rad) settled_s_ = 0.0;
      if (settled_s_ >= p_.settle_s) enter(Step::kInsert);
      break;
    case Step::kInsert:
      insert_tick(s, dt_s);
      break;
    case Step::kRelease:
      release_tick(s, dt_s);
      break;
    case Step::kRetract:
      if (move_to({search_xy().x(), search_xy().y(), safe_z_}, p_.z_speed_m_s, s, dt_s)) enter(Step::kVerify);
      break;
    case Step::kVerify:
      verify_tick(s, dt_s);
      break;
    case Step::kDone:
      break;
  }
  return out_;
}

}  // namespace mc::cell
