// One abrupt edge on a stuck slider (studies/edge_dip.h): a fall slow enough to be no edge
// carries the slider back with the PE, a fast one leaves it in place but for its dip; the
// unloading keeps the slider near its place; the dip scales with the edge's drop; bad cases are
// refused naming their field; the power fit recovers a known law.
#include "microcobot/studies/edge_dip.h"

#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "microcobot/core/error.h"

namespace mc::studies {
namespace {

const stickslip::ActuatorModel& model() {
  static const stickslip::ActuatorModel m{stickslip::StickSlipParams{}};
  return m;
}

TEST(EdgeDip, AFallTooSlowToSlipCarriesTheSliderBackWithThePe) {
  EdgeCase e;
  e.slew_V_s = 200.0;  // 68 V over 0.34 s: the slider sticks all the way down
  e.window_s = 0.4;
  const EdgeDip d = run_edge(model(), e);
  // Back by the PE's stroke (g dV, within the hysteresis' share of it).
  EXPECT_NEAR(-d.net_m, d.pe_travel_m, 0.25 * d.pe_travel_m);
  EXPECT_GT(d.dip_m, 0.75 * d.pe_travel_m);
}

TEST(EdgeDip, TheAmplifiersEdgeUnloadedKeepsTheSliderNearItsPlace) {
  EdgeCase e;  // the tracking controller's edge: 68.38 V at 1 V/us
  const EdgeDip held = run_edge(model(), e);
  e.unload_V = 49.16;
  const EdgeDip unloaded = run_edge(model(), e);
  // The slip keeps the slider from following the PE's 1 um back; the unloading releases the
  // contact's strain before it springs the slider back.
  EXPECT_LT(unloaded.dip_m, 0.5 * held.dip_m);
  EXPECT_LT(std::abs(unloaded.net_m), 0.2 * unloaded.pe_travel_m);
  EXPECT_LT(std::abs(unloaded.net_m), std::abs(held.net_m));
}

TEST(EdgeDip, TheDipGrowsInProportionToTheDropNotAsItsSquare) {
  EdgeCase e;
  std::vector<double> drops, dips;
  for (double v : {12.0, 24.0, 48.0, 96.0}) {
    e.drop_V = v;
    drops.push_back(v);
    dips.push_back(run_edge(model(), e).dip_m);
  }
  const PowerFit f = fit_power(drops, dips);
  EXPECT_EQ(f.points, 4);
  EXPECT_NEAR(f.exponent, 1.0, 0.25) << "a drag during the slip would give ~2, pre-sliding ~0";
}

TEST(EdgeDip, AnEdgeSplitHalfTheContactModesPeriodApartRingsLessButSlipsFurther) {
  EdgeCase e;
  e.unload_V = 49.16;  // the tracking controller's unloaded edge
  const EdgeDip one = run_edge(model(), e);
  e.split_delay_s = 0.5 / 1640.0;  // half the period of the contact's stiff mode
  const EdgeDip shaped = run_edge(model(), e);
  e.split_delay_s = 1.0 / 1640.0;  // a whole period: the halves' ringings add
  const EdgeDip in_phase = run_edge(model(), e);
  // The shaper cancels the ringing: the overshoot beyond the rest shrinks, and the dip with it
  // against the whole period's split.
  EXPECT_LT(shaped.overshoot_m, 0.5 * one.overshoot_m);
  EXPECT_LT(shaped.dip_m, in_phase.dip_m);
  // Each half slips on its own: the slider comes to rest further back than after one edge.
  EXPECT_LT(shaped.net_m, one.net_m - 50e-9);
  EXPECT_NEAR(shaped.overshoot_m, shaped.dip_m + shaped.net_m, 1e-15);
}

TEST(EdgeDip, BadCasesAreRefusedNamingTheirField) {
  const auto refused = [](EdgeCase e, const std::string& field) {
    try {
      run_edge(model(), e);
    } catch (const InvalidInput& err) {
      EXPECT_NE(std::string(err.what()).find(field), std::string::npos) << err.what();
      return true;
    }
    return false;
  };
  EdgeCase e;
  e.drop_V = 120.0;
  EXPECT_TRUE(refused(e, "edge.drop_V"));
  e = {};
  e.slew_V_s = std::nan("");
  EXPECT_TRUE(refused(e, "edge.slew_V_s"));
  e = {};
  e.unload_V = -1.0;
  EXPECT_TRUE(refused(e, "edge.unload_V"));
  e = {};
  e.slew_V_s = 100.0;  // a 0.68 s fall does not fit in the 10 ms window
  EXPECT_TRUE(refused(e, "edge.window_s"));
  e = {};
  e.split_delay_s = 10e-6;  // shorter than a half edge (34 us)
  EXPECT_TRUE(refused(e, "edge.split_delay_s"));
}

TEST(EdgeDip, ThePowerFitRecoversAKnownLawAndNeedsTwoPoints) {
  const std::vector<double> x{1.0, 2.0, 5.0, 10.0};
  std::vector<double> y;
  for (double v : x) y.push_back(3e-7 * std::pow(v, 1.7));
  const PowerFit f = fit_power(x, y);
  EXPECT_NEAR(f.exponent, 1.7, 1e-12);
  EXPECT_NEAR(f.factor, 3e-7, 1e-18);
  EXPECT_TRUE(std::isnan(fit_power({1.0, -2.0}, {1.0, 1.0}).exponent));
}

}  // namespace
}  // namespace mc::studies
