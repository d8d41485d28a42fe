#include "microcobot/haptics/dual_stage_plant.h"

#include <cmath>
#include <numbers>

#include <fmt/format.h>

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
  require_non_negative(m_p_kg, "m_p_kg");
  require_non_negative(k_p_N_per_m, "k_p_N_per_m");
  require_non_negative(b_p_Ns_per_m, "b_p_Ns_per_m");
  require_non_negative(m_d_kg, "m_d_kg");
  require_non_negative(k_d_N_per_m, "k_d_N_per_m");
  require_non_negative(b_d_Ns_per_m, "b_d_Ns_per_m");
  require(m_p_kg == 0.0 || k_p_N_per_m > 0.0, "k_p_N_per_m", "must be > 0 when m_p_kg > 0", k_p_N_per_m);
  require(m_d_kg == 0.0 || k_d_N_per_m > 0.0, "k_d_N_per_m", "must be > 0 when m_d_kg > 0", k_d_N_per_m);
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
  // The links are discretised exactly (ZOH, matrix exponential), which holds for any stiffness the
  // exponential can still compute: measured with `haptics evaluate`, k_2 up to 1e12 N/m (omega h =
  // 870) gives the rigid link's response, 1e15 (omega h = 2.8e4) moves it by 1 dB, 1e308 overflows
  // (exit 4, "diverged"). Each link's omega h on its two masses stays <= 1e3.
  const auto reduced = [](double m_a, double m_b) { return m_a * m_b / (m_a + m_b); };
  const auto link = [&](double k, double mu_ab, const char* field) {
    const double k_max = mu_ab * (1e3 / h) * (1e3 / h);
    require(
        k <= k_max, field,
        fmt::format("too stiff for dt_s/substeps = {:g} s (omega h = {:.3g} > 1e3 on {:.3g} kg: the exact "
                    "discretisation loses its accuracy); the largest value this step allows is {:.3g}",
                    h, std::sqrt(k) / std::sqrt(mu_ab) * h, mu_ab, k_max),
        k);
  };
  link(k_f_N_per_m, m_h_kg, "k_f_N_per_m");  // the finger holds the handle to the (fixed) hand
  link(k_v_N_per_m, reduced(m_h_kg, m_v_kg), "k_v_N_per_m");
  link(k_1_N_per_m, reduced(m_h_kg, m_1_kg), "k_1_N_per_m");
  link(k_2_N_per_m, reduced(m_1_kg, m_2_kg), "k_2_N_per_m");
  if (m_p_kg > 0.0) link(k_p_N_per_m, reduced(m_2_kg, m_p_kg), "k_p_N_per_m");
  if (m_d_kg > 0.0) link(k_d_N_per_m, reduced(m_1_kg, m_d_kg), "k_d_N_per_m");
}

DualStagePlant::DualStagePlant(const DualStagePlantParams& params) : params_(params) {
  params_.validate();
  const auto& p = params_;
  constexpr int n = kMasses;
  using MassMatrix = Eigen::Matrix<double, n, n>;
  // Eq. 3.4: M, C, K in Y = [y_h, y_v, y_1, y_2], bordered by the linkage modes y_p, y_d.
  MassMatrix k = MassMatrix::Zero();
  MassMatrix c = MassMatrix::Zero();
  // A spring-damper between masses i and j (j < 0: to the ground, i.e. the operator's hand).
  const auto link = [&](int i, int j, double kk, double bb) {
    k(i, i) += kk;
    c(i, i) += bb;
    if (j < 0) return;
    k(j, j) += kk;
    c(j, j) += bb;
    k(i, j) -= kk;
    k(j, i) -= kk;
    c(i, j) -= bb;
    c(j, i) -= bb;
  };
  link(0, -1, p.k_f_N_per_m, p.b_f_Ns_per_m);  // finger (eq. 3.4, k_f, b_f on y_h)
  link(0, 1, p.k_v_N_per_m, p.b_v_Ns_per_m);   // Haptuator membrane
  link(0, 2, p.k_1_N_per_m, p.b_1_Ns_per_m);   // distal links
  link(2, 3, p.k_2_N_per_m, p.b_2_Ns_per_m);   // proximal links
  // Linkage modes off the force path (extension of eq. 3.4): an absent branch (0 kg) gets a unit
  // dummy mass with no spring, so its coordinates stay at rest and leave the rest untouched.
  if (p.m_p_kg > 0.0) link(3, 4, p.k_p_N_per_m, p.b_p_Ns_per_m);  // proximal mode on the motor node
  if (p.m_d_kg > 0.0) link(2, 5, p.k_d_N_per_m, p.b_d_Ns_per_m);  // distal bending mode on m_1
  Eigen::Matrix<double, n, 1> mass;
  mass << p.m_h_kg, p.m_v_kg, p.m_1_kg, p.m_2_kg, p.m_p_kg > 0.0 ? p.m_p_kg : 1.0,
      p.m_d_kg > 0.0 ? p.m_d_kg : 1.0;
  const Eigen::Matrix<double, n, 1> minv = mass.cwiseInverse();
  a_.setZero();
  b_.setZero();
  a_.block<n, n>(0, n).setIdentity();
  a_.block<n, n>(n, 0) = -(minv.asDiagonal() * k);
  a_.block<n, n>(n, n) = -(minv.asDiagonal() * c);
  // Force pair (eq. 3.4): -f_v on the handle, +f_v on the magnet, with f_v = -Bl i: the coil
  // is wired so that a positive command pushes the handle towards +y.
  a_(kVh, kCoil) = p.bl_N_per_A / p.m_h_kg;
  a_(kVv, kCoil) = -p.bl_N_per_A / p.m_v_kg;
  // Coil under a PI current loop (the form of eq. 3.6): L i' = k_p (g u - i) + k_i q - R i
  // - Bl (y_v' - y_h'), q' = g u - i.
  a_(kCoil, kCoil) = -(p.coil_R_ohm + p.loop_kp_V_per_A) / p.coil_L_H;
  a_(kCoil, kLoop) = p.loop_ki_V_per_As / p.coil_L_H;
  a_(kLoop, kCoil) = -1.0;
  // Back-EMF e = -Bl (y_v' - y_h') (so that e i is the power f_v (y_v' - y_h')).
  a_(kCoil, kVv) = p.bl_N_per_A / p.coil_L_H;
  a_(kCoil, kVh) = -p.bl_N_per_A / p.coil_L_H;
  b_(n + 3, 0) = 1.0 / p.m_2_kg;                                       // f_m on the motor windings (eq. 3.4)
  b_(kCoil, 1) = p.loop_kp_V_per_A * p.amp_gain_A_per_V / p.coil_L_H;  // current reference g u
  b_(kLoop, 1) = p.amp_gain_A_per_V;
  b_(kVh, 2) = -1.0 / p.m_h_kg;  // end-stop pair
  b_(kVv, 2) = 1.0 / p.m_v_kg;

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
  return s * x(kVh);  // acceleration = s * velocity of the handle
}

double DualStagePlant::total_mass_kg() const {
  return params_.m_h_kg + params_.m_v_kg + params_.m_1_kg + params_.m_2_kg + params_.m_p_kg + params_.m_d_kg;
}

double DualStagePlant::stop_force(const StateVector& x) const {
  const double z = x(kYv) - x(kYh);
  const double excess = std::abs(z) - params_.stroke_m;
  if (excess <= 0.0) return 0.0;
  const double dz = x(kVv) - x(kVh);
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
  if (!x.allFinite() || x.head<kMasses>().cwiseAbs().maxCoeff() > 1.0) return false;
  state.x = x;
  state.accel_m_s2 = acceleration(state, f_m_N, u_V);
  return true;
}

double DualStagePlant::acceleration(const DualStagePlantState& state, double f_m_N, double u_V) const {
  const Eigen::Vector3d u(f_m_N, u_V, stop_force(state.x));
  return a_.row(kVh).dot(state.x) + b_.row(kVh).dot(u);
}

}  // namespace mc::haptics
