#include "microcobot/vendor/sim_companions.h"

#include <algorithm>
#include <cmath>

#include "microcobot/platform/simulated_haptic_master.h"
#include "microcobot/platform/simulated_tweezers_master.h"

namespace mc::vendor {

StandInGripper::StandInGripper(std::string name, double max_opening_m)
    : Gripper(std::move(name)), max_m_(max_opening_m), opening_m_(max_opening_m) {}

void StandInGripper::command_opening_m(double opening) noexcept {
  if (active() && std::isfinite(opening)) opening_m_ = std::clamp(opening, 0.0, max_m_);
}

platform::PlatformDevices make_sim_companions(const platform::PlatformConfig& config) {
  platform::PlatformDevices d;
  const double dt = config.loop.period_s();
  d.haptic = std::make_unique<platform::SimulatedHapticMaster>(
      "dual_stage", config.haptic.plant, config.haptic.render, config.haptic.pantograph, dt);
  d.tweezers = std::make_unique<platform::SimulatedTweezersMaster>("teletweez", config.tweezers, dt);
  d.gripper = std::make_unique<StandInGripper>("stand_in_gripper", config.world.gripper.max_opening_m);
  return d;
}

}  // namespace mc::vendor
