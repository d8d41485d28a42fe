// ActuatorModel::at_rest (a parked axis skips its integration): a drive held constant brings the
// model to rest within milliseconds, and a step from a state at rest changes it by less than the
// rest's picometre; a drive edge, or the PE still ringing, is not rest.
#include <gtest/gtest.h>

#include <cmath>

#include "microcobot/stickslip/actuator.h"

namespace mc::stickslip {
namespace {

TEST(ActuatorRest, AHeldDriveComesToRestAndAStepFromRestChangesNothingMeasurable) {
  const ActuatorModel m{StickSlipParams{}};
  ActuatorState s = m.initial_state();
  // A stick-phase ramp to 60 V in 1 ms (the slider follows the PE), then held.
  for (int i = 1; i <= 100; ++i) m.step(s, 0.6 * i);
  EXPECT_FALSE(m.at_rest(s)) << "just stopped: the PE rings";
  int steps = 0;
  while (!m.at_rest(s) && steps < 100000) m.step(s, 60.0), ++steps;
  ASSERT_TRUE(m.at_rest(s));
  std::printf("at rest %.2f ms after the ramp\n", steps * m.dt_s() * 1e3);
  EXPECT_LT(steps * m.dt_s(), 0.05) << "within 50 ms";
  const double x = m.slider_position(s);
  for (int i = 0; i < 10000; ++i) m.step(s, 60.0);  // 0.1 s more, integrated
  EXPECT_NEAR(m.slider_position(s), x, 1e-12);
  EXPECT_TRUE(m.at_rest(s));
  // An edge (a slip) is not rest.
  m.step(s, 0.0);
  EXPECT_FALSE(m.at_rest(s));
}

}  // namespace
}  // namespace mc::stickslip
