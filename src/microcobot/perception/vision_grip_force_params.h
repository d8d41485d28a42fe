#pragma once
/// @file
/// The live force-by-vision gauge's parameters (`vision_force` of the platform's configuration;
/// the gauge itself: vision_grip_force.h).

#include "microcobot/vision/template_tracker.h"

namespace mc::perception {

struct VisionGripForceParams {
  /// Measure the grip force from the camera's frames whenever the camera forms them (a
  /// console watching, a recording, vision positioning).
  bool enabled = true;
  /// Tare on the first frame of a scene: the gripper starts open with nothing between its
  /// fingers (false: the gauge waits for the operator's tare).
  bool tare_at_start = true;
  /// The tips' tracker, as the positioner's (vision_positioner_params.h).
  vision::TrackerParams tracker = vision::tool_tip_tracker_params();

  template <class V>
  void visit(V& v) {
    v("enabled", enabled);
    v("tare_at_start", tare_at_start);
    v("tracker", tracker);
  }
  /// Throws mc::InvalidParams naming the field (the tracker's under tracker.*).
  void validate() const;
};

}  // namespace mc::perception
