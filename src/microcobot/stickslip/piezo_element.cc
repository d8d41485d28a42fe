#include "microcobot/stickslip/piezo_element.h"

#include <algorithm>
#include <cmath>

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

ModeDiscretization ModeDiscretization::make(double mass, double damping, double stiffness,
                                            double h) noexcept {
  // The augmented system [x, v, f, fdot] in the mode's own units, y = [x, v / w0, f / (M w0^2),
  // fdot / (M w0^3)], has every entry of order w0 h: its exponential by scaling and squaring of a
  // Taylor series is accurate to rounding for any h (a closed form cancels when w0 h << 1).
  using M4 = std::array<std::array<double, 4>, 4>;
  const double w0 = std::sqrt(stiffness / mass);
  const double c = damping / mass;
  M4 b{};
  b[0][1] = w0 * h;
  b[1][0] = -w0 * h;
  b[1][1] = -c * h;
  b[1][2] = w0 * h;
  b[2][3] = w0 * h;
  double norm = std::max(w0, c) * h;
  int squarings = 0;
  while (norm > 0.25 && squarings < 60) {
    norm *= 0.5;
    ++squarings;
  }
  for (auto& row : b)
    for (double& v : row) v = std::ldexp(v, -squarings);
  auto mul = [](const M4& x, const M4& y) {
    M4 z{};
    for (int i = 0; i < 4; ++i)
      for (int k = 0; k < 4; ++k)
        for (int j = 0; j < 4; ++j) z[i][j] += x[i][k] * y[k][j];
    return z;
  };
  M4 e{}, term{};
  for (int i = 0; i < 4; ++i) e[i][i] = term[i][i] = 1.0;
  for (int n = 1; n <= 16; ++n) {  // 0.25^17 / 17! < 1e-24
    term = mul(term, b);
    for (auto& row : term)
      for (double& v : row) v /= n;
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) e[i][j] += term[i][j];
  }
  for (int i = 0; i < squarings; ++i) e = mul(e, e);
  ModeDiscretization d;
  d.phi = {e[0][0], e[0][1] / w0, e[1][0] * w0, e[1][1]};
  const double mw2 = mass * w0 * w0;
  d.g0 = {e[0][2] / mw2, e[1][2] / (mass * w0)};
  d.g1 = {e[0][3] / (mw2 * w0 * h), e[1][3] / (mw2 * h)};
  return d;
}

}  // namespace mc::stickslip
