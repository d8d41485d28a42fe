// The pick-and-place world with the 4-DOF PiezoGripper's vertical benders (thesis §1.1.4):
// misaligned tips hold with the faces' overlap only and tilt the part; the tips touch the
// substrate with their benders' stiffness; level tips grip as the closing model alone.
#include <cmath>

#include <gtest/gtest.h>

#include "microcobot/core/error.h"
#include "microcobot/microworld/pick_place_world.h"
#include "support/counting_allocator.h"

namespace mc::microworld {
namespace {

constexpr double kStep = 1e-3;

PickPlaceParams misaligned(double dz_m) {
  PickPlaceParams p;
  p.gripper.tip_misalignment_m = dz_m;
  return p;
}

// Straight line in 1 um steps, opening command and align drives fixed.
PickPlaceOutput travel(const PickPlaceWorld& w, PickPlaceState& s, Eigen::Vector3d& at,
                       const Eigen::Vector3d& to, double opening, const AlignDrives& align = {}) {
  PickPlaceOutput out;
  const int n = std::max(1, static_cast<int>((to - at).norm() / 1e-6));
  const Eigen::Vector3d from = at;
  for (int i = 1; i <= n; ++i) {
    at = from + (to - from) * (static_cast<double>(i) / n);
    out = w.step(s, at, opening, kStep, 0.0, align);
  }
  return out;
}

PickPlaceOutput wait(const PickPlaceWorld& w, PickPlaceState& s, const Eigen::Vector3d& at, double opening,
                     double t_s, const AlignDrives& align = {}) {
  PickPlaceOutput out;
  for (double t = 0.0; t < t_s; t += kStep) out = w.step(s, at, opening, kStep, 0.0, align);
  return out;
}

// Comes down round the 300 um part, squeezes it to `closed` and lifts 200 um: whether it came up.
bool lifts(const PickPlaceParams& p, double closed, PickPlaceOutput* grip = nullptr) {
  const PickPlaceWorld w{p};
  auto s = w.initial_state();
  Eigen::Vector3d g(0, 0, 1e-3);
  travel(w, s, g, {0, 0, 50e-6}, 500e-6);
  const PickPlaceOutput squeezed = wait(w, s, g, closed, 0.1);
  if (grip != nullptr) *grip = squeezed;
  travel(w, s, g, {0, 0, 250e-6}, closed);
  return s.phase == PartPhase::kGrasped;
}

// The largest substrate pull-off (the pull the grip must beat to lift the part) under which the
// grip at `closed` still lifts it, by bisection to 0.1 uN.
double largest_pull_held_N(double dz_m, double closed) {
  double lo = 0.0, hi = 200e-6;
  while (hi - lo > 0.1e-6) {
    PickPlaceParams p = misaligned(dz_m);
    p.substrate_pulloff_N = 0.5 * (lo + hi);
    (lifts(p, closed) ? lo : hi) = p.substrate_pulloff_N;
  }
  return lo;
}

TEST(PickPlaceBenders, LevelTipsHoldWithTheFullFrictionAndDoNotTiltThePart) {
  PickPlaceOutput grip;
  const PickPlaceParams p;
  ASSERT_TRUE(lifts(p, 260e-6, &grip));
  // k (w - o) / 2 = 1 mN of grip, held with 2 mu F_grip: the closing model's figure, exactly.
  EXPECT_NEAR(grip.grip_force_N, 1e-3, 1e-9);
  EXPECT_DOUBLE_EQ(grip.holding_force_N, 2.0 * p.finger_friction * grip.grip_force_N);
  EXPECT_DOUBLE_EQ(grip.tip_misalignment_m, 0.0);
  const PickPlaceWorld w{p};
  auto s = w.initial_state();
  Eigen::Vector3d g(0, 0, 1e-3);
  travel(w, s, g, {0, 0, 50e-6}, 500e-6);
  wait(w, s, g, 260e-6, 0.1);
  const auto out = travel(w, s, g, {0, 0, 250e-6}, 260e-6);
  ASSERT_EQ(s.phase, PartPhase::kGrasped);
  EXPECT_DOUBLE_EQ(s.part_tilt_rad, 0.0);
  EXPECT_DOUBLE_EQ(out.tips.contact_N[0] + out.tips.contact_N[1], 0.0);
}

TEST(PickPlaceBenders, MisalignedTipsHoldWithTheFacesOverlapAndTiltTheLiftedPart) {
  const PickPlaceParams p = misaligned(20e-6);
  const PickPlaceWorld w{p};
  auto s = w.initial_state();
  Eigen::Vector3d g(0, 0, 1e-3);
  travel(w, s, g, {0, 0, 50e-6}, 500e-6);
  const auto squeezed = wait(w, s, g, 260e-6, 0.1);
  EXPECT_NEAR(squeezed.tip_misalignment_m, 20e-6, 1e-15);
  // F_hold = 2 mu F_grip (1 - |dz| / h_face): 60 % of 0.6 mN.
  EXPECT_NEAR(squeezed.holding_force_N, 2.0 * 0.3 * 1e-3 * (1.0 - 20.0 / 50.0), 1e-9);
  EXPECT_DOUBLE_EQ(squeezed.holding_force_N, holding_force_N(w.fingers(), squeezed.grip_force_N, 20e-6));
  EXPECT_DOUBLE_EQ(s.part_tilt_rad, 0.0);  // on the substrate, the part rests flat
  travel(w, s, g, {0, 0, 250e-6}, 260e-6);
  ASSERT_EQ(s.phase, PartPhase::kGrasped);  // 0.36 mN still beats 36 uN of adhesion and weight
  EXPECT_NEAR(s.part_tilt_rad, std::atan(20.0 / 300.0), 1e-12);
  EXPECT_GT(s.part_tilt_rad, 0.066);  // 3.8 deg
}

TEST(PickPlaceBenders, AGripWithTwentyMicrometresOfMisalignmentSlipsUnderASmallerPull) {
  // A 4 um squeeze grips with 100 uN: level tips hold 2 mu F = 60 uN, tips 20 um apart 60 % of it.
  const double closed = 296e-6, weight = PickPlaceParams{}.part_weight_N();
  const double level = largest_pull_held_N(0.0, closed);
  const double tilted = largest_pull_held_N(20e-6, closed);
  EXPECT_NEAR(level, 60e-6 - weight, 0.2e-6);
  EXPECT_NEAR(tilted, 0.6 * 60e-6 - weight, 0.2e-6);
  // A pull between the two: the level grip lifts the part, the misaligned one slips.
  PickPlaceParams between = misaligned(0.0);
  between.substrate_pulloff_N = 0.5 * (level + tilted);
  EXPECT_TRUE(lifts(between, closed));
  between.gripper.tip_misalignment_m = 20e-6;
  EXPECT_FALSE(lifts(between, closed));
  // Beyond the faces' height nothing holds: not even a light part comes up.
  PickPlaceParams apart = misaligned(60e-6);
  apart.substrate_pulloff_N = 1e-6;
  EXPECT_FALSE(lifts(apart, 260e-6));
}

TEST(PickPlaceBenders, TheLowTipTouchesTheSubstrateWithItsBendersStiffness) {
  const PickPlaceWorld w{misaligned(20e-6)};
  auto s = w.initial_state();
  // Away from the part: finger 0's tip 10 um below the reference, finger 1's 10 um above.
  const Eigen::Vector3d g(1e-3, 1e-3, 5e-6);
  auto out = wait(w, s, g, 500e-6, 0.01);
  EXPECT_NEAR(out.tips.contact_N[0], 50.0 * 5e-6, 1e-12);  // 5 um of press at 50 N/m
  EXPECT_DOUBLE_EQ(out.tips.contact_N[1], 0.0);
  EXPECT_NEAR(out.tips.z_m[0], -5e-6, 1e-15);  // held on the substrate
  EXPECT_NEAR(out.force_on_gripper_N.z(), 250e-6, 1e-12);
  EXPECT_FALSE(s.crashed);
  // Finger 1's align drive lowers its tip onto the substrate too: it presses as read_tips says.
  const AlignDrives down{0.0, -40.0};
  out = wait(w, s, g, 500e-6, 2.0, down);
  const TipReading r = read_tips(w.fingers(), s.fingers, -g.z());
  EXPECT_GT(out.tips.contact_N[1], 20e-6);
  EXPECT_DOUBLE_EQ(out.tips.contact_N[1], r.contact_N[1]);
  EXPECT_NEAR(out.force_on_gripper_N.z(), r.contact_N[0] + r.contact_N[1], 1e-15);
  // Level tips 5 um above the substrate touch nothing.
  const PickPlaceWorld level{PickPlaceParams{}};
  auto ls = level.initial_state();
  out = wait(level, ls, g, 500e-6, 0.01);
  EXPECT_DOUBLE_EQ(out.tips.contact_N[0] + out.tips.contact_N[1], 0.0);
  EXPECT_DOUBLE_EQ(out.force_on_gripper_N.z(), 0.0);
}

TEST(PickPlaceBenders, TheAlignDrivesMoveTheTipsAsTheBenderModelDoes) {
  const PickPlaceWorld w{misaligned(20e-6)};
  auto s = w.initial_state();
  const PiezoBenderParams b = finger_bender(w.fingers(), w.fingers().align, 1);
  PiezoBenderState alone;
  const Eigen::Vector3d g(1e-3, 1e-3, 500e-6);
  PickPlaceOutput out;
  for (int i = 0; i < 3000; ++i) {
    out = w.step(s, g, 500e-6, kStep, 0.0, {0.0, -20.0});
    step_bender(b, alone, -20.0, kStep);
  }
  EXPECT_DOUBLE_EQ(out.tip_misalignment_m, 20e-6 + alone.y_m);
  // About 1 um/V less the hysteresis' share: the drive took out most of the 20 um.
  EXPECT_LT(std::abs(out.tip_misalignment_m), 6e-6);
  EXPECT_GT(s.fingers.align[1].u_V, -20.0 - 1e-12);
}

TEST(PickPlaceBenders, SteppingWithTheAlignDrivesNeverAllocatesAndBadParamsAreNamed) {
  const PickPlaceWorld w{misaligned(20e-6)};
  auto s = w.initial_state();
  std::size_t n = 0;
  {
    test::AllocationGuard guard;
    for (int i = 0; i < 2000; ++i)
      w.step(s, Eigen::Vector3d(0, 0, 50e-6 + 1e-7 * i), 260e-6, 1e-4, 0.0, {0.0, -0.01 * i});
    n = guard.allocations();
  }
  EXPECT_EQ(n, 0u);
  PickPlaceParams bad = misaligned(1e-3);
  try {
    PickPlaceWorld{bad};
    ADD_FAILURE() << "a 1 mm misalignment was accepted";
  } catch (const InvalidParams& e) {
    EXPECT_NE(std::string(e.what()).find("gripper.tip_misalignment_m"), std::string::npos) << e.what();
  }
  bad = PickPlaceParams{};
  bad.gripper.align.gain_m_V = -1.0;
  EXPECT_THROW(PickPlaceWorld{bad}, InvalidParams);
}

}  // namespace
}  // namespace mc::microworld
