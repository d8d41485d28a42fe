#include "microcobot/stickslip/piezo_element.h"

#include <cmath>

#include <Eigen/Dense>
#include <unsupported/Eigen/MatrixFunctions>

#include "microcobot/core/error.h"

namespace mc::stickslip {

void PiezoParams::validate() const {
  require_positive(mass_kg, "pe.mass_kg");
  require_non_negative(damping_a_N_s_m, "pe.damping_a_N_s_m");
  require_positive(stiffness_a_N_m, "pe.stiffness_a_N_m");
  require_non_negative(damping_b_N_s_m, "pe.damping_b_N_s_m");
  require_positive(stiffness_b_N_m, "pe.stiffness_b_N_m");
  require_positive(static_gain_m_V, "pe.static_gain_m_V");
  require_in_range(gain_fraction_a, 0.0, 1.0, "pe.gain_fraction_a");
}

double PiezoParams::natural_frequency_a_Hz() const {
  return std::sqrt(stiffness_a_N_m / mass_kg) / (2.0 * M_PI);
}
double PiezoParams::natural_frequency_b_Hz() const {
  return std::sqrt(stiffness_b_N_m / mass_kg) / (2.0 * M_PI);
}

ModeDiscretization ModeDiscretization::make(double mass, double damping, double stiffness, double h) {
  // Augmented state [x, v, f, fdot]: f' = fdot, fdot' = 0. exp(A h) gives Phi, the zero-order
  // hold column (f) and the ramp column (fdot, scaled by 1/h for f_{k+1} - f_k).
  Eigen::Matrix4d a = Eigen::Matrix4d::Zero();
  a(0, 1) = 1.0;
  a(1, 0) = -stiffness / mass;
  a(1, 1) = -damping / mass;
  a(1, 2) = 1.0 / mass;
  a(2, 3) = 1.0;
  const Eigen::Matrix4d e = (a * h).exp();
  ModeDiscretization d;
  d.phi = {e(0, 0), e(0, 1), e(1, 0), e(1, 1)};
  d.g0 = {e(0, 2), e(1, 2)};
  d.g1 = {e(0, 3) / h, e(1, 3) / h};
  return d;
}

}  // namespace mc::stickslip
