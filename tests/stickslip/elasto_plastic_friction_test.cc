// Elasto-plastic friction with z_ss(z) = z_ss sgn(z) (thesis eq. 2.9-2.13, 2.18-2.19).
#include "microcobot/stickslip/elasto_plastic_friction.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "microcobot/core/error.h"
#include "microcobot/core/rng.h"

namespace mc::stickslip {
namespace {

constexpr double kZba = 400e-9;
constexpr double kZss = kZba / 0.667;

TEST(ElastoPlasticFriction, AlphaPhases) {
  EXPECT_EQ(friction_alpha(0.5 * kZba, 1.0, kZba, kZss), 0.0);  // elastic
  EXPECT_EQ(friction_alpha(kZss, 1.0, kZba, kZss), 1.0);        // plastic
  const double mid = friction_alpha(0.5 * (kZba + kZss), 1.0, kZba, kZss);
  EXPECT_NEAR(mid, 0.5, 1e-12);                                  // eq. 2.12 centre
  EXPECT_EQ(friction_alpha(-0.9 * kZss, 1.0, kZba, kZss), 0.0);  // relaxing: sgn(x') != sgn(z)
  EXPECT_NEAR(friction_alpha(-0.5 * (kZba + kZss), -1.0, kZba, kZss), 0.5, 1e-12);  // |z| (eq. 2.12)
  // Continuity at both phase borders.
  EXPECT_NEAR(friction_alpha(kZba * (1 + 1e-9), 1.0, kZba, kZss), 0.0, 1e-9);
  EXPECT_NEAR(friction_alpha(kZss * (1 - 1e-9), 1.0, kZba, kZss), 1.0, 1e-9);
}

TEST(ElastoPlasticFriction, TheHotPathsSineIsLibmsWithin1e13) {
  // The polynomial that replaces std::sin in the strain integration, on its domain and clamped
  // beyond it (alpha = 0 below z_ba, 1 at z_ss: eq. 2.13).
  double worst = 0.0;
  for (int i = -100000; i <= 100000; ++i) {
    const double x = 0.5 * M_PI * i / 100000.0;
    worst = std::max(worst, std::abs(internal::sin_within_half_pi(x) - std::sin(x)));
  }
  EXPECT_LT(worst, 1e-13);
  EXPECT_EQ(internal::sin_within_half_pi(0.0), 0.0);
  EXPECT_NEAR(internal::sin_within_half_pi(3.0), 1.0, 1e-13);
  EXPECT_NEAR(internal::sin_within_half_pi(-40.0), -1.0, 1e-13);
  // So the mixed-phase slope is eq. 2.11-2.12 evaluated with libm (friction_alpha), to 1e-13.
  for (int i = 1; i < 1000; ++i) {
    const double z = kZba + (kZss - kZba) * i / 1000.0;
    for (const double sign : {1.0, -1.0}) {
      EXPECT_NEAR(friction_dz_dx(sign * z, sign, kZba, kZss),
                  1.0 - friction_alpha(sign * z, sign, kZba, kZss) * z / kZss, 1e-13)
          << z;
    }
  }
}

TEST(ElastoPlasticFriction, SlopeWithinZeroOneOnRandomDrives) {
  // eq. 2.19: 0 <= dz/dx <= 1 for every phase and both directions, and |z| <= z_ss.
  Rng rng(3);
  double z = 0.0;
  for (int k = 0; k < 200000; ++k) {
    const double dx = (rng.uniform() - 0.5) * (k % 7 == 0 ? 2e-7 : 2e-8);
    const double z_new = advance_strain(z, dx, kZba, kZss);
    const double slope = (z_new - z) / dx;
    // Rounding of (z + dz) - z, relative to dx.
    const double tol =
        1e-12 + 4.0 * std::numeric_limits<double>::epsilon() * (std::abs(z) + kZss) / std::abs(dx);
    ASSERT_GE(slope, -tol) << k;
    ASSERT_LE(slope, 1.0 + tol) << k;
    ASSERT_LE(std::abs(z_new), kZss * (1 + 1e-12));
    const double d = friction_dz_dx(z_new, dx > 0 ? 1.0 : -1.0, kZba, kZss);
    ASSERT_GE(d, 0.0);
    ASSERT_LE(d, 1.0);
    z = z_new;
  }
}

TEST(ElastoPlasticFriction, ElasticPhaseIsExactAndReversible) {
  const double z = advance_strain(0.0, 0.8 * kZba, kZba, kZss);
  EXPECT_DOUBLE_EQ(z, 0.8 * kZba);
  EXPECT_NEAR(advance_strain(z, -0.8 * kZba, kZba, kZss), 0.0, 1e-20);
}

TEST(ElastoPlasticFriction, SaturatesAtSteadyStateStrainBothDirections) {
  // Long sliding: |z| -> z_ss with the sign of the motion (eq. 2.18), never beyond.
  EXPECT_NEAR(advance_strain(0.0, 50 * kZss, kZba, kZss), kZss, 1e-12 * kZss);
  EXPECT_NEAR(advance_strain(0.0, -50 * kZss, kZba, kZss), -kZss, 1e-12 * kZss);
  // Motion reversal from the plastic phase is elastic (Table 2.6): dz = dx.
  EXPECT_NEAR(advance_strain(kZss, -0.3 * kZss, kZba, kZss), 0.7 * kZss, 1e-15);
}

TEST(ElastoPlasticFriction, StepSizeIndependent) {
  // Rate independence and path integration: one big increment equals many small ones.
  double z_fine = 0.0;
  for (int k = 0; k < 1000; ++k) z_fine = advance_strain(z_fine, 1.5e-9, kZba, kZss);
  const double z_one = advance_strain(0.0, 1.5e-6, kZba, kZss);
  EXPECT_NEAR(z_one, z_fine, 1e-6 * kZss);
}

TEST(ElastoPlasticFriction, ParamsValidate) {
  FrictionParams p;
  EXPECT_NO_THROW(p.validate());
  p.zba_zss_ratio = 1.2;
  EXPECT_THROW(p.validate(), InvalidParams);
}

}  // namespace
}  // namespace mc::stickslip
