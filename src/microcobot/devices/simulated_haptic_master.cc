#include "microcobot/devices/simulated_haptic_master.h"

#include <algorithm>
#include <cmath>

#include "microcobot/core/error.h"

namespace mc::devices {
namespace {

haptics::DualStagePlantParams at_rate(haptics::DualStagePlantParams p, double dt_s) {
  p.dt_s = dt_s;
  return p;
}
haptics::RenderPipelineParams at_rate(haptics::RenderPipelineParams p, double dt_s) {
  p.fs_Hz = 1.0 / dt_s;
  return p;
}

}  // namespace

SimulatedHapticMaster::SimulatedHapticMaster(std::string name, const haptics::DualStagePlantParams& plant,
                                             const haptics::RenderPipelineParams& pipeline,
                                             const haptics::PantographParams& pantograph, double dt_s)
    : HapticMaster(std::move(name)),
      plant_(at_rate(plant, dt_s)),
      pipeline_(at_rate(pipeline, dt_s)),
      pantograph_(pantograph),
      centre_(pantograph_.workspace_centre()) {}

void SimulatedHapticMaster::on_configure() {
  state_ = haptics::DualStagePlantState{};
  pipeline_.reset();
  force_cmd_ = {};
  rendered_ = {};
  channels_ = {};
  handle_m_ = hand_.hand_m;
}

void SimulatedHapticMaster::command_force_N(Vec2 force) noexcept {
  if (active() && std::isfinite(force.x) && std::isfinite(force.y)) force_cmd_ = force;
}

void SimulatedHapticMaster::enter_safe_state() noexcept {
  force_cmd_ = {};
  pipeline_.reset();
}

void SimulatedHapticMaster::update(double) noexcept {
  const Vec2 f = active() ? force_cmd_ : Vec2{};
  const double limit = pipeline_.params().max_force_N;
  channels_ = pipeline_.tick(f.y);  // y: crossover to the Pantograph and the Haptuator (Fig. 3.12)
  rendered_ = {std::clamp(f.x, -limit, limit), channels_.f_m_N};
  if (!plant_.try_step(state_, channels_.f_m_N, channels_.u_V)) {
    fault();
    state_ = haptics::DualStagePlantState{};
  }
  const double k_f = plant_.params().k_f_N_per_m;
  const Eigen::Vector2d handle(hand_.hand_m.x + rendered_.x / k_f, hand_.hand_m.y + state_.x(0));
  // The linkage stops at the workspace's limits: outside, the handle stays where it was.
  if (pantograph_.in_workspace(centre_ + handle)) handle_m_ = {handle.x(), handle.y()};
  if (!frozen_) ++readings_;
}

}  // namespace mc::devices
