#pragma once
// Shared by the control tests: one default model and its step map (built once: ~0.3 s).

#include "microcobot/motion/step_map.h"
#include "microcobot/stickslip/actuator.h"

namespace mc::motion::test {

inline const stickslip::ActuatorModel& model() {
  static const stickslip::ActuatorModel m{stickslip::StickSlipParams{}};
  return m;
}

inline const StepMap& step_map() {
  static const StepMap map{model()};
  return map;
}

}  // namespace mc::motion::test
