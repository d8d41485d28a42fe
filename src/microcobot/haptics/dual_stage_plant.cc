#include "microcobot/haptics/dual_stage_plant.h"

#include <cmath>
#include <numbers>

#include <unsupported/Eigen/MatrixFunctions>

#include "microcobot/core/error.h"

namespace mc::haptics {

void DualStagePlantParams::validate() const {
  require_positive(m_h_kg, "m_h_kg");
  require_positive(m_v_kg, "m_v_kg");
  require_positive(m_1_kg, "m_1_kg");
  require_positive(m_2_kg, "m_2_kg");
  require_positive(k_f_N_per_m, "k_f_N_per_m");
  require_non_negative(b_f_Ns_per_m, "b_f_Ns_per_m");
  require_positive(k_v_N_per_m, "k_v_N_per_m");
  require_non_negative(b_v_Ns_per_m, "b_v_Ns_per_m");
  require_positive(k_1_N_per_m, "k_1_N_per_m");
  require_non_negative(b_1_Ns_per_m, "b_1_Ns_per_m");
  require_positive(k_2_N_per_m, "k_2_N_per_m");
  require_non_negative(b_2_Ns_per_m, "b_2_Ns_per_m");
  require_positive(amp_gain_A_per_V, "amp_gain_A_per_V");
  require_non_negative(loop_kp_V_per_A, "loop_kp_V_per_A");
  require_positive(loop_ki_V_per_As, "loop_ki_V_per_As");
  require_positive(coil_R_ohm, "coil_R_ohm");
  require_positive(coil_L_H, "coil_L_H");
  require_positive(bl_N_per_A, "bl_N_per_A");
  require_positive(stroke_m, "stroke_m");
  require_non_negative(stop_k_N_per_m, "stop_k_N_per_m");
  require_non_negative(stop_b_Ns_per_m, "stop_b_Ns_per_m");
  require_in_range(dt_s, 1e-6, 1e-2, "dt_s");
  require(substeps >= 1 && substeps <= 1000, "substeps", "must be in [1, 1000]", substeps);
  // The explicit end-stop force must be resolved by the substep: contact frequency below
  // a fifth of the substep rate.
  const double mu = m_v_kg * m_h_kg / (m_v_kg + m_h_kg);
  const double h = dt_s / substeps;
  require(std::sqrt(stop_k_N_per_m / mu) * h < 0.4 * std::numbers::pi, "stop_k_N_per_m",
          "end-stop contact too stiff for dt_s/substeps (need sqrt(k/mu)*h < 0.4 pi)", stop_k_N_per_m);
}

DualStagePlant::DualStagePlant(const DualStagePlantParams& params) : params_(params) {
  params_.validate();
  const auto& p = params_;
  // Eq. 3.4: M, C, K in Y = [y_h, y_v, y_1, y_2].
  Eigen::Matrix4d m = Eigen::Vector4d(p.m_h_kg, p.m_v_kg, p.m_1_kg, p.m_2_kg).asDiagonal();
  Eigen::Matrix4d c;
  c << p.b_1_Ns_per_m + p.b_v_Ns_per_m + p.b_f_Ns_per_m, -p.b_v_Ns_per_m, -p.b_1_Ns_per_m, 0, -p.b_v_Ns_per_m,
      p.b_v_Ns_per_m, 0, 0,                                                  //
      -p.b_1_Ns_per_m, 0, p.b_1_Ns_per_m + p.b_2_Ns_per_m, -p.b_2_Ns_per_m,  //
      0, 0, -p.b_2_Ns_per_m, p.b_2_Ns_per_m;
  Eigen::Matrix4d k;
  k << p.k_1_N_per_m + p.k_v_N_per_m + p.k_f_N_per_m, -p.k_v_N_per_m, -p.k_1_N_per_m, 0, -p.k_v_N_per_m,
      p.k_v_N_per_m, 0, 0,                                               //
      -p.k_1_N_per_m, 0, p.k_1_N_per_m + p.k_2_N_per_m, -p.k_2_N_per_m,  //
      0, 0, -p.k_2_N_per_m, p.k_2_N_per_m;
  const Eigen::Matrix4d minv = m.inverse();
  a_.setZero();
  b_.setZero();
  a_.block<4, 4>(0, 4).setIdentity();
  a_.block<4, 4>(4, 0) = -minv * k;
  a_.block<4, 4>(4, 4) = -minv * c;
  // Force pair (eq. 3.4): -f_v on the handle, +f_v on the magnet, with f_v = -Bl i: the coil
  // is wired so that a positive command pushes the handle towards +y.
  a_(4, 8) = p.bl_N_per_A / p.m_h_kg;
  a_(5, 8) = -p.bl_N_per_A / p.m_v_kg;
  // Coil under a PI current loop: L i' = k_p (g u - i) + k_i q - R i - Bl (y_v' - y_h'),
  // q' = g u - i.
  a_(8, 8) = -(p.coil_R_ohm + p.loop_kp_V_per_A) / p.coil_L_H;
  a_(8, 9) = p.loop_ki_V_per_As / p.coil_L_H;
  a_(9, 8) = -1.0;
  // Back-EMF e = -Bl (y_v' - y_h') (so that e i is the power f_v (y_v' - y_h')).
  a_(8, 5) = p.bl_N_per_A / p.coil_L_H;
  a_(8, 4) = -p.bl_N_per_A / p.coil_L_H;
  b_(7, 0) = 1.0 / p.m_2_kg;                                       // f_m on the motor windings
  b_(8, 1) = p.loop_kp_V_per_A * p.amp_gain_A_per_V / p.coil_L_H;  // current reference g u
  b_(9, 1) = p.amp_gain_A_per_V;
  b_(4, 2) = -1.0 / p.m_h_kg;  // end-stop pair
  b_(5, 2) = 1.0 / p.m_v_kg;

  // Zero-order-hold discretisation over one substep.
  const double h = p.dt_s / p.substeps;
  Eigen::Matrix<double, kStates + 3, kStates + 3> aug;
  aug.setZero();
  aug.block<kStates, kStates>(0, 0) = a_ * h;
  aug.block<kStates, 3>(0, kStates) = b_ * h;
  const Eigen::Matrix<double, kStates + 3, kStates + 3> e = aug.exp();
  ad_ = e.block<kStates, kStates>(0, 0);
  bd_ = e.block<kStates, 3>(0, kStates);
}

std::complex<double> DualStagePlant::frf(Channel channel, double f_Hz) const {
  const int col = channel == Channel::kPantograph ? 0 : 1;
  const std::complex<double> s(0.0, 2.0 * std::numbers::pi * f_Hz);
  Eigen::Matrix<std::complex<double>, kStates, kStates> sys =
      s * Eigen::Matrix<std::complex<double>, kStates, kStates>::Identity() - a_.cast<std::complex<double>>();
  const Eigen::Matrix<std::complex<double>, kStates, 1> x =
      sys.partialPivLu().solve(b_.col(col).cast<std::complex<double>>());
  return s * x(4);  // acceleration = s * velocity of the handle
}

double DualStagePlant::total_mass_kg() const {
  return params_.m_h_kg + params_.m_v_kg + params_.m_1_kg + params_.m_2_kg;
}

double DualStagePlant::stop_force(const StateVector& x) const {
  const double z = x(1) - x(0);
  const double excess = std::abs(z) - params_.stroke_m;
  if (excess <= 0.0) return 0.0;
  const double dz = x(5) - x(4);
  double f = -params_.stop_k_N_per_m * std::copysign(excess, z) - params_.stop_b_Ns_per_m * dz;
  // A contact pushes, never pulls.
  if (f * z > 0.0) f = 0.0;
  return f;
}

void DualStagePlant::step(DualStagePlantState& state, double f_m_N, double u_V) const {
  if (!try_step(state, f_m_N, u_V)) {
    throw ComputationFailed("dual-stage plant diverged (|y| > 1 m or non-finite state)");
  }
}

bool DualStagePlant::try_step(DualStagePlantState& state, double f_m_N, double u_V) const noexcept {
  StateVector x = state.x;
  for (int i = 0; i < params_.substeps; ++i) {
    const Eigen::Vector3d u(f_m_N, u_V, stop_force(x));
    x = ad_ * x + bd_ * u;
  }
  if (!x.allFinite() || x.head<4>().cwiseAbs().maxCoeff() > 1.0) return false;
  state.x = x;
  state.accel_m_s2 = acceleration(state, f_m_N, u_V);
  return true;
}

double DualStagePlant::acceleration(const DualStagePlantState& state, double f_m_N, double u_V) const {
  const Eigen::Vector3d u(f_m_N, u_V, stop_force(state.x));
  return a_.row(4).dot(state.x) + b_.row(4).dot(u);
}

}  // namespace mc::haptics
