#include "microcobot/cell/tip_levelling_step.h"

#include <cmath>

#include "microcobot/core/error.h"

namespace mc::cell {
namespace {

constexpr double kStepThere_m = 1e-6;

}  // namespace

void TipLevellingStepParams::validate() const {
  require(mode == "on" || mode == "off", "level_tips.mode", "must be on or off (got '" + mode + "')");
  require(std::isfinite(x_m) && std::abs(x_m) <= 10e-3, "level_tips.x_m", "must be within [-10, 10] mm", x_m);
  require(std::isfinite(y_m) && std::abs(y_m) <= 10e-3, "level_tips.y_m", "must be within [-10, 10] mm", y_m);
  require(std::isfinite(height_m) && height_m >= 20e-6 && height_m <= 150e-6, "level_tips.height_m",
          "must be within [20, 150] um (the procedure descends at most alignment.max_travel_m)", height_m);
  require(std::isfinite(travel_speed_m_s) && travel_speed_m_s > 0.0 && travel_speed_m_s <= 2e-3,
          "level_tips.travel_speed_m_s", "must be within (0, 2] mm/s", travel_speed_m_s);
  require(std::isfinite(z_speed_m_s) && z_speed_m_s > 0.0 && z_speed_m_s <= 1e-3, "level_tips.z_speed_m_s",
          "must be within (0, 1] mm/s", z_speed_m_s);
}

TipLevellingStep::TipLevellingStep(const TipLevellingStepParams& params, double open_m) : p_(params) {
  p_.validate();
  require(std::isfinite(open_m) && open_m > 0.0, "level_tips", "the fingers' opening must be positive",
          open_m);
  in_.active = in_.fresh = in_.deadman = true;
  in_.has_gripper = true;
  in_.gripper_opening_m = open_m;
}

bool TipLevellingStep::head_for(const Eigen::Vector3d& goal, double speed, const TaskSensors& s) noexcept {
  in_.has_goal = true;
  in_.goal_m = goal;
  in_.goal_speed_m_s = speed;
  return (s.tip_m - goal).norm() <= kStepThere_m;
}

void TipLevellingStep::fail(platform::Platform& p, const char* why) noexcept {
  phase_ = Phase::kFailed;
  failure_ = why;
  in_.deadman = false;
  in_.has_goal = false;
  p.set_console_input(in_);
  p.hold();
}

void TipLevellingStep::tick(platform::Platform& p, const TaskSensors& s) noexcept {
  if (!started_) {
    start_ = s.tip_m;
    started_ = true;
  }
  switch (phase_) {
    case Phase::kOver:
      if (head_for({p_.x_m, p_.y_m, start_.z()}, p_.travel_speed_m_s, s)) phase_ = Phase::kDown;
      break;
    case Phase::kDown:
      if (head_for({p_.x_m, p_.y_m, p_.height_m}, p_.z_speed_m_s, s)) {
        in_.has_goal = false;  // the procedure moves Z; the input holds its deadman
        p.set_console_input(in_);
        if (!p.start_tip_levelling()) return fail(p, p.tip_levelling().failure);
        phase_ = Phase::kLevel;
        return;
      }
      break;
    case Phase::kLevel:
      if (p.tip_levelling_running()) break;
      if (p.tip_levelling().state != platform::TipLevellingStatus::State::kDone)
        return fail(p, p.tip_levelling().failure);
      phase_ = Phase::kBack;
      [[fallthrough]];
    case Phase::kBack:
      // Straight up first, then over: the patch is clear, the way back at the start's height too.
      if (s.tip_m.z() < start_.z() - kStepThere_m &&
          (s.tip_m.head<2>() - start_.head<2>()).norm() > kStepThere_m) {
        head_for({s.tip_m.x(), s.tip_m.y(), start_.z()}, p_.z_speed_m_s, s);
      } else if (head_for(start_, p_.travel_speed_m_s, s)) {
        phase_ = Phase::kDone;
      }
      break;
    case Phase::kDone:
    case Phase::kFailed:
      return;
  }
  p.set_console_input(in_);
}

}  // namespace mc::cell
