#pragma once
/// @file
/// The devices a vendor driver set (pi-gcs2, anc300, smaract-mcs2) does not drive: the haptic master and the
/// TéléTweez are the simulated ones (the console, or their simulated hands, operate them), and
/// the gripper is a stand-in with no microworld behind it (the stage is real, or another
/// process's twin, so this process has no part to pick): it reports the opening it was commanded
/// and no force. A lab with a real gripper replaces it in its own driver set.

#include "microcobot/devices/device_set.h"
#include "microcobot/platform/platform_config.h"

namespace mc::drivers {

/// A gripper with nothing between its fingers: opening = the last command (clamped to
/// [0, max_opening_m]), grip and contact forces 0. Its safe state keeps the opening (as every
/// gripper's: never drop a part).
class StandInGripper final : public devices::Gripper {
 public:
  StandInGripper(std::string name, double max_opening_m);
  void command_opening_m(double opening) noexcept override;
  double opening_m() const override { return opening_m_; }
  double grip_force_N() const override { return 0.0; }
  devices::Vec3 contact_force_N() const override { return {}; }
  void update(double) noexcept override {}
  void enter_safe_state() noexcept override {}

 private:
  double max_m_;
  double opening_m_ = 0.0;
};

/// The simulated haptic master and TéléTweez of `config`, and a StandInGripper; no axes.
devices::DeviceSet make_sim_companions(const platform::PlatformConfig& config);

}  // namespace mc::drivers
