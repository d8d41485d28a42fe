#include "microcobot/net/remote_master.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "microcobot/core/error.h"

namespace mc::net {

void RemoteMasterParams::validate() const {
  link.validate();
  emulate.validate();
  require(std::isfinite(stale_timeout_s) && stale_timeout_s >= 1e-3 && stale_timeout_s <= 10.0,
          "stale_timeout_s", "must be within [0.001, 10] s", stale_timeout_s);
  for (double h : home_m) require(std::isfinite(h), "home_m", "must be finite", h);
  require_positive(goal_speed_m_s, "goal_speed_m_s");
  stream.validate();
  require(stream.capacity >= stream.delay_s * 1e3 + 2, "stream.capacity",
          "must hold the look-ahead's targets at 1 kHz (>= delay_s * 1000 + 2)", stream.capacity);
}

namespace {

// An emulated jitter is known: the look-ahead covers it (the stamps spread by twice the jitter,
// plus a period), and the ring holds the targets of that look-ahead.
motion::SetpointStreamParams covering_jitter(const RemoteMasterParams& p) {
  motion::SetpointStreamParams s = p.stream;
  if (p.emulate.jitter_s > 0.0) {
    s.delay_s = std::max(s.delay_s, 2.0 * p.emulate.jitter_s + 1e-3);
    s.capacity = std::max(s.capacity, static_cast<int>(std::ceil(s.delay_s * 1e3)) + 8);
  }
  return s;
}

}  // namespace

RemoteMaster::RemoteMaster(const RemoteMasterParams& params)
    : params_(params), ports_(params.passivity), targets_(covering_jitter(params)) {
  params_.link.role = Role::kSlave;
  params_.validate();
  stale_timeout_s_ = params_.stale_timeout_s + 2.0 * params_.emulate.jitter_s;
  if (impairs(params_.emulate)) emulator_ = std::make_unique<WireEmulator>(params_.emulate, kStateRate_Hz);
  link_ = std::make_unique<Link>(params_.link);
}

RemoteMaster::~RemoteMaster() = default;

void RemoteMaster::apply(const NetSample& s, double t_s, live::RemoteRequest& r) noexcept {
  switch (s.channel) {
    case Channel::kTarget:
      target_yaw_rad_ = s.yaw_rad;  // the rotary axis' goal (turned at its own speed limit)
      // The goal follows in poll(), through the jitter buffer and the ports.
      if (params_.interpolate_targets) {
        targets_.push(1e-9 * static_cast<double>(s.stamp_ns), s.xyz, now_s_);
      } else {
        asked_m_ = s.xyz;
      }
      has_target_ = true;
      // As old as it is: a backlog arriving after an outage does not refresh the master.
      last_target_t_ = std::max(last_target_t_, t_s - target_transit_.observe(s.transit_s(), s.received_s()));
      break;
    case Channel::kMasterPortEnergy:
      ports_.arrived(s.xyz);
      break;
    case Channel::kMasterGripperPortEnergy:
      ports_.arrived_gripper(s.xyz[0]);
      break;
    case Channel::kGripperTarget:
      asked_opening_m_ = s.scalar;  // the opening follows in poll(), through the gripper's port
      has_gripper_target_ = true;
      break;
    case Channel::kEstop: {
      const bool on = s.scalar != 0.0;
      if (estop_ && !on) r.reset = true;
      estop_ = on;
      break;
    }
    case Channel::kEngaged:
      engaged_ = s.scalar != 0.0;
      break;
    case Channel::kGripperShake:
      shake_ = s.scalar != 0.0;
      break;
    default:
      break;  // the slave's own channels never come back (the link ignores them)
  }
}

live::RemoteRequest RemoteMaster::poll(double t_s, live::ConsoleCommand& command) noexcept {
  live::RemoteRequest r;
  // The stamps' clock (ROS time): a vDSO read, no system call.
  now_s_ = 1e-9 * static_cast<double>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                          std::chrono::system_clock::now().time_since_epoch())
                                          .count());
  NetSample s;
  while (link_->receive(s)) {  // validated by the link thread: finite and within NetLimits
    if (emulator_) {
      emulator_->arrive(t_s, s);
    } else {
      apply(s, t_s, r);
    }
  }
  if (emulator_) emulator_->deliver(t_s, [&](const NetSample& d) { apply(d, t_s, r); });
  r.estop = estop_;
  r.fresh =
      engaged_ && t_s - last_target_t_ <= stale_timeout_s_ && (!params_.watch_dds || link_->peer_alive());
  command.deadman = engaged_;
  const double dt = last_poll_t_ >= 0.0 ? t_s - last_poll_t_ : 0.0;
  last_poll_t_ = t_s;
  if (r.fresh && !was_fresh_) {
    // The master (re)appeared: a new session of the channel. The goal stays where it is: it
    // joins the master's target through the ports like any motion (snapping it there would
    // output energy that no observer saw, e.g. into a contact after a lossy moment).
    ports_.restart();
    targets_.reset(goal_m_);
  }
  was_fresh_ = r.fresh;
  if (r.fresh && has_target_) {
    // The energy booked is force times displacement whatever the step: two polls at one time
    // (a test's) move the goal as one tick would.
    const double h = dt > 0.0 ? dt : 1e-3;
    if (params_.interpolate_targets) asked_m_ = targets_.sample(now_s_, h);
    Axes3 asked_v{};
    for (std::size_t i = 0; i < 3; ++i) asked_v[i] = (asked_m_[i] - goal_m_[i]) / h;
    const Axes3 v = ports_.velocity(asked_v, contact_N_, h);
    for (std::size_t i = 0; i < 3; ++i) goal_m_[i] += v[i] * h;
    if (has_gripper_target_ && opening_known_) {
      const double w = ports_.opening_rate((asked_opening_m_ - goal_opening_m_) / h, grip_N_, h);
      goal_opening_m_ += w * h;
    }
  }
  if (has_gripper_target_ && opening_known_) {
    command.has_gripper = true;
    command.gripper_opening_m = goal_opening_m_;
    command.gripper_shake = shake_;  // the coupling passes it only while engaged and fresh
  }
  if (has_target_) {
    command.has_goal = true;
    for (std::size_t i = 0; i < 3; ++i) command.goal_m[i] = params_.home_m[i] + goal_m_[i];
    command.velocity_m_s = {};
    command.goal_speed_m_s = params_.goal_speed_m_s;
    command.has_theta_goal = params_.rotary;
    command.theta_goal_rad = target_yaw_rad_;
  }
  const PortsReport ports = ports_.report();
  min_observed_J_.store(ports.min_observed_J, std::memory_order_relaxed);
  dissipated_J_.store(ports.dissipated_J, std::memory_order_relaxed);
  return r;
}

void RemoteMaster::send(Channel c, const std::array<double, 3>& xyz, double scalar, std::int64_t stamp_ns,
                        double yaw_rad) noexcept {
  NetSample s;
  s.channel = c;
  s.stamp_ns = stamp_ns;
  s.xyz = xyz;
  s.scalar = scalar;
  s.yaw_rad = yaw_rad;
  link_->send(s);  // a full ring is counted by the link
}

void RemoteMaster::publish(const platform::Platform& p) noexcept {
  const std::int64_t stamp = std::chrono::duration_cast<std::chrono::nanoseconds>(
                                 std::chrono::system_clock::now().time_since_epoch())
                                 .count();
  const auto& g = p.gripper();
  const devices::Vec3 f = g.contact_force_N();
  send(Channel::kMeasuredPose, {p.axis(0).position_m(), p.axis(1).position_m(), p.axis(2).position_m()}, 0.0,
       stamp, p.yaw_rad());
  send(Channel::kContactForce, {f.x, f.y, f.z}, 0.0, stamp);
  send(Channel::kGripForce, {g.grip_force_N(), 0.0, 0.0}, 0.0, stamp);
  send(Channel::kGripperOpening, {}, g.opening_m(), stamp);
  contact_N_ = {f.x, f.y, f.z};  // the slave's port reads it at the next poll
  grip_N_ = g.grip_force_N();
  if (!opening_known_) {
    // The opening goal starts where the gripper is: it joins the master's target through the
    // port like any motion.
    goal_opening_m_ = g.opening_m();
    opening_known_ = true;
  }
  const PortsReport ports = ports_.report();
  send(Channel::kSlavePortEnergy, ports.axes_input_energy_J(), 0.0, stamp);
  send(Channel::kSlaveGripperPortEnergy, {ports.input_energy_J[kGripperPort], 0.0, 0.0}, 0.0, stamp);
  // The device states: on a change at once, else at 10 Hz of the 1 kHz operator ticks.
  const std::array<double, 4> states = {
      static_cast<double>(p.axis(0).state()), static_cast<double>(p.axis(1).state()),
      static_cast<double>(p.axis(2).state()), static_cast<double>(g.state())};
  if (states != states_sent_ || --ticks_to_diagnostics_ <= 0) {
    send(Channel::kSlaveDiagnostics, {states[0], states[1], states[2]}, states[3], stamp);
    states_sent_ = states;
    ticks_to_diagnostics_ = static_cast<int>(kStateRate_Hz / kDiagnosticsRate_Hz);
  }
}

}  // namespace mc::net
