#include "microcobot/devices/simulated_optical_tweezers.h"

#include <cmath>

#include "microcobot/core/error.h"

namespace mc::devices {

SimulatedOpticalTweezers::SimulatedOpticalTweezers(std::string name,
                                                   const microworld::OpticalTrapSceneParams& scene,
                                                   std::array<const SimulatedSlaveAxis*, 3> axes,
                                                   const Vec3& home_m, double loop_dt_s)
    : Gripper(std::move(name)),
      scene_((scene.validate(), scene)),
      trap_(scene.trap),
      axes_(axes),
      home_m_(home_m.x, home_m.y, home_m.z),
      rng_(static_cast<std::uint64_t>(scene.seed)) {
  for (const auto* a : axes_) require(a != nullptr, this->name() + ".axes", "must all be set");
  require(home_m_.allFinite(), this->name() + ".home_m", "must be finite");
  const double ratio = loop_dt_s / scene_.trap.dt_s;
  require(std::isfinite(ratio) && ratio >= 1.0 && std::abs(ratio - std::round(ratio)) < 1e-6 * ratio,
          "optical_trap.dt_s", "must divide the loop period (1 / loop.base_rate_Hz)", scene_.trap.dt_s);
  substeps_ = static_cast<int>(std::lround(ratio));
  // On the dish, where the scene puts it: it does not move with a reset.
  obstacle_m_ = scene_.obstacle_m(home_m_.head<2>());
  trap_.set_obstacle(obstacle_m_);
}

Eigen::Vector3d SimulatedOpticalTweezers::tool_m() const {
  return home_m_ + Eigen::Vector3d(axes_[0]->true_position_m(), axes_[1]->true_position_m(),
                                   axes_[2]->true_position_m());
}

void SimulatedOpticalTweezers::on_configure() {
  // (Re)configured: a probe bead caught at rest in the trap, wherever the stage is.
  state_.trap_m = tool_m().head<2>();
  state_.bead_m = state_.trap_m;
  rng_ = Rng(static_cast<std::uint64_t>(scene_.seed));
  force_N_.setZero();
}

bool SimulatedOpticalTweezers::in_contact() const { return trap_.contact_force(state_.bead_m).norm() > 0.0; }

void SimulatedOpticalTweezers::update(double) noexcept {
  // The trap moves with the stage between two loop ticks at most by the stage's motion over
  // 100 us (nanometres): held over the tick, the bead integrated at the trap's own step.
  state_.trap_m = tool_m().head<2>();
  for (int i = 0; i < substeps_; ++i) {
    if (!trap_.try_step(state_, rng_)) {
      state_.bead_m = state_.trap_m;  // no non-finite position reaches the telemetry
      force_N_.setZero();
      fault();
      return;
    }
  }
  force_N_ = -trap_.trap_force(state_);  // k (x - x_trap), Fig. 3.3
}

}  // namespace mc::devices
