#include "microcobot/drivers/sim_companions.h"

#include <algorithm>
#include <cmath>

#include "microcobot/devices/simulated_haptic_master.h"
#include "microcobot/devices/simulated_tweezers_master.h"

namespace mc::drivers {

StandInGripper::StandInGripper(std::string name, double max_opening_m)
    : Gripper(std::move(name)), max_m_(max_opening_m), opening_m_(max_opening_m) {}

void StandInGripper::command_opening_m(double opening) noexcept {
  if (active() && std::isfinite(opening)) opening_m_ = std::clamp(opening, 0.0, max_m_);
}

devices::DeviceSet make_sim_companions(const platform::PlatformConfig& config) {
  devices::DeviceSet d;
  const double dt = config.loop.period_s();
  d.haptic = std::make_unique<devices::SimulatedHapticMaster>(
      "dual_stage", config.haptic.plant, config.haptic.render, config.haptic.pantograph, dt);
  d.tweezers = std::make_unique<devices::SimulatedTweezersMaster>("teletweez", config.tweezers, dt);
  d.gripper = std::make_unique<StandInGripper>("stand_in_gripper", config.world.gripper.max_opening_m);
  return d;
}

}  // namespace mc::drivers
