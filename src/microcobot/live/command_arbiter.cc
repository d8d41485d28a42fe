#include "microcobot/live/command_arbiter.h"

#include "microcobot/core/error.h"

namespace mc::live {

teleop::ConsoleInput coupling_input(const ConsoleCommand& c, bool fresh, double theta_speed_rad_s) noexcept {
  teleop::ConsoleInput in;
  in.active = true;
  in.fresh = fresh;
  in.deadman = c.deadman;
  in.velocity_m_s = {c.velocity_m_s[0], c.velocity_m_s[1], c.velocity_m_s[2]};
  in.has_goal = c.has_goal;
  in.goal_m = {c.goal_m[0], c.goal_m[1], c.goal_m[2]};
  in.goal_speed_m_s = c.goal_speed_m_s;
  in.has_gripper = c.has_gripper;
  in.gripper_opening_m = c.gripper_opening_m;
  in.gripper_shake = c.gripper_shake;
  in.has_theta_goal = c.has_theta_goal;
  in.theta_goal_rad = c.theta_goal_rad;
  in.theta_speed_rad_s = theta_speed_rad_s;
  in.theta_rate_rad_s = c.theta_rate_rad_s;
  return in;
}

void CommandArbiter::add(CommandSource& source) {
  require(count_ < kMaxSources, "command sources",
          "at most " + std::to_string(kMaxSources) + " (adding '" + std::string(source.name()) + "')");
  sources_[count_++] = &source;
}

CommandArbiter::Decision CommandArbiter::tick(const SourceTick& t, teleop::ConsoleInput& in) noexcept {
  Decision d;
  int active = -1, standby = -1;
  for (std::size_t i = 0; i < count_; ++i) {
    const SourceRequest r = sources_[i]->poll(t);
    const int index = static_cast<int>(i);
    if (r.estop && !t.platform.faulted()) {
      t.platform.fault_all();  // at once: every device to its safe state
      estop_by_ = index;
    }
    if (r.reset && estop_by_ == index && t.platform.faulted()) {
      d.reset = true;
      estop_by_ = -1;
    }
    if (r.claim == Claim::kActive && active < 0) active = index;
    if (r.claim == Claim::kStandby && standby < 0) standby = index;
  }
  const int next = active >= 0 ? active : standby;
  const int previous = holder_.load(std::memory_order_relaxed);
  if (next != previous) {
    // The new holder starts from rest: every axis holds where it is, the old goal forgotten.
    t.platform.hold();
    if (previous >= 0) sources_[static_cast<std::size_t>(previous)]->released(t);
    holder_.store(next, std::memory_order_relaxed);
    handovers_.fetch_add(1, std::memory_order_relaxed);
  }
  if (next >= 0) sources_[static_cast<std::size_t>(next)]->drive(t, in);
  return d;
}

void CommandArbiter::publish(const SourceTick& t) noexcept {
  for (std::size_t i = 0; i < count_; ++i) sources_[i]->publish(t);
}

void CommandArbiter::reset() noexcept {
  holder_.store(-1, std::memory_order_relaxed);
  estop_by_ = -1;
  for (std::size_t i = 0; i < count_; ++i) sources_[i]->reset();
}

std::string_view CommandArbiter::holder_name() const noexcept {
  const int h = holder();
  return h >= 0 ? sources_[static_cast<std::size_t>(h)]->name() : std::string_view();
}

}  // namespace mc::live
