#pragma once
/// @file
/// Every parameter of one controlled stick-slip axis: the model, its step map, the position
/// sensor, the controllers and the motion limits. The keys of `microcobot control params --json`,
/// which `--params FILE.yaml` and the Python module's control.params() accept.

#include "microcobot/motion/baseline_position.h"
#include "microcobot/motion/iterative_learning.h"
#include "microcobot/motion/path_generator.h"
#include "microcobot/motion/position_controller.h"
#include "microcobot/motion/position_sensor.h"
#include "microcobot/motion/reference.h"
#include "microcobot/motion/setpoint_stream.h"
#include "microcobot/motion/step_map.h"
#include "microcobot/motion/tracking_controller.h"
#include "microcobot/motion/velocity_controller.h"
#include "microcobot/stickslip/stickslip_params.h"

namespace mc::motion {

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
  LearningParams learning;      ///< iterative learning of a repeated reference

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
    v("learning", learning);
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
    learning.validate();
  }
};

}  // namespace mc::motion
