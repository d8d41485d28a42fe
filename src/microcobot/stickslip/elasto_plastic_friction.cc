#include "microcobot/stickslip/elasto_plastic_friction.h"

#include <algorithm>
#include <cmath>

#include "microcobot/core/error.h"

namespace mc::stickslip {

void FrictionParams::validate() const {
  require_positive(rho0_a_N_m, "friction.rho0_a_N_m");
  require_non_negative(rho1_a_N_s_m, "friction.rho1_a_N_s_m");
  require_positive(rho0_b_N_m, "friction.rho0_b_N_m");
  require_non_negative(rho1_b_N_s_m, "friction.rho1_b_N_s_m");
  require_non_negative(rho2_N_s_m, "friction.rho2_N_s_m");
  require(std::isfinite(zba_zss_ratio) && zba_zss_ratio > 0.0 && zba_zss_ratio < 1.0,
          "friction.zba_zss_ratio", "must be in (0, 1)", zba_zss_ratio);
  require(std::isfinite(mass_fraction_a) && mass_fraction_a > 0.0 && mass_fraction_a < 1.0,
          "friction.mass_fraction_a", "must be in (0, 1)", mass_fraction_a);
  require_non_negative(coupling_stiffness_N_m, "friction.coupling_stiffness_N_m");
  require_positive(breakaway_strain_ratio_b, "friction.breakaway_strain_ratio_b");
}

double friction_alpha(double z, double dx_sign, double z_ba, double z_ss) noexcept {
  const double az = std::abs(z);
  // eq. 2.13: no plastic flow while relaxing (motion against the strain) or inside z_ba.
  if (az <= z_ba || dx_sign == 0.0 || (z > 0.0) != (dx_sign > 0.0)) return 0.0;
  if (az >= z_ss) return 1.0;
  return 0.5 * std::sin(M_PI * (az - 0.5 * (z_ss + z_ba)) / (z_ss - z_ba)) + 0.5;  // eq. 2.12
}

namespace internal {

namespace {
// Inlined into eq. 2.12's four RK4 evaluations (as a call it was a tenth of fast stepping).
[[gnu::always_inline]] inline double sin_poly(double x) noexcept {
  // Least-squares fit of sin(x)/x as a polynomial in x^2 on Chebyshev nodes of [-pi/2, pi/2]
  // (degree 13 in x); |error| < 1e-13 there, checked against std::sin by the tests. libm's sin
  // handles any argument and was a fifth of the fast-stepping benchmark's time (RK4 evaluates
  // eq. 2.12 four times per strain step); here the argument is bounded by construction.
  x = std::clamp(x, -0.5 * M_PI, 0.5 * M_PI);
  // Estrin's scheme: the sub-step is latency-bound, and Horner's seven dependent multiply-adds
  // were slower than libm; here the longest chain is four.
  const double y = x * x, y2 = y * y, y4 = y2 * y2;
  const double p01 = 0.999999999999627 - 0.16666666666096164 * y;
  const double p23 = 0.008333333308355432 - 0.00019841265016425254 * y;
  const double p45 = 2.7556840321608933e-06 - 2.5026620623092022e-08 * y;
  const double p456 = p45 + 1.536585025885273e-10 * y2;
  return x * ((p01 + p23 * y2) + p456 * y4);
}
}  // namespace

double sin_within_half_pi(double x) noexcept { return sin_poly(x); }

namespace {
/// The constants of eq. 2.12 for one band [z_ba, z_ss], computed once per call.
struct Band {
  double z_ss, inv_z_ss, mid, k;  ///< alpha = 1/2 sin(k (s - mid)) + 1/2
  Band(double z_ba, double zss) noexcept
      : z_ss(zss), inv_z_ss(1.0 / zss), mid(0.5 * (zss + z_ba)), k(M_PI / (zss - z_ba)) {}
};
/// ds/dr for the strain s = |z| >= z_ba moving outward (eq. 2.11-2.12 with 2.18). k (s - mid)
/// lies in [-pi/2, pi/2] on the band; below it the clamp gives alpha = 0, as eq. 2.13 does.
inline double outward_rate(double s, const Band& b) noexcept {
  if (s >= b.z_ss) return 1.0 - s * b.inv_z_ss;  // alpha = 1: pulled back onto z_ss
  const double a = 0.5 * sin_poly(b.k * (s - b.mid)) + 0.5;
  return 1.0 - a * s * b.inv_z_ss;
}
}  // namespace

double friction_dz_dx_mixed(double z, double z_ba, double z_ss) noexcept {
  // Outward motion beyond z_ba; z / z_ss(z) = |z| / z_ss by eq. 2.18.
  return outward_rate(std::abs(z), Band(z_ba, z_ss));
}

double advance_strain_mixed(double s, double remaining, double z_ba, double z_ss) noexcept {
  // Mixed/plastic part: RK4 in the path variable. Beyond a few z_ss of sliding the strain sits
  // on z_ss to machine precision (exponential approach, rate 1/z_ss per metre of path).
  const double width = z_ss - z_ba;
  const Band band(z_ba, z_ss);
  const double path = std::min(remaining, 40.0 * z_ss);
  // At most a quarter of the band per RK4 step; one step in the common case (no division).
  const double quarter = 0.25 * width;
  const int n = path <= quarter ? 1 : std::clamp(static_cast<int>(std::ceil(path / quarter)), 1, 400);
  const double h = n == 1 ? path : path / n;
  for (int i = 0; i < n; ++i) {
    const double k1 = outward_rate(s, band);
    const double k2 = outward_rate(s + 0.5 * h * k1, band);
    const double k3 = outward_rate(s + 0.5 * h * k2, band);
    const double k4 = outward_rate(s + h * k3, band);
    s += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
  }
  if (remaining > path) s = std::min(s, z_ss);
  return std::min(s, z_ss);
}

}  // namespace internal

}  // namespace mc::stickslip
