#include "microcobot/net/remote_slave.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

#include "microcobot/core/error.h"

namespace mc::net {
namespace {

std::int64_t ros_time_ns() noexcept {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

/// What every remote device shares: the link, and the e-stop semantics of its lifecycle.
/// Leaving operation (a fault, an e-stop, shutdown) latches the slave's e-stop; configure() from
/// rest does not; activate() releases it.
template <class Interface>
class RemoteDevice : public Interface {
 public:
  RemoteDevice(std::string name, RemoteSlave& slave) : Interface(std::move(name)), slave_(slave) {}
  void enter_safe_state() noexcept override {
    if (this->active()) slave_.set_estop(true);
  }

 protected:
  void on_activate() override { slave_.set_estop(false); }
  RemoteSlave& slave_;
};

/// One axis of the remote stage: its measurements are the slave's latest pose.
class RemoteSlaveAxis final : public RemoteDevice<devices::SlaveAxis> {
 public:
  RemoteSlaveAxis(std::string name, RemoteSlave& slave, int index, const RemoteSlaveParams& p)
      : RemoteDevice(std::move(name), slave),
        index_(index),
        period_s_(p.sample_period_s),
        max_V_(p.max_voltage_V),
        rotary_(p.rotary) {}
  double sample_period_s() const override { return period_s_; }
  double max_voltage_V() const override { return max_V_; }
  // Never called: the platform sends targets to position-controlled axes.
  void command_drive(const devices::DriveBlock&) noexcept override {}
  double position_m() const override {
    return index_ == 3 ? rotary_.arc_m(slave_.state().yaw_rad)
                       : slave_.state().position_m[static_cast<std::size_t>(index_)];
  }
  bool at_end_stop() const override { return false; }  // the slave's stage controller knows
  bool position_controlled() const override { return true; }
  void command_target_m(double target_m, double velocity_m_s) noexcept override {
    if (active()) slave_.set_target(index_, target_m, velocity_m_s);
  }
  bool measurement_fresh() const override { return slave_.fresh(); }
  void update(double) noexcept override {}

 private:
  int index_;  // 0-2: x, y, z; 3: the rotary axis (its position the arc of the slave's yaw)
  double period_s_, max_V_;
  motion::RotaryAxisParams rotary_;
};

/// The slave's gripper; its update() runs the link exchange once per tick.
class RemoteGripper final : public RemoteDevice<devices::Gripper> {
 public:
  using RemoteDevice::RemoteDevice;
  void command_opening_m(double opening) noexcept override {
    if (active()) slave_.set_gripper_target(opening);
  }
  /// The burst travels to the slave's gripper; its coupling decides whether it shakes.
  void command_shake(bool on) noexcept override {
    if (active()) slave_.set_gripper_shake(on);
  }
  bool can_shake() const override { return true; }
  void enter_safe_state() noexcept override {
    if (active()) slave_.set_gripper_shake(false);
    RemoteDevice::enter_safe_state();
  }
  double opening_m() const override { return slave_.state().opening_m; }
  double grip_force_N() const override { return slave_.state().grip_force_N; }
  devices::Vec3 contact_force_N() const override {
    const auto& f = slave_.state().contact_force_N;
    return {f[0], f[1], f[2]};
  }
  void update(double dt_s) noexcept override { slave_.exchange(dt_s); }
};

}  // namespace

void RemoteSlaveParams::validate() const {
  link.validate();
  emulate.validate();
  require(std::isfinite(stale_timeout_s) && stale_timeout_s >= 1e-3 && stale_timeout_s <= 10.0,
          "stale_timeout_s", "must be within [0.001, 10] s", stale_timeout_s);
  require_positive(sample_period_s, "sample_period_s");
  require(max_voltage_V > 0 && max_voltage_V <= 100.0, "max_voltage_V", "must be within (0, 100] V",
          max_voltage_V);
}

RemoteSlave::RemoteSlave(const RemoteSlaveParams& params) : params_(params), ports_(params.passivity) {
  params_.link.role = Role::kMaster;
  params_.validate();
  stale_timeout_s_ = params_.stale_timeout_s + 2.0 * params_.emulate.jitter_s;
  if (impairs(params_.emulate)) emulator_ = std::make_unique<WireEmulator>(params_.emulate, kStateRate_Hz);
  link_ = std::make_unique<Link>(params_.link);
}

RemoteSlave::~RemoteSlave() = default;

devices::DeviceSet RemoteSlave::make_devices() {
  devices::DeviceSet d;
  const char* names[3] = {"remote_axis_x", "remote_axis_y", "remote_axis_z"};
  for (int i = 0; i < 3; ++i)
    d.axes[static_cast<std::size_t>(i)] = std::make_unique<RemoteSlaveAxis>(names[i], *this, i, params_);
  if (params_.rotary.enabled)
    d.rotary = std::make_unique<RemoteSlaveAxis>("remote_axis_theta", *this, 3, params_);
  d.gripper = std::make_unique<RemoteGripper>("remote_gripper", *this);
  return d;
}

void RemoteSlave::send(Channel c, const std::array<double, 3>& xyz, double scalar, double yaw_rad) noexcept {
  NetSample s;
  s.channel = c;
  s.stamp_ns = ros_time_ns();
  s.xyz = xyz;
  s.scalar = scalar;
  s.yaw_rad = yaw_rad;
  link_->send(s);  // a full ring is counted by the link
}

void RemoteSlave::set_target(int axis, double target_m, double /*velocity_m_s*/) noexcept {
  if (axis == 3)
    target_yaw_rad_ = params_.rotary.angle_rad(target_m);
  else
    target_m_[static_cast<std::size_t>(axis)] = target_m;
  target_mask_ |= 1u << axis;
  // A target computed while the slave was silent is the coupling's frozen guess, not a command
  // for a slave that (re)appears: only targets computed on fresh measurements are sent.
  targets_fresh_ = fresh();
}

void RemoteSlave::set_gripper_shake(bool on) noexcept {
  if (shake_sent_ == static_cast<int>(on)) return;
  shake_sent_ = static_cast<int>(on);
  send(Channel::kGripperShake, {}, on ? 1.0 : 0.0);
}

void RemoteSlave::set_estop(bool on) noexcept {
  if (estop_sent_ == static_cast<int>(on)) return;
  estop_sent_ = static_cast<int>(on);
  send(Channel::kEstop, {}, on ? 1.0 : 0.0);
  send(Channel::kEngaged, {}, on ? 0.0 : 1.0);
}

void RemoteSlave::apply(const NetSample& s) noexcept {
  switch (s.channel) {
    case Channel::kMeasuredPose:
      state_.position_m = s.xyz;
      state_.yaw_rad = s.yaw_rad;
      // As old as it is: a backlog arriving after an outage does not refresh the slave.
      state_.age_s = std::min(state_.age_s, pose_transit_.observe(s.transit_s(), s.received_s()));
      break;
    case Channel::kContactForce:
      received_contact_N_ = s.xyz;  // out through the ports in exchange()
      break;
    case Channel::kSlavePortEnergy:
      ports_.arrived(s.xyz);
      break;
    case Channel::kSlaveGripperPortEnergy:
      ports_.arrived_gripper(s.xyz[0]);
      break;
    case Channel::kGripForce:
      received_grip_N_ = s.xyz[0];  // out through the gripper's port in exchange()
      break;
    case Channel::kGripperOpening:
      state_.opening_m = s.scalar;
      break;
    case Channel::kSlaveDiagnostics:  // checked by the link: each a Lifecycle value
      for (std::size_t i = 0; i < 3; ++i) state_.lifecycle[i] = static_cast<devices::Lifecycle>(s.xyz[i]);
      state_.lifecycle[3] = static_cast<devices::Lifecycle>(s.scalar);
      break;
    default:
      break;  // the master's own channels never come back (the link ignores them)
  }
}

void RemoteSlave::exchange(double dt_s) noexcept {
  state_.age_s += dt_s;
  now_s_ += dt_s;
  NetSample s;
  while (link_->receive(s)) {  // validated by the link thread: finite and within NetLimits
    if (emulator_) {
      emulator_->arrive(now_s_, s);
    } else {
      apply(s);
    }
  }
  if (emulator_) emulator_->deliver(now_s_, [this](const NetSample& d) { apply(d); });
  const bool is_fresh = fresh();
  if (is_fresh && !was_fresh_) {
    // The slave (re)appeared: a new session of the channel; targets count from the next one.
    ports_.restart();
    target_sent_ = false;
    target_rate_m_s_ = {};
    gripper_rate_m_s_ = 0.0;
  }
  was_fresh_ = is_fresh;
  // This tick's force out of the channel, against the rate of the target last sent.
  state_.contact_force_N = ports_.contact_force(received_contact_N_, target_rate_m_s_, dt_s);
  state_.grip_force_N = ports_.grip_force(received_grip_N_, gripper_rate_m_s_, dt_s);
  const PortsReport ports = ports_.report();
  min_observed_J_.store(ports.min_observed_J, std::memory_order_relaxed);
  dissipated_J_.store(ports.dissipated_J, std::memory_order_relaxed);
  since_sent_s_ += dt_s;
  if (target_mask_ != (params_.rotary.enabled ? 0b1111u : 0b111u)) return;
  target_mask_ = 0;
  if (!targets_fresh_) {
    target_rate_m_s_ = {};
    gripper_rate_m_s_ = 0.0;
    return;
  }
  const bool rate_known = target_sent_ && since_sent_s_ > 0.0;
  for (std::size_t i = 0; i < 3; ++i)
    target_rate_m_s_[i] = rate_known ? (target_m_[i] - sent_target_m_[i]) / since_sent_s_ : 0.0;
  gripper_rate_m_s_ = rate_known ? (gripper_target_m_ - sent_gripper_m_) / since_sent_s_ : 0.0;
  sent_target_m_ = target_m_;
  sent_gripper_m_ = gripper_target_m_;
  target_sent_ = true;
  since_sent_s_ = 0.0;
  send(Channel::kTarget, target_m_, 0.0, params_.rotary.enabled ? target_yaw_rad_ : 0.0);
  send(Channel::kGripperTarget, {}, gripper_target_m_);
  send(Channel::kMasterPortEnergy, ports.axes_input_energy_J(), 0.0);
  send(Channel::kMasterGripperPortEnergy, {ports.input_energy_J[kGripperPort], 0.0, 0.0}, 0.0);
}

}  // namespace mc::net
