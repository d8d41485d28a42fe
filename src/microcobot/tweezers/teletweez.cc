#include "microcobot/tweezers/teletweez.h"

#include <cmath>
#include <numbers>
#include <unsupported/Eigen/MatrixFunctions>

#include <Eigen/LU>

#include "microcobot/core/error.h"

namespace mc::tweezers {

void TeleTweezParams::validate() const {
  require_positive(motor_inertia_kg_m2, "motor_inertia_kg_m2");
  require_non_negative(motor_damping_N_m_s, "motor_damping_N_m_s");
  require_positive(coupling_inertia_kg_m2, "coupling_inertia_kg_m2");
  require_positive(coupling_stiffness_N_m, "coupling_stiffness_N_m");
  require_non_negative(coupling_damping_N_m_s, "coupling_damping_N_m_s");
  require_positive(screw_inertia_kg_m2, "screw_inertia_kg_m2");
  require_positive(screw_torsion_stiffness_N_m, "screw_torsion_stiffness_N_m");
  require_non_negative(screw_torsion_damping_N_m_s, "screw_torsion_damping_N_m_s");
  require_positive(lead_m, "lead_m");
  require_positive(screw_mass_kg, "screw_mass_kg");
  require_positive(axial_stiffness_N_per_m, "axial_stiffness_N_per_m");
  require_non_negative(axial_damping_N_s_per_m, "axial_damping_N_s_per_m");
  require_positive(support_mass_kg, "support_mass_kg");
  require_positive(support_stiffness_N_per_m, "support_stiffness_N_per_m");
  require_non_negative(support_damping_N_s_per_m, "support_damping_N_s_per_m");
  require_positive(transmission_ratio, "transmission_ratio");
  require_positive(lever_mass_kg, "lever_mass_kg");
  require_positive(lever_stiffness_N_per_m, "lever_stiffness_N_per_m");
  require_non_negative(lever_damping_N_s_per_m, "lever_damping_N_s_per_m");
  require_positive(clamping_stiffness_N_per_m, "clamping_stiffness_N_per_m");
  require_non_negative(clamping_damping_N_s_per_m, "clamping_damping_N_s_per_m");
  require_positive(tip_mass_kg, "tip_mass_kg");
  require_positive(tip_stiffness_N_per_m, "tip_stiffness_N_per_m");
  require_non_negative(tip_damping_N_s_per_m, "tip_damping_N_s_per_m");
  require_non_negative(finger_stiffness_N_per_m, "finger_stiffness_N_per_m");
  require_non_negative(finger_damping_N_s_per_m, "finger_damping_N_s_per_m");
  require_positive(max_torque_N_m, "max_torque_N_m");
  require_positive(static_opening_tip_m, "static_opening_tip_m");
  require_positive(total_mass_kg, "total_mass_kg");
  const double moving = screw_mass_kg + support_mass_kg + 2.0 * (lever_mass_kg + tip_mass_kg);
  require(moving <= total_mass_kg, "total_mass_kg",
          "must hold the moving masses m_bs + m_ss + 2 (m_l + m_cl)", total_mass_kg);
}

double TeleTweezParams::screw_ratio() const { return lead_m / (2.0 * std::numbers::pi); }

namespace {
/// Adds the rank-one term w a a^T of the quadratic form 1/2 w (a.q)^2.
void add_term(Mat7& m, double w, std::initializer_list<std::pair<int, double>> a) {
  for (const auto& [i, ai] : a) {
    for (const auto& [j, aj] : a) m(i, j) += w * ai * aj;
  }
}
}  // namespace

MechanicalMatrices assemble(const TeleTweezParams& p) {
  p.validate();
  MechanicalMatrices out;
  out.M.setZero();
  out.C.setZero();
  out.K.setZero();
  out.B.setZero();
  const double rbs = p.screw_ratio();
  const double rss = p.transmission_ratio;
  out.M.diagonal() << p.motor_inertia_kg_m2, p.coupling_inertia_kg_m2, p.screw_inertia_kg_m2, p.screw_mass_kg,
      p.support_mass_kg, 2.0 * p.lever_mass_kg, 2.0 * p.tip_mass_kg;
  // Elements: each a spring (K) and a damper (C) on the same relative coordinate.
  struct Element {
    double k, c, mult;
    std::initializer_list<std::pair<int, double>> a;
  };
  const Element elements[] = {
      {p.coupling_stiffness_N_m, p.coupling_damping_N_m_s, 1.0, {{kThetaM, 1.0}, {kThetaCp, -1.0}}},
      {p.screw_torsion_stiffness_N_m,
       p.screw_torsion_damping_N_m_s,
       1.0,
       {{kThetaCp, 1.0}, {kThetaBs, -1.0}}},
      {p.axial_stiffness_N_per_m, p.axial_damping_N_s_per_m, 1.0, {{kXBs, 1.0}, {kThetaBs, -rbs}}},
      {p.support_stiffness_N_per_m, p.support_damping_N_s_per_m, 1.0, {{kXSs, 1.0}, {kXBs, -1.0}}},
      {p.lever_stiffness_N_per_m, p.lever_damping_N_s_per_m, 2.0, {{kXL, 1.0}, {kXSs, -rss}}},
      {p.clamping_stiffness_N_per_m + p.finger_stiffness_N_per_m,
       p.clamping_damping_N_s_per_m + p.finger_damping_N_s_per_m,
       2.0,
       {{kXL, 1.0}}},
      {p.tip_stiffness_N_per_m, p.tip_damping_N_s_per_m, 2.0, {{kXCl, 1.0}, {kXL, -1.0}}},
      {0.0, p.motor_damping_N_m_s, 1.0, {{kThetaM, 1.0}}},
  };
  for (const auto& e : elements) {
    add_term(out.K, e.mult * e.k, e.a);
    add_term(out.C, e.mult * e.c, e.a);
  }
  out.B(kThetaM, kTorque) = 1.0;
  out.B(kXL, kFingerForce) = 2.0;  // one force on each of the two levers
  out.B(kXCl, kTipForce) = 2.0;
  return out;
}

double energy(const MechanicalMatrices& m, const TeleTweezState& s) {
  return 0.5 * s.v.dot(m.M * s.v) + 0.5 * s.q.dot(m.K * s.q);
}

TeleTweez::TeleTweez(const TeleTweezParams& params, double dt_s) : params_(params), dt_(dt_s) {
  require_positive(dt_s, "dt_s");
  mech_ = assemble(params_);
  minv_ = mech_.M.inverse();
  a_.setZero();
  a_.topRightCorner<kDofs, kDofs>().setIdentity();
  a_.bottomLeftCorner<kDofs, kDofs>() = -minv_ * mech_.K;
  a_.bottomRightCorner<kDofs, kDofs>() = -minv_ * mech_.C;
  bc_.setZero();
  bc_.bottomRows<kDofs>() = minv_ * mech_.B;
  // Exact ZOH discretization: exp([A B; 0 0] dt) = [Ad Bd; 0 I].
  Eigen::Matrix<double, kStates + kInputs, kStates + kInputs> aug;
  aug.setZero();
  aug.topLeftCorner<kStates, kStates>() = a_ * dt_;
  aug.topRightCorner<kStates, kInputs>() = bc_ * dt_;
  const Eigen::Matrix<double, kStates + kInputs, kStates + kInputs> e = aug.exp();
  ad_ = e.topLeftCorner<kStates, kStates>();
  bd_ = e.topRightCorner<kStates, kInputs>();
  if (!ad_.allFinite() || !bd_.allFinite())
    throw ComputationFailed("TeleTweez: discretization is not finite");
}

void TeleTweez::step(TeleTweezState& s, const Input& u) const noexcept {
  Vec14 x;
  x << s.q, s.v;
  const Vec14 next = ad_ * x + bd_ * u;
  s.q = next.head<kDofs>();
  s.v = next.tail<kDofs>();
}

Vec7 TeleTweez::acceleration(const TeleTweezState& s, const Input& u) const noexcept {
  return minv_ * (mech_.B * u - mech_.C * s.v - mech_.K * s.q);
}

double TeleTweez::finger_acceleration(const TeleTweezState& s, const Input& u) const noexcept {
  return minv_.row(kXL).dot(mech_.B * u - mech_.C * s.v - mech_.K * s.q);
}

std::complex<double> TeleTweez::finger_acceleration_frf(double f_Hz, int input) const {
  const double w = 2.0 * std::numbers::pi * f_Hz;
  const std::complex<double> jw(0.0, w);
  const Eigen::Matrix<std::complex<double>, kDofs, kDofs> dyn =
      mech_.K.cast<std::complex<double>>() + jw * mech_.C.cast<std::complex<double>>() -
      (w * w) * mech_.M.cast<std::complex<double>>();
  const Eigen::Matrix<std::complex<double>, kDofs, 1> x =
      dyn.partialPivLu().solve(mech_.B.col(input).cast<std::complex<double>>());
  return -(w * w) * x[kXL];
}

}  // namespace mc::tweezers
