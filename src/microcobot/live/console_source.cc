#include "microcobot/live/console_source.h"

#include <algorithm>

#include "microcobot/live/microscope_source.h"
#include "microcobot/motion/pose.h"

namespace mc::live {

using platform::Platform;

SourceRequest ConsoleSource::poll(const SourceTick& t) noexcept {
  driving_ = false;
  ConsoleCommand c;
  bool got = false;
  while (commands_.pop(c)) {
    got = true;
    apply_microscope(t.platform, c);
    if (c.received_ns > 0) {
      // Applied in this tick: the command-to-target latency (a full ring drops the sample).
      const std::int64_t now = std::chrono::duration_cast<std::chrono::nanoseconds>(
                                   std::chrono::steady_clock::now().time_since_epoch())
                                   .count();
      latencies_.push(1e-9 * static_cast<double>(now - c.received_ns));
    }
  }
  if (got) {
    latest_ = c;
    last_command_t_ = t.tick.t_s;
  }
  const bool in_control = in_control_.load(std::memory_order_relaxed);
  fresh_.store(in_control && t.tick.t_s - last_command_t_ <= params_.command_timeout_s,
               std::memory_order_relaxed);
  SourceRequest r;
  r.claim = in_control || (task_ && task_->in_progress()) ? Claim::kActive : Claim::kStandby;
  return r;
}

void ConsoleSource::drive(const SourceTick& t, teleop::ConsoleInput& in) noexcept {
  driving_ = true;
  Platform& p = t.platform;
  const bool fresh = fresh_.load(std::memory_order_relaxed);
  in = coupling_input(latest_, fresh, params_.max_theta_speed_rad_s);
  // The task, supervised by the console in control: it drives or holds in the console's place.
  const bool in_control = in_control_.load(std::memory_order_relaxed);
  if (task_) task_->tick(p, params_.home_m, t.tick.dt_s, in_control && !p.faulted(), fresh, in);
  if (positioner_) {
    // The goal is the positioner's: the coupling's x and y loops are open.
    if (in.has_goal)
      positioner_->request_goal_world(in.goal_m.x(), in.goal_m.y());
    else if (latest_.has_goal_px)
      positioner_->request_goal_pixel(latest_.goal_px[0], latest_.goal_px[1]);
    else
      positioner_->clear_goal();
    in.has_goal = false;
  }
}

void ConsoleSource::publish(const SourceTick& t) noexcept {
  if (positioner_) vision_tick(t.platform, t.tick);
  pose_tick(t.platform);
  if (level_tips_.exchange(false, std::memory_order_relaxed)) {
    // Only under the console's own deadman: another input driving the coupling refuses it.
    if (driving_)
      t.platform.start_tip_levelling();
    else
      t.platform.refuse_tip_levelling("refused: the console does not drive the stage");
  }
}

void ConsoleSource::pose_tick(Platform& p) noexcept {
  ConsolePoseMove m;
  while (pose_moves_.pop(m)) {
    if (pending_pose_) pose_handled_ = pending_pose_->seq;  // outdated by a newer one
    pending_pose_ = m;
  }
  const devices::ParallelPositioner* pos = p.positioner();
  if (pending_pose_) {
    if (pos == nullptr || !driving_ || !p.pose_move_allowed() || !pending_pose_->trajectory) {
      // A stop, or no deadman: the move under way ends where it is (the platform holds without
      // the deadman anyway), and nothing starts. A jog is the jog's own to end (below).
      if (pos != nullptr && driving_ && pos->moving() && !pos->following()) p.stop_pose_move();
      pose_handled_ = pending_pose_->seq;
      pending_pose_.reset();
    } else if (!pos->moving()) {
      p.start_pose_move(*pending_pose_->trajectory);  // refused (nothing moves) if it no longer fits
      pose_handled_ = pending_pose_->seq;
      pending_pose_.reset();
    }
  }
  if (pos == nullptr) return;
  jog_tick(p);
  ConsolePoseView v;
  v.reference = pos->reference_pose();
  v.moving = pos->moving() || pending_pose_.has_value();
  v.jogging = pos->following();
  v.at_edge = pos->follow_blocked();
  v.handled_seq = pose_handled_;
  v.tips_m = p.tips_m();
  v.tip_floor_m = p.tip_floor_m();
  v.seat_on_plate = p.seat_on_plate();
  pose_view_.publish(v);
}

void ConsoleSource::jog_tick(Platform& p) noexcept {
  // A target this far ahead of the reference at the jog's speed: the pursuit's braking distance
  // at the move limits' accelerations is shorter, so the reference keeps the jog's speed.
  constexpr double kLookahead_s = 0.25;
  const devices::ParallelPositioner& pos = *p.positioner();
  const std::array<double, 6>& j = latest_.pose_jog;
  const Eigen::Vector3d v(j[0], j[1], j[2]), w(j[3], j[4], j[5]);
  const bool jog =
      driving_ && latest_.has_pose_jog && (v.norm() > 0.0 || w.norm() > 0.0) && p.pose_move_allowed();
  if (!jog) {
    // Released (no jog, a still one, no deadman, stale): the positioner holds where it is.
    if (pos.following()) p.stop_pose_move();
    return;
  }
  if (pos.moving() && !pos.following()) p.stop_pose_move();  // the jog takes over from a move
  motion::PoseMoveLimits lim = p.config().parallel_positioner.move;
  lim.max_speed_m_s = std::min(lim.max_speed_m_s, v.norm());
  lim.max_angular_speed_rad_s = std::min(lim.max_angular_speed_rad_s, w.norm());
  motion::PlatformTransform target = pos.reference_pose();
  target.d += kLookahead_s * v;
  target.R = motion::exp_so3(kLookahead_s * w) * target.R;
  p.follow_pose(target, lim);  // refused by a positioner that takes planned moves only
}

void ConsoleSource::vision_tick(Platform& p, const runtime::TickInfo& t) noexcept {
  // A jog run: long enough for a few sawtooth periods, short enough to stop with the stick.
  constexpr double kJogRun_s = 0.02;
  const teleop::ConsoleInput& in = p.console_input();
  const bool enabled = driving_ && in.active && in.fresh && in.deadman && !p.faulted();
  positioner_->set_enabled(enabled);
  const double now = params_.t_offset_s + t.t_s;
  perception::PositionerCommand c;
  while (vision_.pop(c)) {
    const double interval = c.interval_s - (now - c.t_issue_s);  // what is left of it
    if (!enabled || interval <= 0.0) continue;
    for (int i = 0; i < 2; ++i) p.command_open_loop_velocity(i, c.velocity_m_s[i], interval);
  }
  // The joystick in the plane (no goal pending): open-loop runs while it asks.
  if (!enabled || latest_.has_goal || latest_.has_goal_px) return;
  for (int i = 0; i < 2; ++i) {
    const double v = in.velocity_m_s[i];
    if (v != 0.0 && !p.open_loop_running(i)) p.command_open_loop_velocity(i, v, kJogRun_s);
  }
}

void ConsoleSource::reset() noexcept {
  latest_ = ConsoleCommand{};
  last_command_t_ = -1e9;
  driving_ = false;
  level_tips_.store(false, std::memory_order_relaxed);
  perception::PositionerCommand stale;
  while (vision_.pop(stale)) {
  }
  // Moves planned for the scene before: dropped (their sequence numbers count as handled).
  ConsolePoseMove old;
  while (pose_moves_.pop(old)) pose_handled_ = old.seq;
  if (pending_pose_) pose_handled_ = pending_pose_->seq;
  pending_pose_.reset();
}

void ConsoleSource::drain_latencies(runtime::TimingStats& stats) noexcept {
  double latency_s = 0.0;
  while (latencies_.pop(latency_s)) stats.add(latency_s);
}

}  // namespace mc::live
