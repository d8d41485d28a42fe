// Robotic and manual control modes (section 4.3.2).
#include <cmath>

#include <gtest/gtest.h>

#include "microcobot/core/error.h"
#include "microcobot/tweezers/control_modes.h"

namespace mc::tweezers {
namespace {

TEST(RoboticMode, SlaveCopiesScaledOpeningAndForceComesBack) {
  const TeleTweezParams m;
  const RoboticModeParams p;
  const auto r = simulate_robotic_mode(m, p);
  // Before contact (free motion), the slave's closing is the scaled tweezers' closing.
  for (std::size_t k = 0; k < r.trace.t_s.size(); ++k) {
    if (r.trace.contact_force_N[k] > 0) break;
    if (r.trace.t_s[k] < 0.1) continue;
    const double expected =
        p.slave_opening_m - p.position_scale * (m.static_opening_tip_m - r.trace.master_opening_m[k]);
    EXPECT_NEAR(r.trace.slave_opening_m[k], expected, 0.05 * p.slave_opening_m) << r.trace.t_s[k];
  }
  // The slave grasps the object and the fingers feel the scaled force.
  EXPECT_GT(r.final_slave_force_N, 0.0);
  EXPECT_NEAR(r.final_rendered_force_N, p.force_scale * r.final_slave_force_N, 1e-9);
  EXPECT_LT(r.trace.slave_opening_m.back(), p.object_width_m);
  // Without force feedback the operator closes further (nothing resists): more squeeze.
  RoboticModeParams open = p;
  open.force_scale = 0;
  EXPECT_GT(simulate_robotic_mode(m, open).final_slave_force_N, 1.5 * r.final_slave_force_N);
}

TEST(ManualMode, HoldsTheSetForceAfterTheOperatorRelaxes) {
  const auto r = simulate_manual_mode(TeleTweezParams{}, ManualModeParams{});
  EXPECT_NEAR(r.held_force_N, 1.0, 0.02);
  EXPECT_LT(r.held_force_error_N, 0.05);
  // The operator's fingers push nothing after release.
  EXPECT_NEAR(r.trace.finger_force_N.back(), 0.0, 1e-9);
  // A plain tweezers (no force loop) drops the object once the fingers relax.
  ManualModeParams plain;
  plain.hold = false;
  const auto d = simulate_manual_mode(TeleTweezParams{}, plain);
  EXPECT_EQ(d.held_force_N, 0.0);
  // A set force above what the motor can give (2.2 mN m) is not reached.
  ManualModeParams strong;
  strong.set_force_N = 5.0;
  EXPECT_LT(simulate_manual_mode(TeleTweezParams{}, strong).held_force_N, 4.0);
}

TEST(ManualMode, RejectsBadParams) {
  ManualModeParams p;
  p.release_s = 0.1;
  EXPECT_THROW(simulate_manual_mode(TeleTweezParams{}, p), InvalidParams);
}

// The object's spring acts on the tip explicitly; a stiffness the plant step cannot
// resolve diverged (exit 4) or held forces hundreds of newtons off (exit 0).
TEST(ManualMode, AnObjectTooStiffForThePlantStepIsRefused) {
  const TeleTweezParams mp;
  ManualModeParams p;
  const double k_max = 0.25 * mp.tip_mass_kg * p.plant_rate_Hz * p.plant_rate_Hz;
  for (double k : {1.01 * k_max, 1e308}) {
    p.object_stiffness_N_per_m = k;
    try {
      simulate_manual_mode(mp, p);
      ADD_FAILURE() << "accepted " << k;
    } catch (const InvalidParams& e) {
      EXPECT_EQ(e.field(), "object_stiffness_N_per_m");
    }
  }
  // At the limit the loop still holds its set force (the break starts near 2.4 times it).
  p.object_stiffness_N_per_m = k_max;
  const auto r = simulate_manual_mode(mp, p);
  EXPECT_LT(r.held_force_error_N, 0.05 * p.set_force_N);
}

}  // namespace
}  // namespace mc::tweezers
