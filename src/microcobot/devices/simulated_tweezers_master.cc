#include "microcobot/devices/simulated_tweezers_master.h"

#include <algorithm>
#include <cmath>

namespace mc::devices {

SimulatedTweezersMaster::SimulatedTweezersMaster(std::string name, const tweezers::TeleTweezParams& params,
                                                 double dt_s)
    : TweezersMaster(std::move(name)), model_(params, dt_s) {}

void SimulatedTweezersMaster::on_configure() {
  state_ = tweezers::TeleTweezState{};
  force_cmd_ = 0.0;
  torque_ = 0.0;
}

void SimulatedTweezersMaster::command_grip_force_N(double force) noexcept {
  if (active() && std::isfinite(force)) force_cmd_ = force;
}

void SimulatedTweezersMaster::update(double) noexcept {
  const auto& p = model_.params();
  // A grip force resists the closing: the motor pushes the levers open (negative torque).
  const double t = active() ? -p.torque_for_finger_force(force_cmd_) : 0.0;
  torque_ = std::clamp(t, -p.max_torque_N_m, p.max_torque_N_m);
  tweezers::Input u;
  u[tweezers::kTorque] = torque_;
  u[tweezers::kFingerForce] = p.finger_stiffness_N_per_m * target_m_;
  u[tweezers::kTipForce] = 0.0;
  model_.step(state_, u);
  if (!state_.q.allFinite()) {
    fault();
    state_ = tweezers::TeleTweezState{};
  }
  ++readings_;
}

}  // namespace mc::devices
