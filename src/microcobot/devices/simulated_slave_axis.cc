#include "microcobot/devices/simulated_slave_axis.h"

#include <algorithm>
#include <cmath>

#include "microcobot/core/error.h"

namespace mc::devices {

SimulatedSlaveAxis::SimulatedSlaveAxis(std::string name, const stickslip::ActuatorModel& model,
                                       const motion::PositionSensorParams& sensor, double start_m)
    : SlaveAxis(std::move(name)),
      model_(model),
      sensor_(sensor),
      start_m_(start_m),
      state_(model.initial_state()) {
  const double half = 0.5 * model.params().slider.stroke_m;
  require(std::isfinite(start_m) && std::abs(start_m) < half, this->name() + ".start_m",
          "must lie within the stroke", start_m);
}

void SimulatedSlaveAxis::on_configure() {
  state_ = model_.initial_state();
  state_.x2_m = {start_m_, start_m_};
  measured_m_ = sensor_.measure(true_position_m());
}

void SimulatedSlaveAxis::command_drive(const DriveBlock& block) noexcept {
  if (active()) block_ = block;
}

bool SimulatedSlaveAxis::at_end_stop() const {
  const double half = 0.5 * model_.params().slider.stroke_m;
  return std::abs(true_position_m()) >= half - 1e-9;
}

void SimulatedSlaveAxis::update(double dt_s) noexcept {
  const int n = std::max(1, static_cast<int>(std::lround(dt_s / model_.dt_s())));
  if (block_.frequency_Hz > 0.0 && block_.direction != 0) {
    model_.set_operating_point(
        state_, block_.amplitude_V, block_.frequency_Hz,
        block_.direction < 0 ? stickslip::Direction::kBackward : stickslip::Direction::kForward);
  }
  const double vmax = max_voltage_V();
  // A drive held at the model's own voltage on a model at rest changes nothing: a parked axis
  // (its loop off, the voltage held) costs no integration.
  bool held = active() && model_.at_rest(state_);
  for (int i = 0; i < block_.count && held; ++i)
    held = block_.segments[i].corners == 0 && block_.segments[i].end_V == state_.u_V;
  if (held) {
    state_.t_s += n * model_.dt_s();
    block_ = DriveBlock{};
    measured_m_ = sensor_.measure(true_position_m());
    return;
  }
  for (int i = 0; i < n; ++i) {
    // Past the block's end the last voltage holds (a DAC keeps its output).
    stickslip::DriveSegment d =
        i < block_.count ? block_.segments[i]
                         : stickslip::DriveSegment::to(
                               block_.count > 0 ? block_.segments[block_.count - 1].end_V : state_.u_V);
    auto safe = [&](double u) { return active() && std::isfinite(u) ? std::clamp(u, 0.0, vmax) : 0.0; };
    for (int j = 0; j < d.corners; ++j)
      d.u_V[static_cast<std::size_t>(j)] = safe(d.u_V[static_cast<std::size_t>(j)]);
    d.end_V = safe(d.end_V);
    model_.step(state_, d);
  }
  block_ = DriveBlock{};  // a block plays once; without a new one the voltage holds
  if (state_.diverged) {
    fault();
    return;
  }
  measured_m_ = sensor_.measure(true_position_m());
}

void SimulatedSlaveAxis::enter_safe_state() noexcept {
  // Hold at 0 V (update() plays 0 V while not Active): the amplifier's slew limit (1 V/us)
  // ramps the PE down within the next model steps.
  block_ = DriveBlock{};
}

}  // namespace mc::devices
