#pragma once
/// @file
/// The TéléTweez held by a (simulated) operator: the 7-DOF model of eq. 4.6 behind the
/// TweezersMaster interface. The operator's fingers are position sources behind the finger
/// stiffness k_f of the model (the finger force input is k_f x target, as in the thesis's
/// robotic-mode experiment); the commanded grip force becomes the motor torque T = 2 F R_ss R_bs
/// (virtual work over both levers), limited to the motor's continuous torque. The safe state
/// is zero torque.

#include "microcobot/devices/device.h"
#include "microcobot/tweezers/teletweez.h"

namespace mc::devices {

class SimulatedTweezersMaster final : public TweezersMaster {
 public:
  /// Discretises the model at the loop period `dt_s` (allocates).
  SimulatedTweezersMaster(std::string name, const tweezers::TeleTweezParams& params, double dt_s);

  double opening_m() const override { return model_.tip_opening(state_); }
  std::uint64_t reading_count() const override { return readings_; }
  void command_grip_force_N(double force) noexcept override;
  void update(double dt_s) noexcept override;
  void enter_safe_state() noexcept override { force_cmd_ = 0.0; }

  /// The scripted operator: how far each finger aims to close the lever [m].
  void set_operator_closing(double target_m) noexcept { target_m_ = target_m; }
  double motor_torque_N_m() const { return torque_; }

 protected:
  void on_configure() override;

 private:
  tweezers::TeleTweez model_;
  tweezers::TeleTweezState state_;
  double target_m_ = 0.0;
  double force_cmd_ = 0.0;
  double torque_ = 0.0;
  std::uint64_t readings_ = 0;
};

}  // namespace mc::devices
