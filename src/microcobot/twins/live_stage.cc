#include "microcobot/twins/live_stage.h"

#include <algorithm>
#include <cmath>

#include "microcobot/platform/platform_config.h"

namespace mc::twins {

LiveStage::LiveStage(live::LivePlatform& live) : live_(live) {
  const auto& l = live.limits();
  const double home[3] = {live.params().platform.stage.home_x_m, live.params().platform.stage.home_y_m,
                          live.params().platform.stage.home_z_m};
  for (std::size_t i = 0; i < 3; ++i) {
    min_[i] = l.min_m[i] - home[i];
    max_[i] = l.max_m[i] - home[i];
  }
  max_speed_m_s_ = l.max_speed_m_s;
  // The rotary axis: the console's travel and speed (both 0 without the axis), its angle from its
  // home (the console's is the gripper's yaw: home_rad + that angle), as the stage's from its home.
  if (l.max_theta_speed_rad_s > 0.0) {
    axis_count_ = 4;
    home_rad_ = live.params().platform.stage.rotary.home_rad;
    min_[kTheta] = l.min_theta_rad - home_rad_;
    max_[kTheta] = l.max_theta_rad - home_rad_;
    max_theta_speed_rad_s_ = l.max_theta_speed_rad_s;
  }
  max_voltage_V_ = platform::axis_params(live.params().platform).drive.max_V;
  if (live.params().platform.parallel_positioner_enabled())
    kinematics_.emplace(live.params().platform.parallel_positioner.geometry);
}

TwinStage::Axis LiveStage::axis(int i) const {
  const live::ProtocolView v = live_.protocol_view();
  const auto k = static_cast<std::size_t>(i);
  Axis a;
  a.position = k == kTheta ? v.position[k] - home_rad_ : v.position[k];
  // Until the loop applied the last command, what it published is about the one before.
  a.on_target = v.on_target[k] && v.applied_seq >= move_seq_ && v.applied_seq >= step_seq_[k];
  a.stepping = v.stepping[k] || v.applied_seq < step_seq_[k];
  return a;
}

bool LiveStage::halted() const { return live_.status().estopped; }

bool LiveStage::controls(ClientId client) const {
  return client != 0 && owner_ == client && !live_.console_in_control();
}

TwinStage::Refusal LiveStage::claim(ClientId client) {
  if (halted()) {
    release(owner_);  // control is taken again after the reset, by a new motion command
    return Refusal::kHalted;
  }
  if (live_.console_in_control()) {
    owner_ = 0;  // the console took control: the loop holds the stage
    return Refusal::kOtherOperator;
  }
  if (live_.params().remote != nullptr) return Refusal::kOtherOperator;  // a slave: its master drives
  if (owner_ != 0 && owner_ != client) return Refusal::kOtherOperator;
  owner_ = client;
  return Refusal::kNone;
}

bool LiveStage::push(live::ProtocolCommand c) {
  c.seq = ++seq_;
  return live_.push_protocol_command(c);
}

TwinStage::Refusal LiveStage::move_to(ClientId client, const Goal& goal, double speed_m_s,
                                      double theta_speed_rad_s) {
  if (const Refusal r = claim(client); r != Refusal::kNone) return r;
  auto clamped = [&](std::size_t i) {
    return std::clamp(std::isfinite(goal[i]) ? goal[i] : 0.0, min_[i], max_[i]);
  };
  auto speed = [](double v, double cap) { return std::isfinite(v) ? std::clamp(v, 0.0, cap) : 0.0; };
  live::ProtocolCommand c;
  c.kind = live::ProtocolCommand::Kind::kMoveTo;
  for (std::size_t i = 0; i < 3; ++i) c.goal_m[i] = clamped(i);
  c.speed_m_s = speed(speed_m_s, max_speed_m_s_);
  if (axis_count_ > kTheta) {
    c.theta_goal_rad = home_rad_ + clamped(kTheta);
    c.theta_speed_rad_s = speed(theta_speed_rad_s, max_theta_speed_rad_s_);
  }
  if (!push(c)) return Refusal::kBusy;
  move_seq_ = seq_;
  return Refusal::kNone;
}

TwinStage::Refusal LiveStage::step(ClientId client, int i, double amplitude_V, double frequency_Hz,
                                   int direction, std::int64_t periods) {
  if (const Refusal r = claim(client); r != Refusal::kNone) return r;
  live::ProtocolCommand c;
  c.kind = live::ProtocolCommand::Kind::kSteps;
  c.axis = std::clamp(i, 0, axis_count_ - 1);
  c.amplitude_V = amplitude_V;  // range-checked again by the platform
  c.frequency_Hz = frequency_Hz;
  c.direction = direction < 0 ? -1 : 1;
  c.periods = periods;
  if (!push(c)) return Refusal::kBusy;
  step_seq_[static_cast<std::size_t>(c.axis)] = seq_;
  move_seq_ = seq_;  // the stage leaves its goal
  return Refusal::kNone;
}

TwinStage::Refusal LiveStage::move_pose(ClientId client, const motion::PoseTrajectory& traj,
                                        std::uint64_t& seq, std::string& reason) {
  if (!kinematics_) {
    reason = "the platform has no parallel positioner (positioner: parallel)";
    return Refusal::kUnreachable;
  }
  // Checked here, on the protocol thread, whatever the twin checked: no unchecked move reaches
  // the loop, which only starts it.
  const motion::MoveCheck c = motion::check_move(*kinematics_, traj);
  if (!c.ok) {
    reason = c.reason;
    return Refusal::kUnreachable;
  }
  if (const Refusal r = claim(client); r != Refusal::kNone) return r;
  live::ProtocolCommand cmd;
  cmd.kind = live::ProtocolCommand::Kind::kPoseMove;
  cmd.pose = traj;
  if (!push(cmd)) return Refusal::kBusy;
  seq = seq_;
  return Refusal::kNone;
}

TwinStage::Refusal LiveStage::stop_pose(ClientId client, std::uint64_t& seq) {
  if (!controls(client) || halted()) return Refusal::kOtherOperator;
  live::ProtocolCommand c;
  c.kind = live::ProtocolCommand::Kind::kStop;
  if (!push(c)) return Refusal::kBusy;
  seq = seq_;
  return Refusal::kNone;
}

void LiveStage::stop(ClientId client) {
  if (!controls(client)) return;
  live::ProtocolCommand c;
  c.kind = live::ProtocolCommand::Kind::kStop;
  push(c);  // a full ring: the heartbeat stops with the client anyway
}

void LiveStage::release(ClientId client) {
  if (owner_ != client || client == 0) return;
  live::ProtocolCommand c;
  c.kind = live::ProtocolCommand::Kind::kRelease;
  push(c);
  owner_ = 0;
}

void LiveStage::heartbeat() {
  if (owner_ == 0) return;
  if (halted()) {
    release(owner_);
    return;
  }
  if (live_.console_in_control()) {
    owner_ = 0;  // outranked: the loop already holds the stage
    return;
  }
  live::ProtocolCommand c;
  c.kind = live::ProtocolCommand::Kind::kHeartbeat;
  push(c);
}

}  // namespace mc::twins
