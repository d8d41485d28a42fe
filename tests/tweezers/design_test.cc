// The design calculators of chapter 4 and appendices A, B reproduce the thesis's tables.
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "microcobot/core/error.h"
#include "microcobot/tweezers/actuator_options.h"
#include "microcobot/tweezers/amplifier.h"
#include "microcobot/tweezers/ballscrew.h"
#include "microcobot/tweezers/beam.h"
#include "microcobot/tweezers/piezo_brake.h"
#include "microcobot/tweezers/specs.h"
#include "microcobot/tweezers/transmission.h"
#include "support/test_support.h"

namespace mc::tweezers {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// Table 4.6 with mu = 0.01: (diameter, lead) -> (forward, backward), printed to 2 decimals.
TEST(BallScrew, ReproducesTable46) {
  struct Row {
    double d, forward, backward;
  };
  for (const Row& r : {Row{4e-3, 0.89, 0.87}, Row{3e-3, 0.91, 0.90}}) {
    const auto e = ball_screw_efficiency(r.d, 1e-3, 0.01);
    EXPECT_NEAR(e.forward_efficiency, r.forward, 0.005) << r.d;
    EXPECT_NEAR(e.backward_efficiency, r.backward, 0.005) << r.d;
    EXPECT_NEAR(std::tan(e.lead_angle_rad), 1e-3 / (std::numbers::pi * r.d), 1e-12);
  }
}

TEST(BallScrew, FrictionlessIsLosslessAndBackwardNeverExceedsForward) {
  const double th = lead_angle(4e-3, 1e-3);
  EXPECT_DOUBLE_EQ(forward_efficiency(th, 0.0), 1.0);
  EXPECT_DOUBLE_EQ(backward_efficiency(th, 0.0), 1.0);
  for (double mu : {0.005, 0.01, 0.05}) {
    EXPECT_LT(backward_efficiency(th, mu), forward_efficiency(th, mu));
    EXPECT_GT(backward_efficiency(th, mu),
              0.0);  // erratum 5 (docs/errata.md): the printed B.9 would be negative
  }
  // Self-locking when the friction angle exceeds the lead angle.
  EXPECT_EQ(backward_efficiency(th, 0.2), 0.0);
  EXPECT_GT(forward_efficiency(th, 0.2), 0.0);
  EXPECT_THROW(lead_angle(-1, 1e-3), InvalidParams);
}

TEST(BallScrew, AxialForceEq44) {
  EXPECT_NEAR(axial_force(2.2e-3, 1e-3, 0.89), 12.3, 0.01);
  // Force scales with torque and inversely with lead.
  EXPECT_NEAR(axial_force(4.4e-3, 2e-3, 0.89), 12.3, 0.01);
  EXPECT_THROW(axial_force(1e-3, 1e-3, 1.5), InvalidParams);
}

TEST(Transmission, FingerForceAndPreloadSection442) {
  const double fa = axial_force(2.2e-3, 1e-3, 0.89);
  const double fy = finger_force(fa, 63 * kDeg, 0.9);
  EXPECT_GT(fy, 2.0);  // "the maximum haptic force F_Y can be from 2 to 3 N"
  EXPECT_LT(fy, 3.0);
  EXPECT_NEAR(required_axial_force(fy, 63 * kDeg, 0.9), fa, 1e-9);
  const double preload = min_preload(1.75, 63 * kDeg);
  EXPECT_NEAR(preload, 3.9, 0.05);  // "must be greater than 3.9 N"
  EXPECT_GT(preload, 1.75);
  EXPECT_THROW(finger_force(1, 95 * kDeg, 0.9), InvalidParams);
}

TEST(Specs, Eq41) {
  EXPECT_NEAR(stiffness_force(250, 7e-3), 1.75, 1e-12);
  EXPECT_NEAR(TweezersSpecs{}.min_force_N(), 1.75, 1e-12);
}

// Table 4.5: L, dL, e, a -> 2 da (mm), ratio.
TEST(Amplifier, ReproducesTable45) {
  struct Row {
    double l, dl, a, expansion_mm, ratio;
  };
  for (const Row& r : {Row{54e-3, 60e-6, 5.5e-3, 0.34, 5.7}, Row{107e-3, 120e-6, 7e-3, 0.97, 8.0},
                       Row{58e-3, 60e-6, 7e-3, 0.29, 4.8}, Row{111e-3, 120e-6, 7e-3, 1.0, 8.3}}) {
    const auto res = amplifier_expansion(r.l, r.dl, 5e-3, r.a);
    EXPECT_NEAR(res.transverse_expansion_m * 1e3, r.expansion_mm, 0.006) << r.l;
    EXPECT_NEAR(res.ratio, r.ratio, 0.1) << r.l;
  }
}

TEST(Amplifier, MonotoneAsEqA9ToA11) {
  const auto base = amplifier_expansion(60e-3, 60e-6, 5e-3, 6e-3).transverse_expansion_m;
  EXPECT_LT(amplifier_expansion(60e-3, 60e-6, 5e-3, 7e-3).transverse_expansion_m, base);  // A.9
  EXPECT_GT(amplifier_expansion(60e-3, 80e-6, 5e-3, 6e-3).transverse_expansion_m, base);  // A.10
  EXPECT_GT(amplifier_expansion(80e-3, 60e-6, 5e-3, 6e-3).transverse_expansion_m, base);  // A.11
  EXPECT_THROW(amplifier_expansion(1e-3, 2e-3, 0, 1e-3), InvalidParams);
}

TEST(PiezoBrake, Eq42And43) {
  EXPECT_NEAR(piezo_push_force(1000, 0.85), 150, 1e-9);
  EXPECT_NEAR(piezo_block_force(1000, 0.85, 0.1, 0.5), 7.5, 1e-9);
  EXPECT_THROW(piezo_push_force(1000, 1.2), InvalidParams);
}

// Table 3.1: 20 cm beam, 5 x 5 mm^2.
TEST(Beam, ReproducesTable31) {
  struct Row {
    const char* name;
    double hz;
  };
  for (const Row& r :
       {Row{"cast iron", 276}, Row{"stainless steel", 286}, Row{"aluminum", 288}, Row{"carbon-fiber", 611}}) {
    const auto m = find_material(r.name);
    ASSERT_TRUE(m) << r.name;
    EXPECT_NEAR(beam_natural_frequency(m->young_Pa, m->density_kg_m3, 0.2, 5e-3), r.hz, 1.0) << r.name;
  }
  EXPECT_FALSE(find_material("unobtainium"));
  // Scaling of eq. 3.2: f ~ s / L^2 and f_n ~ n^2.
  const double f1 = beam_natural_frequency(200e9, 7850, 0.2, 5e-3);
  EXPECT_NEAR(beam_natural_frequency(200e9, 7850, 0.1, 5e-3), 4 * f1, 1e-9 * f1);
  EXPECT_NEAR(beam_natural_frequency(200e9, 7850, 0.2, 10e-3), 2 * f1, 1e-9 * f1);
  EXPECT_NEAR(beam_natural_frequency(200e9, 7850, 0.2, 5e-3, 2), 4 * f1, 1e-9 * f1);
}

TEST(ActuatorOptions, Table47SelectsMotorAndBallScrew) {
  const auto rows = evaluate_actuator_options();
  ASSERT_EQ(rows.size(), 5u);
  EXPECT_FALSE(rows[0].meets_supply);  // ERF needs > 100 V
  EXPECT_TRUE(rows[1].meets_supply);
  EXPECT_FALSE(rows[1].meets_force);  // MRF below 1.75 N
  ASSERT_TRUE(rows[3].force_N);
  EXPECT_NEAR(*rows[3].force_N, 7.5, 1e-9);
  EXPECT_TRUE(rows[3].meets_force);
  ASSERT_TRUE(rows[4].force_N);
  EXPECT_GT(*rows[4].force_N, 1.75);
  int selected = 0;
  for (const auto& r : rows) selected += r.selected ? 1 : 0;
  EXPECT_EQ(selected, 1);
  EXPECT_TRUE(rows[4].selected);
  // A weaker motor that cannot reach the spec is no longer selected: the brake is.
  OptionFigures weak;
  weak.motor_torque_Nm = 0.5e-3;
  const auto rows2 = evaluate_actuator_options({}, weak);
  EXPECT_FALSE(rows2[4].meets_force);
  EXPECT_TRUE(rows2[3].selected);
}

TEST(DesignCli, JsonOutputs) {
  auto r = test::run_cli(
      {"design", "ballscrew", "--diameter", "0.004", "--lead", "0.001", "--mu", "0.01", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  EXPECT_NEAR(j["forward_efficiency"].get<double>(), 0.89, 0.005);
  EXPECT_NEAR(j["backward_efficiency"].get<double>(), 0.87, 0.005);
  EXPECT_TRUE(j.contains("lead_angle_rad"));

  r = test::run_cli(
      {"design", "actuator", "--torque", "0.0022", "--lead", "0.001", "--efficiency", "0.89", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NEAR(nlohmann::json::parse(r.out)["axial_force_N"].get<double>(), 12.3, 0.01);

  r = test::run_cli(
      {"design", "transmission", "--alpha", "63", "--eta", "0.9", "--axial-force", "12.3", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  j = nlohmann::json::parse(r.out);
  EXPECT_NEAR(j["min_preload_N"].get<double>(), 3.85, 0.01);
  EXPECT_NEAR(j["finger_force_N"].get<double>(), 0.9 * 6.15 / std::tan(63 * kDeg), 1e-6);

  r = test::run_cli({"design", "stiffness-force", "--stiffness", "250", "--opening", "0.007", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NEAR(nlohmann::json::parse(r.out)["force_N"].get<double>(), 1.75, 1e-9);

  r = test::run_cli({"design", "amplifier", "--length", "0.111", "--stroke", "120e-6", "--e", "0.005", "--a",
                     "0.007", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  j = nlohmann::json::parse(r.out);
  EXPECT_NEAR(j["transverse_expansion_m"].get<double>(), 1.0e-3, 6e-6);
  EXPECT_NEAR(j["ratio"].get<double>(), 8.3, 0.1);

  r = test::run_cli({"design", "piezo-brake", "--max-force", "1000", "--travel-used", "0.85", "--mu", "0.1",
                     "--geometry", "0.5", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NEAR(nlohmann::json::parse(r.out)["block_force_N"].get<double>(), 7.5, 1e-9);

  r = test::run_cli(
      {"design", "beam", "--material", "carbon fiber", "--length", "0.2", "--side", "0.005", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NEAR(nlohmann::json::parse(r.out)["first_mode_Hz"].get<double>(), 611, 1);
  r = test::run_cli({"design", "beam", "--young", "70e9", "--density", "2700", "--length", "0.2", "--side",
                     "0.005", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NEAR(nlohmann::json::parse(r.out)["first_mode_Hz"].get<double>(), 288, 1);

  r = test::run_cli({"design", "options", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["options"].size(), 5u);
  EXPECT_TRUE(j["options"][4]["selected"].get<bool>());
  EXPECT_NEAR(j["min_force_N"].get<double>(), 1.75, 1e-9);
}

TEST(DesignCli, BadFlagsExitWithUsageOrInvalid) {
  EXPECT_EQ(
      test::run_cli({"design", "ballscrew", "--diameter", "-1", "--lead", "0.001", "--mu", "0.01"}).exit_code,
      2);
  EXPECT_EQ(test::run_cli({"design", "ballscrew", "--lead", "0.001", "--mu", "0.01"}).exit_code, 2);
  EXPECT_EQ(test::run_cli({"design", "beam", "--material", "cheese", "--length", "0.2", "--side", "0.005"})
                .exit_code,
            2);
  EXPECT_EQ(test::run_cli({"design", "beam", "--length", "0.2", "--side", "0.005"}).exit_code, 2);
  EXPECT_EQ(test::run_cli({"design", "transmission", "--alpha", "95", "--eta", "0.9", "--axial-force", "1"})
                .exit_code,
            2);
  EXPECT_EQ(test::run_cli(
                {"design", "amplifier", "--length", "0.001", "--stroke", "0.002", "--e", "0", "--a", "0.007"})
                .exit_code,
            3);
}

}  // namespace
}  // namespace mc::tweezers
