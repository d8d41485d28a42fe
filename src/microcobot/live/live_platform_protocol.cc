// The live platform's port for the vendor-protocol twins (vendor/, the rotary axis
// included): what a GCS 2.0 or ANC300 client asked, taken on the operator tick (a heartbeat-guarded
// goal or a run of open-loop steps, outranked by a console user, the demo, a task or a remote master), and
// what it reads back (positions, on-target after the settle window, stepping), published for its threads.
#include <algorithm>
#include <cmath>

#include "microcobot/live/live_platform.h"

namespace mc::live {

using platform::Platform;

bool LivePlatform::protocol_tick(const runtime::TickInfo& t, bool console_control,
                                 teleop::ConsoleInput& in) noexcept {
  Platform& p = *platform_;
  auto stop_and_hold = [&] {
    p.stop_open_loop();
    p.hold();
    protocol_has_goal_ = false;
    protocol_steps_pending_ = false;
  };
  ProtocolCommand c;
  while (protocol_.pop(c)) {
    popped_seq_ = std::max(popped_seq_, c.seq);
    switch (c.kind) {
      case ProtocolCommand::Kind::kHeartbeat:
        protocol_last_t_ = t.t_s;
        break;
      case ProtocolCommand::Kind::kMoveTo:
        protocol_last_t_ = t.t_s;
        p.stop_open_loop();
        protocol_goal_m_ = c.goal_m;
        protocol_speed_m_s_ = c.speed_m_s;
        protocol_theta_goal_rad_ = c.theta_goal_rad;
        protocol_theta_speed_rad_s_ = c.theta_speed_rad_s;
        protocol_has_goal_ = true;
        protocol_steps_pending_ = false;
        settled_s_ = {};
        break;
      case ProtocolCommand::Kind::kSteps:
        protocol_last_t_ = t.t_s;
        protocol_has_goal_ = false;
        pending_steps_ = c;
        protocol_steps_pending_ = true;
        break;
      case ProtocolCommand::Kind::kStop:
        if (protocol_fresh_) stop_and_hold();  // a protocol stop never interrupts a console user
        break;
      case ProtocolCommand::Kind::kRelease:
        stop_and_hold();
        protocol_last_t_ = -1e9;
        break;
    }
  }
  // A halted platform forgets the protocol's goal: nothing resumes by itself after the reset.
  if (p.faulted()) {
    protocol_has_goal_ = false;
    protocol_steps_pending_ = false;
  }
  // The heartbeat is the protocol client's deadman; a console client in control, the demo, a
  // started task or a remote master outrank it.
  const bool fresh = !console_control && !params_.remote && !(demo_ && !demo_finished_) &&
                     !(task_ && task_->in_progress()) &&
                     t.t_s - protocol_last_t_ <= params_.command_timeout_s;
  if (protocol_fresh_ && !fresh) stop_and_hold();  // gone, stale or outranked: every axis holds
  protocol_fresh_ = fresh;
  if (!fresh) {
    protocol_steps_pending_ = false;
    return false;
  }
  const double home[3] = {params_.platform.stage.home_x_m, params_.platform.stage.home_y_m,
                          params_.platform.stage.home_z_m};
  in.active = true;
  in.fresh = true;
  in.deadman = true;
  in.has_goal = protocol_has_goal_;
  in.goal_m = {home[0] + protocol_goal_m_[0], home[1] + protocol_goal_m_[1], home[2] + protocol_goal_m_[2]};
  in.goal_speed_m_s = protocol_speed_m_s_;
  // The rotary axis turns to the same command's goal (none without the axis: the target stays).
  in.has_theta_goal = protocol_has_goal_ && p.has_rotary();
  in.theta_goal_rad = protocol_theta_goal_rad_;
  in.theta_speed_rad_s = protocol_theta_speed_rad_s_;
  return true;
}

void LivePlatform::protocol_publish(const runtime::TickInfo& t) noexcept {
  Platform& p = *platform_;
  if (protocol_steps_pending_) {
    const ProtocolCommand& s = pending_steps_;
    if (!p.start_open_loop_steps(s.axis, s.amplitude_V, s.frequency_Hz, s.direction, s.periods))
      refused_steps_.fetch_add(1, std::memory_order_relaxed);
    protocol_steps_pending_ = false;
  }
  const double dt = std::max(0.0, t.t_s - last_operator_t_);
  last_operator_t_ = t.t_s;
  const auto& target = p.teleop().slave_target_m;
  // The rotary axis is on target within the linear axes' tolerance as an arc at its contact
  // radius: the same actuator, the same sensor.
  const double theta_tolerance_rad = params_.on_target_tolerance_m / params_.platform.stage.rotary.radius_m;
  for (std::size_t i = 0; i < 4; ++i) {
    const bool theta = i == 3;
    if (theta && !p.has_rotary()) break;
    const double x = theta ? p.yaw_rad() : p.axis(static_cast<int>(i)).position_m();
    const bool running = p.open_loop_running(static_cast<int>(i));
    const double goal = theta ? (protocol_has_goal_ ? protocol_theta_goal_rad_ : p.yaw_target_rad())
                        : protocol_has_goal_ ? protocol_goal_m_[i]
                                             : target[static_cast<Eigen::Index>(i)];
    const double tolerance = theta ? theta_tolerance_rad : params_.on_target_tolerance_m;
    settled_s_[i] = !running && std::abs(x - goal) <= tolerance ? settled_s_[i] + dt : 0.0;
    axis_position_[i].store(x, std::memory_order_relaxed);
    on_target_[i].store(settled_s_[i] >= params_.settle_window_s, std::memory_order_relaxed);
    stepping_[i].store(running, std::memory_order_relaxed);
  }
  protocol_driving_.store(protocol_fresh_, std::memory_order_relaxed);
  applied_seq_.store(popped_seq_, std::memory_order_release);
}

ProtocolView LivePlatform::protocol_view() const noexcept {
  ProtocolView v;
  v.applied_seq = applied_seq_.load(std::memory_order_acquire);
  v.protocol_fresh = protocol_driving_.load(std::memory_order_relaxed);
  for (std::size_t i = 0; i < 4; ++i) {
    v.position[i] = axis_position_[i].load(std::memory_order_relaxed);
    v.on_target[i] = on_target_[i].load(std::memory_order_relaxed);
    v.stepping[i] = stepping_[i].load(std::memory_order_relaxed);
  }
  v.console_in_control = in_control_.load(std::memory_order_relaxed);
  v.halted = estopped_.load(std::memory_order_relaxed);
  v.refused_steps = refused_steps_.load(std::memory_order_relaxed);
  return v;
}

}  // namespace mc::live
