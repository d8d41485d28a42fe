#pragma once
/// @file
/// The vision positioner's parameters (`stage.vision` of the platform's configuration; the
/// positioner itself: vision_positioner.h).

#include "microcobot/vision/template_tracker.h"
#include "microcobot/vision/visual_servo.h"

namespace mc::perception {

struct VisionPositionerParams {
  vision::VisualServoParams servo;
  /// The tips' tracker: high-passed (the glow and edges of a part 150 um below move under the
  /// templates; live, a click with a part's edge under a tip rested 0.12-0.32 um off without,
  /// 0.02-0.09 um with: docs/benchmarks.md).
  vision::TrackerParams tracker = vision::tool_tip_tracker_params();
  /// A run ends this long before the next exposure it must not be seen in [s]: the loop applies
  /// a command within one operator tick (1 ms) of its issue.
  double margin_s = 3e-3;
  /// A run shorter than this is not worth starting (a stick-slip period at 1 kHz is 1 ms) [s].
  double min_run_s = 4e-3;
  /// In position after this many servoed frames in a row with the servo's predicted error within
  /// in_position_m: the stage then rests until the error leaves the servo's converged window
  /// (0.3 um). Half the window: the tips' tracking agrees with the truth within ~0.06 um at 5x
  /// away from other structures, so a rest within 0.15 um is within 0.3 um of the goal.
  int settle_frames = 2;
  double in_position_m = 0.15e-6;
  /// In position, too, after this many servoed frames in a row within the converged window that
  /// never came within in_position_m: the last hundred nanometres are a stick-slip axis' finest
  /// steps, whose sign near the break-away amplitude is a gamble (holding a part, the stage hunted
  /// 0.15-0.25 um off at every third frame for seconds, each run swinging the tips by up to
  /// 1.2 um). 15 frames: half a second at 30 Hz.
  int max_hunt_frames = 15;

  template <class V>
  void visit(V& v) {
    v("servo", servo);
    v("tracker", tracker);
    v("margin_s", margin_s);
    v("min_run_s", min_run_s);
    v("settle_frames", settle_frames);
    v("in_position_m", in_position_m);
    v("max_hunt_frames", max_hunt_frames);
  }
  /// Throws mc::InvalidParams naming the field.
  void validate() const;
};

}  // namespace mc::perception
