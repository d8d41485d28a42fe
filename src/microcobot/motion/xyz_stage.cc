#include "microcobot/motion/xyz_stage.h"

#include <cmath>
#include <string>

#include "microcobot/core/error.h"
#include "microcobot/motion/closed_loop.h"

namespace mc::motion {

Axis parse_axis(const std::string& name) {
  if (name == "x") return Axis::kX;
  if (name == "y") return Axis::kY;
  if (name == "z") return Axis::kZ;
  throw UsageError("--axis must be x, y or z (got '" + name + "')");
}

std::string to_string(Axis a) {
  switch (a) {
    case Axis::kX:
      return "x";
    case Axis::kY:
      return "y";
    case Axis::kZ:
      return "z";
  }
  return "x";
}

XyzStage::XyzStage(const stickslip::ActuatorModel& model, const StepMap& map, const XyzStageParams& p)
    : model_(model), p_(p) {
  p_.validate();
  ratio_ = steps_per_tick(model, p_.control.control_rate_Hz);
  for (std::size_t i = 0; i < 3; ++i) {
    PositionSensorParams sp = p_.sensor;
    sp.seed = p_.sensor.seed + static_cast<int>(i);  // independent noise per axis
    axes_[i].state = model.initial_state();
    axes_[i].sensor = PositionSensor(sp);
    axes_[i].ctrl = std::make_unique<PositionController>(p_.control, model.params(), map);
    axes_[i].measured = model.slider_position(axes_[i].state);
  }
}

void XyzStage::place(Axis a, double position_m) {
  const double half = 0.5 * model_.params().slider.stroke_m;
  require(std::isfinite(position_m) && std::abs(position_m) <= half, "position_m",
          "must lie within the stroke", position_m);
  auto& ax = axes_[static_cast<std::size_t>(a)];
  ax.state = model_.initial_state();
  ax.state.x2_m = {position_m, position_m};
}

void XyzStage::set_target(Axis a, double target_m) noexcept {
  axes_[static_cast<std::size_t>(a)].ctrl->set_target(target_m);
}

void XyzStage::emergency_stop() noexcept {
  for (auto& ax : axes_) {
    ax.ctrl->emergency_stop();
    ax.u = 0.0;
  }
}

void XyzStage::tick() noexcept {
  const double dt = model_.dt_s();
  for (auto& ax : axes_) {
    ax.measured = ax.sensor.measure(model_.slider_position(ax.state));
    ax.ctrl->update(ax.measured);
    const auto& g = ax.ctrl->generator();
    model_.set_operating_point(ax.state, g.amplitude_V(), g.frequency_Hz(), g.direction());
    for (int i = 0; i < ratio_; ++i) {
      const stickslip::DriveSegment d = ax.ctrl->next_drive(dt);
      model_.step(ax.state, d);
      ax.u = d.end_V;
    }
    if (ax.state.diverged) {
      // Safe state on a fault: this axis and the others to 0 V.
      diverged_ = true;
      emergency_stop();
    }
  }
  t_ += tick_s();
}

AxisStatus XyzStage::status(Axis a) const noexcept {
  const auto& ax = axes_[static_cast<std::size_t>(a)];
  AxisStatus s;
  s.position_m = model_.slider_position(ax.state);
  s.measured_m = ax.measured;
  s.voltage_V = ax.state.u_V;
  s.mode = ax.ctrl->mode();
  s.end_stop = ax.ctrl->end_stop();
  return s;
}

bool XyzStage::all_in_position() const noexcept {
  for (const auto& ax : axes_) {
    if (!ax.ctrl->in_position()) return false;
  }
  return true;
}

}  // namespace mc::motion
