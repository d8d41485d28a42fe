#include "microcobot/microworld/tip_alignment.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "microcobot/core/error.h"

namespace mc::microworld {
namespace {

// Fingers whose tips sit `dz_m` apart (finger 1 higher for dz > 0), the align drives at `u0_V`
// for a while, the grasp drives at 0 V.
BenderFingersState misaligned(const BenderFingersParams& p, double dz_m, double u0_V) {
  BenderFingersState s;
  for (int k = 0; k < 2; ++k) {
    const auto i = static_cast<std::size_t>(k);
    s.align[i] = settled_bender(finger_bender(p, p.align, k), u0_V);
    s.grasp[i] = settled_bender(finger_bender(p, p.grasp, k), 0.0);
  }
  s.mount_z_m[1] = dz_m - (s.align[1].y_m - s.align[0].y_m);
  return s;
}

TEST(BenderFingers, ATipOnTheSubstratePressesWithItsDepthAndMisalignedTipsHoldLess) {
  BenderFingersParams p;
  BenderFingersState s = misaligned(p, 5e-6, 0.0);
  EXPECT_NEAR(misalignment_m(p, s), 5e-6, 1e-12);
  const TipReading r = read_tips(p, s, 2e-6);  // the substrate 2 um above tip 0, 3 um below tip 1
  EXPECT_DOUBLE_EQ(r.z_m[0], 2e-6);
  EXPECT_NEAR(r.contact_N[0], p.contact_stiffness_N_m * 2e-6, 1e-12);
  EXPECT_EQ(r.contact_N[1], 0.0);
  EXPECT_DOUBLE_EQ(holding_force_N(p, 1e-3, 0.0), 2.0 * p.friction_coefficient * 1e-3);
  EXPECT_LT(holding_force_N(p, 1e-3, 20e-6), holding_force_N(p, 1e-3, 5e-6));
  EXPECT_EQ(holding_force_N(p, 1e-3, p.tip_face_height_m), 0.0);
  EXPECT_NEAR(part_tilt_rad(20e-6, 200e-6), std::atan(0.1), 1e-12);
}

// The procedure levels tips 20 um apart to within 1 um, the check after the creep included, on a
// seeded random set: either tip high, the fingers' gains 0-5 % apart, the align drives anywhere in
// their middle, the substrate 20-80 um below.
TEST(TipAlignment, LevelsTipsTwentyMicrometresApartToWithinOneOnARandomSet) {
  std::mt19937_64 rng(20261207);
  std::uniform_real_distribution<double> sign(-1.0, 1.0), mismatch(0.0, 0.05), drive(-50.0, 50.0),
      height(20e-6, 80e-6);
  const TipAlignmentParams params;
  double worst_later = 0.0;
  for (int c = 0; c < 8; ++c) {
    BenderFingersParams p;
    p.gain_mismatch = mismatch(rng);
    const double dz = (sign(rng) < 0.0 ? -1.0 : 1.0) * 20e-6;
    const double u0 = drive(rng);
    const double h = height(rng);
    const BenderFingersState s = misaligned(p, dz, u0);
    BenderDrives d;
    d.align_V = {u0, u0};
    const AlignmentRun run = run_tip_alignment(p, s, d, params, h);
    EXPECT_TRUE(run.done) << "case " << c << ": " << run.failure;
    EXPECT_NEAR(run.misalignment_before_m, dz, 1e-12);
    EXPECT_LT(std::abs(run.misalignment_after_m), 1e-6) << "case " << c;
    EXPECT_LT(std::abs(run.misalignment_later_m), 1e-6) << "case " << c;
    EXPECT_LT(run.peak_contact_N, params.max_contact_N);
    worst_later = std::max(worst_later, std::abs(run.misalignment_later_m));
    std::printf(
        "alignment case %d: %+.1f um -> %+.3f um at the end (%d passes, %.1f s), %+.3f um 60 s later\n", c,
        1e6 * dz, 1e6 * run.misalignment_after_m, run.passes, run.duration_s, 1e6 * run.misalignment_later_m);
  }
  std::printf("alignment: worst %.3f um a minute after\n", 1e6 * worst_later);
}

TEST(TipAlignment, WithoutASubstrateItStopsAfterItsTravelAndHolds) {
  BenderFingersParams p;
  TipAlignmentParams params;
  params.max_travel_m = 50e-6;
  const AlignmentRun run = run_tip_alignment(p, misaligned(p, 20e-6, 0.0), {}, params, 1.0, 0.0);
  EXPECT_FALSE(run.done);
  EXPECT_STREQ(run.failure, "no tip touched within alignment.max_travel_m");
  EXPECT_EQ(run.peak_contact_N, 0.0);
}

TEST(TipAlignment, AFailedProcedureCommandsNoMotion) {
  TipAlignment a;
  a.start({});
  TipReading pressed;
  pressed.contact_N = {1.0, 0.0};  // far beyond max_contact_N
  const AlignmentCommand c = a.tick(pressed, 1e-3);
  EXPECT_EQ(a.phase(), AlignmentPhase::kFailed);
  EXPECT_EQ(c.z_velocity_m_s, 0.0);
  EXPECT_EQ(a.tick({}, 1e-3).z_velocity_m_s, 0.0);  // and stays so
}

TEST(TipAlignment, ParametersAreRefusedNamingTheirKey) {
  TipAlignmentParams p;
  p.max_contact_N = p.contact_threshold_N / 2;
  try {
    TipAlignment a(p);
    FAIL();
  } catch (const InvalidParams& e) {
    EXPECT_NE(std::string(e.what()).find("alignment.max_contact_N"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace mc::microworld
