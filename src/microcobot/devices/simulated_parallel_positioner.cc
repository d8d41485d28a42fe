#include "microcobot/devices/simulated_parallel_positioner.h"

#include <algorithm>
#include <cmath>

#include "microcobot/core/error.h"

namespace mc::devices {

SimulatedParallelPositioner::SimulatedParallelPositioner(std::string name,
                                                         const stickslip::ActuatorModel& model,
                                                         const motion::StepMap& map,
                                                         const motion::ParallelStageParams& params,
                                                         double loop_period_s)
    : ParallelPositioner(std::move(name)), stage_(model, map, params) {
  const double n = loop_period_s / stage_.tick_s();
  require(std::isfinite(n) && n >= 1.0 - 1e-9 && std::abs(n - std::round(n)) < 1e-6 * n,
          "parallel_positioner.tracking.control_rate_Hz",
          "must be a whole multiple of the loop's rate (loop.base_rate_Hz)", params.tracking.control_rate_Hz);
  ticks_per_update_ = std::max(1, static_cast<int>(std::lround(n)));
}

void SimulatedParallelPositioner::update(double /*dt_s*/) noexcept {
  // The physics runs in every state; the drive is the trackers' while Active, 0 V otherwise.
  for (int k = 0; k < ticks_per_update_; ++k) stage_.tick();
  if (stage_.fault() && state() != Lifecycle::kFault) fault();
}

bool SimulatedParallelPositioner::start_move(const motion::PoseTrajectory& checked) noexcept {
  return active() && stage_.start_move(checked);
}

double SimulatedParallelPositioner::max_leg_voltage_V() const noexcept {
  double u = 0.0;
  for (int i = 0; i < motion::kParallelAxes; ++i) u = std::max(u, std::abs(stage_.status(i).voltage_V));
  return u;
}

void SimulatedParallelPositioner::step_leg(int leg, motion::LegPositioner positioner, int steps,
                                           double frequency_Hz) {
  if (!active()) throw InvalidInput("device '" + name() + "': steps only while active");
  stage_.step_leg(leg, positioner, steps, frequency_Hz);
}

}  // namespace mc::devices
