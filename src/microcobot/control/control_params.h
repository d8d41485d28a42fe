#pragma once
/// @file
/// Every parameter of one controlled stick-slip axis: the model, its step map, the position
/// sensor, the controllers and the motion limits. The keys of `microcobot control params --json`,
/// which `--params FILE.yaml` and the Python module's control.params() accept.

#include "microcobot/control/baseline_position.h"
#include "microcobot/control/path_generator.h"
#include "microcobot/control/position_controller.h"
#include "microcobot/control/position_sensor.h"
#include "microcobot/control/reference.h"
#include "microcobot/control/setpoint_stream.h"
#include "microcobot/control/step_map.h"
#include "microcobot/control/tracking_controller.h"
#include "microcobot/control/velocity_controller.h"
#include "microcobot/stickslip/stickslip_params.h"

namespace mc::control {

struct ControlParams {
  stickslip::StickSlipParams model;
  StepMapParams step_map;
  PositionSensorParams sensor;
  VelocityControlParams velocity;
  PositionControlParams position;
  BaselinePositionParams baseline;
  MotionLimits limits;
  TrackingParams tracking;      ///< the tracking controller
  SetpointStreamParams stream;  ///< setpoint streaming
  PathLimits path;              ///< 3-D paths (jerk; velocity/acceleration from limits)

  template <class V>
  void visit(V& v) {
    v("model", model);
    v("step_map", step_map);
    v("sensor", sensor);
    v("velocity", velocity);
    v("position", position);
    v("baseline", baseline);
    v("limits", limits);
    v("tracking", tracking);
    v("stream", stream);
    v("path", path);
  }
  void validate() const {
    model.validate();
    step_map.validate();
    sensor.validate();
    velocity.validate();
    position.validate();
    baseline.validate();
    limits.validate();
    tracking.validate();
    stream.validate();
    path.validate();
  }
};

}  // namespace mc::control
