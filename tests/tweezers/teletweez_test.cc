// The 7-DOF TéléTweez model: energy-derived matrices, passivity, statics, FRF features, and an
// allocation-free step.
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>
#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "microcobot/core/error.h"
#include "microcobot/core/params.h"
#include "microcobot/tweezers/teletweez.h"
#include "support/counting_allocator.h"

namespace mc::tweezers {
namespace {

TEST(TeleTweezMatrices, SymmetricPositiveSemidefinite) {
  const auto m = assemble(TeleTweezParams{});
  EXPECT_TRUE(m.M.isApprox(m.M.transpose()));
  EXPECT_TRUE(m.K.isApprox(m.K.transpose(), 1e-14));
  EXPECT_TRUE(m.C.isApprox(m.C.transpose(), 1e-14));
  // Mass-normalized (M^-1/2 K M^-1/2) so that rad and m coordinates compare: eigenvalues are
  // omega^2. K is positive definite (fingers and flexure ground the chain); C at least PSD.
  const Vec7 s = m.M.diagonal().cwiseSqrt().cwiseInverse();
  const Mat7 kn = s.asDiagonal() * m.K * s.asDiagonal();
  const Mat7 cn = s.asDiagonal() * m.C * s.asDiagonal();
  Eigen::SelfAdjointEigenSolver<Mat7> ek(kn), ec(cn);
  EXPECT_GT(m.M.diagonal().minCoeff(), 0.0);
  EXPECT_GT(ek.eigenvalues().minCoeff(), std::pow(2 * std::numbers::pi * 1.0, 2));  // slowest mode > 1 Hz
  EXPECT_GE(ec.eigenvalues().minCoeff(), -1e-9 * ec.eigenvalues().maxCoeff());
  EXPECT_TRUE(Eigen::LLT<Mat7>(kn).info() == Eigen::Success);
  // Errata 6: the ball screw couples rotation and axial motion, x = R_bs theta.
  const double rbs = TeleTweezParams{}.screw_ratio();
  EXPECT_NE(m.K(kThetaBs, kXBs), 0.0);
  EXPECT_NEAR(m.K(kThetaBs, kXBs), -TeleTweezParams{}.axial_stiffness_N_per_m * rbs, 1e-9);
}

TEST(TeleTweezMatrices, FreeTweezersHaveOneRigidMode) {
  // Without fingers, with a vanishing flexure, nothing holds the chain: K has exactly one zero
  // eigenvalue whose mode is the kinematic chain theta -> x = R_bs theta -> x_l = R_ss x_ss.
  TeleTweezParams p;
  p.finger_stiffness_N_per_m = 0;
  p.clamping_stiffness_N_per_m = 1e-12;
  const auto m = assemble(p);
  Eigen::SelfAdjointEigenSolver<Mat7> ek(m.K);
  EXPECT_LT(std::abs(ek.eigenvalues()[0]), 1e-9);
  EXPECT_GT(ek.eigenvalues()[1], 1e-3);
  const Vec7 mode = ek.eigenvectors().col(0) / ek.eigenvectors()(kThetaM, 0);
  EXPECT_NEAR(mode[kThetaBs], 1.0, 1e-6);
  EXPECT_NEAR(mode[kXBs], p.screw_ratio(), 1e-9);
  EXPECT_NEAR(mode[kXL], p.lever_per_motor_rad(), 1e-8);
}

TEST(TeleTweez, PassiveEnergyNeverIncreasesWithoutInput) {
  TeleTweez model(TeleTweezParams{}, 1e-4);
  TeleTweezState s;
  // Arbitrary initial deflection and velocities.
  s.q << 0.3, 0.2, -0.1, 1e-5, -2e-5, 1e-4, -3e-4;
  s.v << 50, -20, 10, 1e-3, 2e-3, -0.01, 0.02;
  double e = energy(model.matrices(), s);
  const double e0 = e;
  const Input zero = Input::Zero();
  for (int k = 0; k < 20000; ++k) {
    model.step(s, zero);
    const double en = energy(model.matrices(), s);
    ASSERT_LE(en, e * (1 + 1e-12) + 1e-18) << "step " << k;
    e = en;
  }
  EXPECT_LT(e, 1e-3 * e0);  // and it dissipates
}

TEST(TeleTweez, StaticDeflectionUnderTorque) {
  const TeleTweezParams p;
  TeleTweez model(p, 1e-4);
  TeleTweezState s;
  Input u = Input::Zero();
  u[kTorque] = 1e-3;
  for (int k = 0; k < 40000; ++k) model.step(s, u);  // 4 s: settled (slowest mode 12 Hz, zeta 0.5)
  // Virtual work: the torque is a generalized force T / (R_ss R_bs) on x_l, held by both levers'
  // flexure and finger springs.
  const double expected = u[kTorque] / (p.lever_per_motor_rad() * 2 *
                                        (p.clamping_stiffness_N_per_m + p.finger_stiffness_N_per_m));
  EXPECT_NEAR(s.q[kXL], expected, 1e-3 * expected);
  EXPECT_NEAR(s.q[kXCl], expected, 1e-3 * expected);
  EXPECT_LT(std::abs(s.v[kXL]), 1e-7);
  EXPECT_NEAR(model.tip_opening(s), p.static_opening_tip_m - 2 * expected, 1e-9);
  // The force per finger equals the torque converted by torque_for_finger_force().
  EXPECT_NEAR(p.torque_for_finger_force(2 * (p.clamping_stiffness_N_per_m + p.finger_stiffness_N_per_m) *
                                        expected / 2),
              u[kTorque], 1e-9);
}

TEST(TeleTweez, FrfHasAntiresonanceAtTheTipAbsorber) {
  const TeleTweezParams p;
  TeleTweez model(p, 1e-4);
  const double fa = std::sqrt(p.tip_stiffness_N_per_m / p.tip_mass_kg) / (2 * std::numbers::pi);
  // Minimum of |H| near fa on a fine grid.
  double best_f = 0, best = 1e300;
  for (double f = 300; f < 480; f += 0.25) {
    const double m = std::abs(model.finger_acceleration_frf(f));
    if (m < best) best = m, best_f = f;
  }
  EXPECT_NEAR(best_f, fa, 3.0);
  // Dominant peak (above the hand-held rigid mode) near 150 Hz.
  double peak_f = 0, peak = 0;
  for (double f = 40; f < 1000; f += 0.5) {
    const double m = std::abs(model.finger_acceleration_frf(f));
    if (m > peak) peak = m, peak_f = f;
  }
  EXPECT_NEAR(peak_f, 150, 10);
}

TEST(TeleTweez, SimulationMatchesAnalyticFrf) {
  // A 80 Hz torque sine: steady-state amplitude of the finger acceleration equals |H(80)|.
  TeleTweez model(TeleTweezParams{}, 1e-4);
  TeleTweezState s;
  Input u = Input::Zero();
  const double f = 80, amp = 1e-3;
  double peak = 0;
  for (int k = 0; k < 30000; ++k) {
    u[kTorque] = amp * std::sin(2 * std::numbers::pi * f * (k + 0.5) * 1e-4);
    const double a = model.finger_acceleration(s, u);
    if (k > 20000) peak = std::max(peak, std::abs(a));
    model.step(s, u);
  }
  EXPECT_NEAR(peak, amp * std::abs(model.finger_acceleration_frf(f)), 0.02 * peak);
}

TEST(TeleTweez, StepDoesNotAllocate) {
  TeleTweez model(TeleTweezParams{}, 1e-4);
  TeleTweezState s;
  Input u = Input::Zero();
  u[kTorque] = 1e-3;
  double sink = 0;
  {
    test::AllocationGuard guard;
    for (int k = 0; k < 1000; ++k) {
      model.step(s, u);
      sink += model.finger_acceleration(s, u) + model.tip_opening(s);
    }
    EXPECT_EQ(guard.allocations(), 0u);
  }
  EXPECT_TRUE(std::isfinite(sink));
}

TEST(TeleTweezParams, ValidateAndYaml) {
  TeleTweezParams p;
  EXPECT_NO_THROW(p.validate());
  p.lever_mass_kg = 30e-3;  // levers heavier than the whole prototype
  EXPECT_THROW(p.validate(), InvalidParams);
  p = TeleTweezParams{};
  p.lead_m = 0;
  EXPECT_THROW(p.validate(), InvalidParams);
  const auto q = params_from_yaml_text<TeleTweezParams>("lever_stiffness_N_per_m: 2.0e4\n");
  EXPECT_EQ(q.lever_stiffness_N_per_m, 2.0e4);
  EXPECT_THROW(params_from_yaml_text<TeleTweezParams>("no_such_key: 1\n"), InvalidInput);
  // The thesis's values.
  EXPECT_DOUBLE_EQ(TeleTweezParams{}.motor_inertia_kg_m2, 0.151e-7);
  EXPECT_DOUBLE_EQ(TeleTweezParams{}.clamping_stiffness_N_per_m, 190.0);
}

}  // namespace
}  // namespace mc::tweezers
