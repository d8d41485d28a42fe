// The platform's parallel positioner (`positioner: parallel`; devices/parallel_positioner.h): the
// simulated one built from the configuration when no driver brings one (or the registered driver
// `parallel_positioner.driver` names, platform/driver_registry.h), its pose moves and followed
// poses under the deadman of the input that drives the coupling, its update on every tick.
#include <memory>

#include "microcobot/devices/simulated_parallel_positioner.h"
#include "microcobot/platform/driver_registry.h"
#include "microcobot/platform/platform.h"

namespace mc::platform {

void Platform::build_positioner() {
  if (devices_.positioner || !config_.parallel_positioner_enabled()) return;
  if (!config_.parallel_positioner.simulated()) {
    devices_.positioner = make_positioner(config_);  // a driver's (parallel_positioner.driver)
    return;
  }
  // The legs are the project's stick-slip axes: the platform's model and step map.
  const auto& c = config_.parallel_positioner;
  auto p = std::make_unique<devices::SimulatedParallelPositioner>(
      "parallel_positioner", *model_, *map_, c, config_.loop.period_s(),
      c.controller_on_thread() ? std::optional(c.controller_thread) : std::nullopt);
  sim_.positioner = p.get();
  devices_.positioner = std::move(p);
}

bool Platform::start_pose_move(const motion::PoseTrajectory& checked) noexcept {
  return devices_.positioner != nullptr && pose_move_allowed() && devices_.positioner->start_move(checked);
}

bool Platform::follow_pose(const motion::PlatformTransform& target,
                           const motion::PoseMoveLimits& limits) noexcept {
  return devices_.positioner != nullptr && pose_move_allowed() && devices_.positioner->follow(target, limits);
}

void Platform::positioner_task(double dt_s) noexcept {
  devices::ParallelPositioner* p = devices_.positioner.get();
  if (p == nullptr) return;
  // A move or a followed target runs only under the rule it started with: the deadman released,
  // the input stale or outranked, or a fault, and every leg holds where it is measured.
  if ((p->moving() || p->following()) && !pose_move_allowed()) p->stop();
  p->update(dt_s);
}

}  // namespace mc::platform
