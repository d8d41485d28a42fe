#include "microcobot/microworld/piezo_bender.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "microcobot/core/error.h"

namespace mc::microworld {
namespace {

// The bender driven slowly along a voltage path (the mode settled: quasi-static), its deflection
// at each point.
std::vector<double> slow_sweep(const PiezoBenderParams& p, PiezoBenderState& s, double from_V, double to_V,
                               int points) {
  std::vector<double> y;
  for (int k = 0; k <= points; ++k) {
    step_bender(p, s, from_V + (to_V - from_V) * k / points, 2e-3);
    y.push_back(s.y_m);
  }
  return y;
}

TEST(PiezoBender, TheFullCycleIsAHysteresisLoopAboutTheStaticGain) {
  PiezoBenderParams p;
  p.creep_per_decade = 0.0;  // the static loop alone
  PiezoBenderState s;
  slow_sweep(p, s, 0.0, -150.0, 300);  // onto the major loop
  const std::vector<double> up = slow_sweep(p, s, -150.0, 150.0, 600);
  const std::vector<double> down = slow_sweep(p, s, 150.0, -150.0, 600);
  double widest = 0.0;
  for (std::size_t k = 0; k < up.size(); ++k) widest = std::max(widest, down[up.size() - 1 - k] - up[k]);
  const double stroke = up.back() - up.front();
  // The stroke is d times the swing less the hysteresis' share; the loop opens by 10-20 % of it.
  EXPECT_NEAR(stroke, 300.0 * p.gain_m_V, 0.25 * 300.0 * p.gain_m_V);
  EXPECT_GT(widest / stroke, 0.12);
  EXPECT_LT(widest / stroke, 0.17);
  std::printf("bender loop: stroke %.1f um, widest opening %.1f um (%.1f %%)\n", 1e6 * stroke, 1e6 * widest,
              100.0 * widest / stroke);
  // Descending lies above ascending (a counter-clockwise loop in (u, y)).
  EXPECT_GT(down[300], up[300]);
}

TEST(PiezoBender, AStepCreepsByItsShareEachDecadeOfTime) {
  PiezoBenderParams p;
  p.bw_A_m_V = 0.0;  // no hysteresis: the creep alone
  PiezoBenderState s;
  const double u = 100.0;
  // Holds the step for `t_s` more; the deflection then.
  auto at = [&](double t_s) {
    double t = 0.0;
    while (t < t_s) {
      step_bender(p, s, u, 1e-3);
      t += 1e-3;
    }
    return s.y_m;
  };
  const double y01 = at(0.1);  // t = 0.1 s
  const double y1 = at(0.9);   // t = 1 s
  const double y10 = at(9.0);  // t = 10 s
  const double per_decade = (y10 - y1) / (p.gain_m_V * u);
  std::printf("bender creep from 1 s to 10 s after a step: %.2f %% of d u\n", 100.0 * per_decade);
  EXPECT_NEAR(per_decade, p.creep_per_decade, 0.5 * p.creep_per_decade) << y01 << " " << y1 << " " << y10;
  EXPECT_GT(y1, y01);
}

TEST(PiezoBender, AStepRingsAtTheFirstMode) {
  PiezoBenderParams p;
  p.bw_A_m_V = 0.0;
  p.creep_per_decade = 0.0;
  PiezoBenderState s;
  step_bender(p, s, 10.0, 1e-6);  // a step
  std::vector<double> t_cross;
  double prev = s.y_m - 10.0 * p.gain_m_V;
  for (int k = 1; k < 40000; ++k) {  // 40 ms at 1 us: the ringing decays by e^-12
    step_bender(p, s, 10.0, 1e-6);
    const double e = s.y_m - 10.0 * p.gain_m_V;
    if (prev < 0.0 && e >= 0.0) t_cross.push_back(k * 1e-6);
    prev = e;
  }
  ASSERT_GE(t_cross.size(), 5u);
  const double period = (t_cross[4] - t_cross[0]) / 4.0;
  EXPECT_NEAR(1.0 / period, p.mode_frequency_Hz * std::sqrt(1.0 - p.mode_damping * p.mode_damping), 20.0);
  EXPECT_NEAR(s.y_m, 10.0 * p.gain_m_V, 1e-9);  // settled
}

TEST(PiezoBender, TheDriveIsClampedToItsRangeAndSettledStartsAtRest) {
  PiezoBenderParams p;
  PiezoBenderState s = settled_bender(p, 500.0);
  EXPECT_EQ(s.u_V, p.max_voltage_V);
  const double y = s.y_m;
  step_bender(p, s, 500.0, 0.1);
  EXPECT_NEAR(s.y_m, y, 1e-3 * y);  // at rest: neither the mode nor the creep moves it
}

TEST(PiezoBender, ParametersAreRefusedNamingTheirKey) {
  PiezoBenderParams p;
  p.bw_gamma_1_V = 1.0;  // beyond beta: an unbounded loop
  try {
    p.validate("gripper.align");
    FAIL();
  } catch (const InvalidParams& e) {
    EXPECT_NE(std::string(e.what()).find("gripper.align.bw_gamma_1_V"), std::string::npos) << e.what();
  }
  p = {};
  p.mode_frequency_Hz = 0.0;
  EXPECT_THROW(p.validate(), InvalidParams);
}

}  // namespace
}  // namespace mc::microworld
