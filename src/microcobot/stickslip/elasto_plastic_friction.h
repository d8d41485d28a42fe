#pragma once
/// @file
/// Single-state elasto-plastic friction (Dupont 2002) as modified by the thesis (eq. 2.9-2.13, 2.18), and
/// the two-asperity contact of eq. 2.20-2.21 (docs/errata.md, "Two asperities"; docs/concepts/stick-slip.md).
///
///   x = z + w                                           (2.9)  elastic z + plastic w
///   F_f = rho0 z + rho1 z' + rho2 x'                    (2.10)
///   z' = x' [1 - alpha(z, x') z / z_ss(z)]              (2.11)
///   alpha = 1/2 sin(pi (|z| - (z_ss + z_ba)/2) / (z_ss - z_ba)) + 1/2   for z_ba < |z| < z_ss (2.12)
///   alpha = 0 if |z| <= z_ba or sgn(x') != sgn(z);  alpha = 1 if |z| >= z_ss   (2.13)
///   z_ss(z) = z_ss sgn(z)                               (2.18)
/// The law is rate independent: z depends only on the path of x. advance_strain() integrates
/// dz/dx along an increment dx, so a step of any length stays on the model's manifold
/// 0 <= dz/dx <= 1 (eq. 2.19) and |z| <= z_ss.

#include <algorithm>
#include <cmath>

namespace mc::stickslip {

/// Contact parameters of the two asperities (Table 2.8, eq. 2.20-2.21) and of the modal slider.
struct FrictionParams {
  double rho0_a_N_m = 3.517e5;    ///< rho_0a, Table 2.8: mode sqrt(rho0a/M_s) = 600 Hz
  double rho1_a_N_s_m = 64.9651;  ///< rho_1a, Table 2.8
  double rho0_b_N_m = 2.62e6;     ///< rho_0b, Table 2.8: mode sqrt(rho0b/M_s) = 1639 Hz
  double rho1_b_N_s_m = 15.6125;  ///< rho_1b, Table 2.8
  double rho2_N_s_m = 0.0;        ///< rho_2, viscous friction: negligible (thesis §2.4.3)
  double zba_zss_ratio = 0.667;   ///< z_ba / |z_ss(z)|, Table 2.8
  double mass_fraction_a = 0.5;   ///< c_a: share of the slider (mass and normal load) on asperity a
  double coupling_stiffness_N_m =
      2.0e3;  ///< k_c: slow coupling of the two slider parts (erratum 2, docs/errata.md)
  /// z_ba,b / z_ba,a: the table gives z_ba of asperity a; default 1 (one break-away strain for the
  /// whole contact, as the thesis's single z_ba; docs/concepts/stick-slip.md).
  double breakaway_strain_ratio_b = 1.0;

  template <class V>
  void visit(V& v) {
    v("rho0_a_N_m", rho0_a_N_m);
    v("rho1_a_N_s_m", rho1_a_N_s_m);
    v("rho0_b_N_m", rho0_b_N_m);
    v("rho1_b_N_s_m", rho1_b_N_s_m);
    v("rho2_N_s_m", rho2_N_s_m);
    v("zba_zss_ratio", zba_zss_ratio);
    v("mass_fraction_a", mass_fraction_a);
    v("coupling_stiffness_N_m", coupling_stiffness_N_m);
    v("breakaway_strain_ratio_b", breakaway_strain_ratio_b);
  }
  void validate() const;
};

/// alpha(z, x') of eq. 2.12-2.13 for a motion of sign `dx_sign` (-1, 0, +1).
double friction_alpha(double z, double dx_sign, double z_ba, double z_ss) noexcept;

/// True when alpha = 0 (eq. 2.13): |z| <= z_ba, no motion, or motion against the strain (relaxing).
inline bool friction_is_elastic(double z, double dx_sign, double z_ba) noexcept {
  return std::abs(z) <= z_ba || dx_sign == 0.0 || (z > 0.0) != (dx_sign > 0.0);
}

namespace internal {
/// sin(x) for x in [-pi/2, pi/2] (clamped to it), within 1e-13: eq. 2.12's sine on the hot path.
double sin_within_half_pi(double x) noexcept;
double friction_dz_dx_mixed(double z, double z_ba, double z_ss) noexcept;
double advance_strain_mixed(double s, double remaining, double z_ba, double z_ss) noexcept;
}  // namespace internal

/// dz/dx of eq. 2.11 with z_ss(z) of eq. 2.18: 1 - alpha z / (z_ss sgn z). In [0, 1] (eq. 2.19).
/// The elastic phase (alpha = 0, the common case on the real-time path) is inline.
inline double friction_dz_dx(double z, double dx_sign, double z_ba, double z_ss) noexcept {
  if (friction_is_elastic(z, dx_sign, z_ba)) return 1.0;
  return internal::friction_dz_dx_mixed(z, z_ba, z_ss);
}

/// The elastic strain after the relative displacement x moves by `dx` from strain `z`
/// (integration of eq. 2.11 along the path, exact in the elastic phase, RK4 in the mixed phase).
/// Never allocates. The elastic phase is inline; the mixed phase is out of line.
inline double advance_strain(double z, double dx, double z_ba, double z_ss) noexcept {
  if (dx == 0.0) return z;
  const double d = dx > 0.0 ? 1.0 : -1.0;
  double s = d * z;  // strain measured along the motion
  double remaining = std::abs(dx);
  // Elastic part: relaxing (s < 0, alpha = 0) and loading up to z_ba: dz = dx exactly.
  if (s < z_ba) {
    const double e = std::min(remaining, z_ba - s);
    s += e;
    remaining -= e;
  }
  if (remaining > 0.0) s = internal::advance_strain_mixed(s, remaining, z_ba, z_ss);
  return d * s;
}

}  // namespace mc::stickslip
