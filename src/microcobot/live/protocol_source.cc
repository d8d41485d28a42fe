#include "microcobot/live/protocol_source.h"

#include <algorithm>
#include <cmath>

namespace mc::live {

using platform::Platform;

void ProtocolSource::stop_and_hold(Platform& p) noexcept {
  p.stop_open_loop();
  p.hold();
  has_goal_ = false;
  pending_steps_ = {};
  clear_pose_queue(true);
}

void ProtocolSource::queue_pose(const ProtocolCommand& c) noexcept {
  if (pose_count_ == kPoseQueue || !c.pose) {
    pose_rejected_ = std::max(pose_rejected_, c.seq);
    return;
  }
  const std::size_t i = (pose_head_ + pose_count_) % kPoseQueue;
  pose_queue_[i] = c.pose;  // a copy into storage of fixed size: no allocation
  pose_seq_[i] = c.seq;
  ++pose_count_;
}

void ProtocolSource::clear_pose_queue(bool rejected) noexcept {
  while (pose_count_ > 0) {
    if (rejected) pose_rejected_ = std::max(pose_rejected_, pose_seq_[pose_head_]);
    pose_head_ = (pose_head_ + 1) % kPoseQueue;
    --pose_count_;
  }
}

SourceRequest ProtocolSource::poll(const SourceTick& t) noexcept {
  Platform& p = t.platform;
  const double now = t.tick.t_s;
  ProtocolCommand c;
  while (ring_.pop(c)) {
    popped_seq_ = std::max(popped_seq_, c.seq);
    switch (c.kind) {
      case ProtocolCommand::Kind::kHeartbeat:
        last_t_ = now;
        break;
      case ProtocolCommand::Kind::kMoveTo:
        last_t_ = now;
        p.stop_open_loop();
        goal_m_ = c.goal_m;
        speed_m_s_ = c.speed_m_s;
        theta_goal_rad_ = c.theta_goal_rad;
        theta_speed_rad_s_ = c.theta_speed_rad_s;
        has_goal_ = true;
        pending_steps_ = {};
        settled_s_ = {};
        break;
      case ProtocolCommand::Kind::kSteps:
        last_t_ = now;
        has_goal_ = false;
        pending_steps_[static_cast<std::size_t>(std::clamp(c.axis, 0, 3))] = c;
        break;
      case ProtocolCommand::Kind::kStop:
        clear_pose_queue(false);         // the stop covers the moves sent before it
        if (holding_) stop_and_hold(p);  // a protocol stop never interrupts another source
        pose_stop_ = c.seq;
        break;
      case ProtocolCommand::Kind::kPoseMove:
        last_t_ = now;
        queue_pose(c);
        break;
      case ProtocolCommand::Kind::kRelease:
        stop_and_hold(p);
        last_t_ = -1e9;
        break;
    }
  }
  // A halted platform forgets the protocol's goal: nothing resumes by itself after the reset.
  if (p.faulted()) {
    has_goal_ = false;
    pending_steps_ = {};
    clear_pose_queue(true);
  }
  SourceRequest r;
  if (now - last_t_ <= params_.command_timeout_s) r.claim = Claim::kActive;
  return r;
}

void ProtocolSource::drive(const SourceTick& t, teleop::ConsoleInput& in) noexcept {
  holding_ = true;
  const Eigen::Vector3d& home = params_.home_m;
  in.active = true;
  in.fresh = true;
  in.deadman = true;
  in.has_goal = has_goal_;
  in.goal_m = {home.x() + goal_m_[0], home.y() + goal_m_[1], home.z() + goal_m_[2]};
  in.goal_speed_m_s = speed_m_s_;
  // The rotary axis turns to the same command's goal (none without the axis: the target stays).
  in.has_theta_goal = has_goal_ && t.platform.has_rotary();
  in.theta_goal_rad = theta_goal_rad_;
  in.theta_speed_rad_s = theta_speed_rad_s_;
}

void ProtocolSource::released(const SourceTick& t) noexcept {
  // A pose move under way at the last tick (the arbiter has held the platform since) ends short of
  // its goal: its client is told (interrupted_seq).
  if (holding_ && pose_running_) pose_interrupted_ = pose_started_;
  pose_running_ = false;
  holding_ = false;
  stop_and_hold(t.platform);  // gone, stale or outranked: every axis holds
}

void ProtocolSource::publish(const SourceTick& t) noexcept {
  Platform& p = t.platform;
  // Steps start only while the protocol drives (the console input they check is its).
  for (auto& pending : pending_steps_) {
    if (pending && holding_) {
      const ProtocolCommand& s = *pending;
      if (!p.start_open_loop_steps(s.axis, s.amplitude_V, s.frequency_Hz, s.direction, s.periods))
        refused_steps_.fetch_add(1, std::memory_order_relaxed);
    }
    pending.reset();
  }
  const double dt = std::max(0.0, t.tick.t_s - last_publish_t_);
  last_publish_t_ = t.tick.t_s;
  const auto& target = p.teleop().slave_target_m;
  // The rotary axis is on target within the linear axes' tolerance as an arc at its contact
  // radius: the same actuator, the same sensor.
  const double theta_tolerance_rad = params_.on_target_tolerance_m / params_.rotary_radius_m;
  for (std::size_t i = 0; i < 4; ++i) {
    const bool theta = i == 3;
    if (theta && !p.has_rotary()) break;
    const double x = theta ? p.yaw_rad() : p.axis(static_cast<int>(i)).position_m();
    const bool running = p.open_loop_running(static_cast<int>(i));
    const double goal = theta       ? (has_goal_ ? theta_goal_rad_ : p.yaw_target_rad())
                        : has_goal_ ? goal_m_[i]
                                    : target[static_cast<Eigen::Index>(i)];
    const double tolerance = theta ? theta_tolerance_rad : params_.on_target_tolerance_m;
    settled_s_[i] = !running && std::abs(x - goal) <= tolerance ? settled_s_[i] + dt : 0.0;
    position_[i].store(x, std::memory_order_relaxed);
    on_target_[i].store(settled_s_[i] >= params_.settle_window_s, std::memory_order_relaxed);
    stepping_[i].store(running, std::memory_order_relaxed);
  }
  driving_.store(holding_, std::memory_order_relaxed);
  publish_positioner(t);
  applied_seq_.store(popped_seq_, std::memory_order_release);
}

void ProtocolSource::publish_positioner(const SourceTick& t) noexcept {
  Platform& p = t.platform;
  const devices::ParallelPositioner* pos = p.positioner();
  if (pos == nullptr) {
    clear_pose_queue(true);
    return;
  }
  // The next queued move starts once the one under way has ended (it was planned from its goal),
  // only while the protocol drives.
  if (!holding_) clear_pose_queue(true);
  if (pose_count_ > 0 && !pos->moving()) {
    const std::uint64_t seq = pose_seq_[pose_head_];
    if (p.start_pose_move(*pose_queue_[pose_head_]))
      pose_started_ = std::max(pose_started_, seq);
    else
      pose_rejected_ = std::max(pose_rejected_, seq);
    pose_head_ = (pose_head_ + 1) % kPoseQueue;
    --pose_count_;
  }
  // A move under way the platform stopped short (the seat onto the tips, ...): its client is told.
  if (pose_running_ && p.pose_moves_stopped() != platform_stops_) pose_interrupted_ = pose_started_;
  platform_stops_ = p.pose_moves_stopped();
  pose_running_ = pos->moving();
  PositionerView v;
  v.measured = pos->measured_pose();
  v.reference = pos->reference_pose();
  v.moving = pos->moving() || pose_count_ > 0;
  v.at_rest = pos->at_rest() && pose_count_ == 0;
  v.halted = p.faulted() || !pos->active();
  v.started_seq = pose_started_;
  v.rejected_seq = pose_rejected_;
  v.stop_seq = pose_stop_;
  v.interrupted_seq = pose_interrupted_;
  v.time_s = t.tick.t_s;
  positioner_view_.publish(v);
}

void ProtocolSource::reset() noexcept {
  clear_pose_queue(true);
  last_t_ = -1e9;
  holding_ = has_goal_ = pose_running_ = false;
  pending_steps_ = {};
  settled_s_ = {};
}

ProtocolView ProtocolSource::view() const noexcept {
  ProtocolView v;
  v.applied_seq = applied_seq_.load(std::memory_order_acquire);
  v.protocol_fresh = driving_.load(std::memory_order_relaxed);
  for (std::size_t i = 0; i < 4; ++i) {
    v.position[i] = position_[i].load(std::memory_order_relaxed);
    v.on_target[i] = on_target_[i].load(std::memory_order_relaxed);
    v.stepping[i] = stepping_[i].load(std::memory_order_relaxed);
  }
  v.refused_steps = refused_steps_.load(std::memory_order_relaxed);
  return v;
}

}  // namespace mc::live
