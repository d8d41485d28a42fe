// The virtual cube (section 4.5.3): chatter of a stiff sampled wall, its suppression by the lag
// compensator, the chatter criterion on both sides of its boundary, Colgate's bound.
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "microcobot/core/error.h"
#include "microcobot/tweezers/lag_compensator.h"
#include "microcobot/tweezers/virtual_cube.h"
#include "support/counting_allocator.h"

namespace mc::tweezers {
namespace {

VirtualCubeResult run(double k, bool comp) {
  VirtualCubeParams c;
  c.stiffness_N_per_m = k;
  c.compensator = comp;
  return simulate_virtual_cube(TeleTweezParams{}, c);
}

TEST(LagCompensator, UnitStaticGainAttenuatedHighBand) {
  LagCompensator lag(1.0, 10.0, 1000.0);
  EXPECT_NEAR(lag.magnitude(0.01), 1.0, 1e-3);
  EXPECT_NEAR(lag.magnitude(300.0), 0.1, 0.005);
  EXPECT_NEAR(lag.high_frequency_gain(), 0.1, 1e-12);
  // Little phase left above 100 Hz (the thesis's "without phase decrease").
  EXPECT_GT(lag.phase(150.0), -0.1);
  EXPECT_LT(lag.phase(3.0), -0.5);  // the lag lives below 100 Hz
  double y = 0;
  for (int i = 0; i < 5000; ++i) y = lag.process(2.0);
  EXPECT_NEAR(y, 2.0, 1e-6);
  EXPECT_THROW(LagCompensator(10.0, 5.0, 1000.0), InvalidParams);
}

TEST(VirtualCube, SoftWallIsStableAndStatic) {
  const auto r = run(1000, false);
  EXPECT_FALSE(r.chatter);
  EXPECT_GT(r.mean_force_N, 0.1);
  // Statics: the rendered force equals K times the held penetration.
  EXPECT_NEAR(r.wall_force_N.back(), 1000 * r.penetration_m.back(), 1e-12);
  EXPECT_LT(r.oscillation_rms_N, 0.01 * r.mean_force_N);
  // The tips stop near the cube: opening ~ width - 2 * penetration.
  EXPECT_NEAR(r.opening_m.back(), 6e-3 - 2 * r.penetration_m.back(), 2e-4);
}

TEST(VirtualCube, StiffWallChattersWithoutCompensatorNotWith) {
  const auto bare = run(16000, false);
  EXPECT_TRUE(bare.chatter);
  EXPECT_GT(bare.oscillation_rms_N, 0.2 * bare.mean_force_N);
  const auto comp = run(16000, true);
  EXPECT_FALSE(comp.chatter);
  EXPECT_LT(comp.oscillation_rms_N, 0.05 * comp.mean_force_N);
}

TEST(VirtualCube, CriterionOnBothSidesOfTheBoundary) {
  VirtualCubeParams c;
  c.compensator = false;
  const double kmax = max_chatter_free_stiffness(TeleTweezParams{}, c, 500, 2e5, 12);
  EXPECT_GT(kmax, 500);
  EXPECT_LT(kmax, 2e5);
  EXPECT_FALSE(run(0.9 * kmax, false).chatter);
  EXPECT_TRUE(run(1.1 * kmax, false).chatter);
}

TEST(VirtualCube, CompensatorAtLeastDoublesTheStiffness) {
  VirtualCubeParams c;
  c.compensator = false;
  const double bare = max_chatter_free_stiffness(TeleTweezParams{}, c, 500, 1e6, 10);
  c.compensator = true;
  const double comp = max_chatter_free_stiffness(TeleTweezParams{}, c, 500, 1e6, 10);
  EXPECT_GE(comp, 2.0 * bare);
  // A faster loop (less ZOH delay) raises the uncompensated limit.
  c.compensator = false;
  c.control_rate_Hz = 5000;
  EXPECT_GT(max_chatter_free_stiffness(TeleTweezParams{}, c, 500, 1e6, 10), bare);
}

// A wall beyond the loop's Nyquist frequency is refused where the renderer is made
// (1e308 N/m reported no chatter with wall forces of 2e303 N), and the sweep stops below it.
TEST(VirtualCube, AWallBeyondTheLoopsNyquistFrequencyIsRefused) {
  const TeleTweezParams p;
  VirtualCubeParams c;
  c.compensator = false;
  const double k_max = max_renderable_stiffness(p, c);
  EXPECT_NEAR(k_max, tip_mass(p) * std::pow(std::numbers::pi * c.control_rate_Hz, 2), 1e-6 * k_max);
  c.compensator = true;
  EXPECT_NEAR(max_renderable_stiffness(p, c), k_max * c.lag_zero_Hz / c.lag_pole_Hz, 1e-6 * k_max);
  c.compensator = false;
  for (double k : {1.01 * k_max, 1e308}) {
    c.stiffness_N_per_m = k;
    EXPECT_THROW(simulate_virtual_cube(p, c), InvalidParams) << k;
  }
  c.stiffness_N_per_m = 0.99 * k_max;
  EXPECT_NO_THROW(VirtualCubeRenderer(p, c));
  EXPECT_LE(max_chatter_free_stiffness(p, c, 500, 1e12, 4), k_max);
  // The compensator's zero at the rate's Nyquist frequency: named by the rate.
  c.compensator = true;
  c.control_rate_Hz = 2 * c.lag_zero_Hz;
  c.plant_rate_Hz = 20 * c.control_rate_Hz;
  try {
    c.validate();
    ADD_FAILURE() << "accepted";
  } catch (const InvalidParams& e) {
    EXPECT_EQ(e.field(), "control_rate_Hz");
  }
}

TEST(VirtualCube, ColgateBound) {
  const TeleTweezParams p;
  const double b = tip_damping(p);
  EXPECT_NEAR(colgate_stiffness_bound(p, 1000), 2 * b * 1000, 1e-9);
  EXPECT_NEAR(colgate_stiffness_bound(p, 2000), 2 * colgate_stiffness_bound(p, 1000), 1e-9);
  EXPECT_LT(colgate_stiffness_bound(p, 1000, 0.5 * b), colgate_stiffness_bound(p, 1000));
  TeleTweezParams more = p;
  more.motor_damping_N_m_s *= 2;
  EXPECT_GT(tip_damping(more), 1.9 * tip_damping(p) - p.clamping_damping_N_s_per_m);
}

TEST(VirtualCube, RendererUpdateDoesNotAllocate) {
  VirtualCubeRenderer r(TeleTweezParams{}, VirtualCubeParams{});
  double sink = 0;
  {
    test::AllocationGuard guard;
    for (int k = 0; k < 1000; ++k) sink += r.update(r.contact_closing() + 1e-6 * (k % 7));
    EXPECT_EQ(guard.allocations(), 0u);
  }
  EXPECT_LT(sink, 0.0);  // the wall pushes the tips open
  // Torque saturates at the motor's continuous limit.
  EXPECT_NEAR(r.update(1.0), -TeleTweezParams{}.max_torque_N_m, 1e-15);
}

TEST(VirtualCube, RejectsACubeWiderThanTheOpening) {
  VirtualCubeParams c;
  c.cube_width_m = 12e-3;
  EXPECT_THROW(simulate_virtual_cube(TeleTweezParams{}, c), InvalidParams);
}

}  // namespace
}  // namespace mc::tweezers
