#pragma once
/// @file
/// All parameters of the `tweezers` command group in one file: the keys that
/// `microcobot tweezers params --json` prints and `--params FILE.yaml` accepts.

#include "microcobot/tweezers/bandwidth.h"
#include "microcobot/tweezers/control_modes.h"
#include "microcobot/tweezers/teletweez.h"
#include "microcobot/tweezers/virtual_cube.h"

namespace mc::tweezers {

struct TweezersConfig {
  TeleTweezParams model;
  BandwidthIdentParams identify;
  VirtualCubeParams cube;
  RoboticModeParams robotic;
  ManualModeParams manual;
  template <class V>
  void visit(V& v) {
    v("model", model);
    v("identify", identify);
    v("cube", cube);
    v("robotic", robotic);
    v("manual", manual);
  }
  void validate() const {
    model.validate();
    identify.validate();
    cube.validate();
    robotic.validate();
    manual.validate();
  }
};

}  // namespace mc::tweezers
