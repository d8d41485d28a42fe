#pragma once
/// @file
/// The Cartesian XYZ stage of thesis §2.3 (Fig. 2.4): three identical stick-slip axes (12 mm
/// stroke each, 0.1 nm sensors) driven by one controller object: one ActuatorModel (immutable,
/// shared), three ActuatorStates, three sensors and three hybrid position controllers. tick()
/// runs one control period: each axis is measured, its controller updated, and the axis stepped
/// at the model's own step until the next tick. End stops are detected (no progress while
/// stepping) and reported per axis without integrator wind-up; emergency_stop() brings every
/// axis to 0 V in the very next model step. tick() never allocates.

#include <array>
#include <memory>

#include "microcobot/motion/position_controller.h"
#include "microcobot/motion/position_sensor.h"
#include "microcobot/stickslip/actuator.h"

namespace mc::motion {

enum class Axis { kX = 0, kY = 1, kZ = 2 };
Axis parse_axis(const std::string& name);  ///< "x" | "y" | "z", else UsageError
std::string to_string(Axis a);

struct XyzStageParams {
  PositionControlParams control;
  PositionSensorParams sensor;

  template <class V>
  void visit(V& v) {
    v("control", control);
    v("sensor", sensor);
  }
  void validate() const {
    control.validate();
    sensor.validate();
  }
};

struct AxisStatus {
  double position_m = 0.0;  ///< true slider position (simulation)
  double measured_m = 0.0;  ///< last sensor reading
  double voltage_V = 0.0;
  AxisMode mode = AxisMode::kIdle;
  bool end_stop = false;
};

class XyzStage {
 public:
  /// `model` and `map` must outlive the stage (one model and one map serve the three axes).
  XyzStage(const stickslip::ActuatorModel& model, const StepMap& map, const XyzStageParams& p = {});

  void set_target(Axis a, double target_m) noexcept;
  /// Places an axis at `position_m` at rest (simulation set-up).
  void place(Axis a, double position_m);
  /// One control period (1 / control.control_rate_Hz). Never allocates.
  void tick() noexcept;
  /// Every axis to 0 V at once; the axes stay stopped until their next set_target().
  void emergency_stop() noexcept;

  AxisStatus status(Axis a) const noexcept;
  bool all_in_position() const noexcept;
  double time_s() const noexcept { return t_; }
  /// True once an axis diverged (every axis was then stopped at 0 V).
  bool fault() const noexcept { return diverged_; }
  double tick_s() const noexcept { return static_cast<double>(ratio_) * model_.dt_s(); }
  const stickslip::ActuatorState& state(Axis a) const noexcept {
    return axes_[static_cast<std::size_t>(a)].state;
  }

 private:
  struct AxisUnit {
    stickslip::ActuatorState state;
    PositionSensor sensor;
    std::unique_ptr<PositionController> ctrl;
    double measured = 0.0;
    double u = 0.0;
  };
  const stickslip::ActuatorModel& model_;
  XyzStageParams p_;
  std::array<AxisUnit, 3> axes_;
  int ratio_ = 1;
  double t_ = 0.0;
  bool diverged_ = false;
};

}  // namespace mc::motion
