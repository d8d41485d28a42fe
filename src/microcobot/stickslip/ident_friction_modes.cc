#include "microcobot/stickslip/ident_friction_modes.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <unsupported/Eigen/MatrixFunctions>

#include "microcobot/core/error.h"
#include "microcobot/stickslip/ident_modal.h"
#include "microcobot/stickslip/ident_varpro.h"

namespace mc::stickslip {

std::vector<double> elastic_slider_response(const std::vector<double>& x1_static, double h,
                                            const PiezoParams& pe, double slider_mass_kg, double coupling_N_m,
                                            double rho0_a, double rho1_a, double rho0_b, double rho1_b,
                                            double mass_fraction_a) {
  // State [x1a, v1a, x1b, v1b, x2a, v2a, x2b, v2b, p, q]: the PE's two modes (eq. 2.1-2.2, loaded
  // by the contact: the PE's compliance in series with rho0_b is a few percent), the slider parts,
  // and the input x1_static = g H(U) along the step (p' = q, q held: first-order hold), so exp(A h)
  // is the exact step map.
  using Mat = Eigen::Matrix<double, 10, 10>;
  const double m = slider_mass_kg, mp = pe.mass_kg;
  const double c[2] = {mass_fraction_a, 1.0 - mass_fraction_a};
  const double r0[2] = {rho0_a, rho0_b}, r1[2] = {rho1_a, rho1_b};
  const double kp[2] = {pe.stiffness_a_N_m, pe.stiffness_b_N_m},
               dp[2] = {pe.damping_a_N_s_m, pe.damping_b_N_s_m};
  const double share[2] = {pe.gain_fraction_a, 1.0 - pe.gain_fraction_a};
  Mat a = Mat::Zero();
  // Friction on the PE: F_f = sum_i c_i [rho0_i (x1 - x2i) + rho1_i (v1 - v2i)], x1 = x1a + x1b.
  for (int mode = 0; mode < 2; ++mode) {
    const int x = 2 * mode, v = x + 1;
    a(x, v) = 1.0;
    a(v, x) -= kp[mode] / mp;
    a(v, v) -= dp[mode] / mp;
    a(v, 8) += kp[mode] * share[mode] / mp;
    for (int i = 0; i < 2; ++i) {
      for (int col : {0, 2}) {
        a(v, col) -= c[i] * r0[i] / mp;
        a(v, col + 1) -= c[i] * r1[i] / mp;
      }
      a(v, 4 + 2 * i) += c[i] * r0[i] / mp;
      a(v, 5 + 2 * i) += c[i] * r1[i] / mp;
    }
  }
  for (int i = 0; i < 2; ++i) {
    const int xi = 4 + 2 * i, vi = xi + 1, xj = 4 + 2 * (1 - i);
    const double kc = coupling_N_m / (c[i] * m);
    a(xi, vi) = 1.0;
    for (int col : {0, 2}) {
      a(vi, col) += r0[i] / m;
      a(vi, col + 1) += r1[i] / m;
    }
    a(vi, xi) = -r0[i] / m - kc;
    a(vi, vi) = -r1[i] / m;
    a(vi, xj) = kc;
  }
  a(8, 9) = 1.0;
  const Mat e = (a * h).exp();
  const Eigen::Matrix<double, 8, 8> f = e.topLeftCorner<8, 8>();
  const Eigen::Matrix<double, 8, 2> g = e.topRightCorner<8, 2>();
  std::vector<double> out(x1_static.size());
  if (x1_static.empty()) return out;
  // At rest at the first input: PE modes at their static shares, slider parts on the PE.
  Eigen::Matrix<double, 8, 1> s = Eigen::Matrix<double, 8, 1>::Zero();
  const double x0 = x1_static[0];
  s << share[0] * x0, 0.0, share[1] * x0, 0.0, x0, 0.0, x0, 0.0;
  out[0] = x0;
  for (std::size_t k = 1; k < x1_static.size(); ++k) {
    const Eigen::Vector2d in(x1_static[k - 1], (x1_static[k] - x1_static[k - 1]) / h);
    s = f * s + g * in;
    out[k] = c[0] * s[4] + c[1] * s[6];
  }
  return out;
}

FrictionModesResult identify_friction_modes(const MeasuredRecord& rec, const StickSlipParams& base,
                                            const PiParams* hysteresis) {
  base.validate();
  require_record_length(rec, 128, 0.0, "the friction modes");
  const StepInput step = fit_step_input(rec);
  const double fs = rec.fs_Hz(), h = rec.dt_s();
  const double ms = base.slider.mass_kg, kc = base.friction.coupling_stiffness_N_m;
  std::vector<double> s = step.u_V;
  const double base_h = hysteresis ? pi_loading_curve(*hysteresis, step.u0_V) : step.u0_V;
  for (double& v : s) v = (hysteresis ? pi_loading_curve(*hysteresis, v) : v) - base_h;
  const ModePeaks pk = dynamic_response_peaks(rec, s, 2, 20.0, 0.45 * fs);
  FrictionModesResult out;
  out.psd = pk.psd;
  out.psd_peaks_Hz = pk.peaks_Hz;
  std::vector<double> f0 = pk.peaks_Hz;
  if (f0.empty()) throw ComputationFailed(rec.source + ": no resonance peak in the PSD of the step response");
  if (f0.size() == 1) f0 = {f0[0] / 2.0, f0[0] * 1.5};
  const double free_s = rec.t_s.back() - step.t_settled_s();
  if (free_s * f0[0] < 5.0) {
    throw InvalidInput(
        rec.source, 0,
        fmt::format("record too short for the friction modes: {:.3g} s after the step, need >= 5 "
                    "periods of the {:.4g} Hz mode ({:.3g} s)",
                    free_s, f0[0], 5.0 / f0[0]));
  }
  const auto n = static_cast<Eigen::Index>(rec.size());
  const Eigen::VectorXd y = Eigen::Map<const Eigen::VectorXd>(rec.x_m.data(), n);
  auto unpack = [&](const Eigen::VectorXd& th, double& r0a, double& r1a, double& r0b, double& r1b,
                    double& ca) {
    const double wa = std::exp(th[0]), wb = std::exp(th[2]);
    r0a = ms * wa * wa;
    r1a = 2.0 * std::exp(th[1]) * wa * ms;
    r0b = ms * wb * wb;
    r1b = 2.0 * std::exp(th[3]) * wb * ms;
    ca = 1.0 / (1.0 + std::exp(-th[4]));
  };
  // The step's ramp is often shorter than a sample (25 kHz vs a 1 V/us amplifier): its timing
  // within the sample is a fit parameter (theta[5], in samples), and the model runs on a grid 8x
  // finer than the record so that a sub-sample step is represented exactly.
  constexpr int kFine = 8;
  const double hf = h / kFine;
  const double t0 = rec.t_s.front();
  auto equivalent = [&](double u) { return (hysteresis ? pi_loading_curve(*hysteresis, u) : u) - base_h; };
  std::vector<double> fine(static_cast<std::size_t>((n - 1) * kFine + 1));
  const BasisFn basis = [&](const Eigen::VectorXd& th) {
    double r0a, r1a, r0b, r1b, ca;
    unpack(th, r0a, r1a, r0b, r1b, ca);
    const double shift = th[5] * h;
    for (std::size_t k = 0; k < fine.size(); ++k) fine[k] = equivalent(step.value(t0 + k * hf - shift));
    const auto x2 = elastic_slider_response(fine, hf, base.pe, ms, kc, r0a, r1a, r0b, r1b, ca);
    Eigen::MatrixXd phi(n, 2);
    for (Eigen::Index i = 0; i < n; ++i) {
      phi(i, 0) = x2[static_cast<std::size_t>(i * kFine)];
      phi(i, 1) = 1.0;
    }
    return phi;
  };
  VarProResult best;
  best.rms = HUGE_VAL;
  for (double zeta0 : {0.05, 0.3}) {
    for (double c0 : {0.3, 0.7}) {
      Eigen::VectorXd th0(6);
      th0 << std::log(2 * M_PI * f0[0]), std::log(zeta0), std::log(2 * M_PI * f0[1]), std::log(0.05),
          std::log(c0 / (1.0 - c0)), 0.0;
      VarProResult r = fit_varpro(basis, y, th0);
      if (r.rms < best.rms) best = std::move(r);
    }
  }
  double r0a, r1a, r0b, r1b, ca;
  unpack(best.theta, r0a, r1a, r0b, r1b, ca);
  if (r0a > r0b) {
    std::swap(r0a, r0b);
    std::swap(r1a, r1b);
    ca = 1.0 - ca;
  }
  auto mode = [&](double r0, double r1) {
    return ModeEstimate{std::sqrt(r0 / ms) / (2 * M_PI), r1 / (2.0 * std::sqrt(r0 * ms))};
  };
  out.a = mode(r0a, r1a);
  out.b = mode(r0b, r1b);
  out.mass_fraction_a = ca;
  out.step_V = step.u1_V - step.u0_V;
  out.static_gain_m_V = best.coef[0];
  out.rms_m = best.rms;
  out.fitted_m.assign(best.fitted.data(), best.fitted.data() + best.fitted.size());
  const bool ok = std::isfinite(r0a + r0b + r1a + r1b + ca) &&
                  out.b.frequency_Hz > 1.05 * out.a.frequency_Hz && out.a.damping_ratio > 0 &&
                  out.a.damping_ratio < 2 && out.b.damping_ratio > 0 && out.b.damping_ratio < 2 &&
                  ca > 0.01 && ca < 0.99 && out.static_gain_m_V > 0 && out.b.frequency_Hz < 0.5 * fs;
  if (!ok) {
    throw ComputationFailed(fmt::format(
        "{}: friction modal fit did not give two distinct damped modes (f = {:.4g}, {:.4g} Hz, zeta = "
        "{:.3g}, "
        "{:.3g}, c_a = {:.3g}); check that the step stays in scanning mode (no slip)",
        rec.source, out.a.frequency_Hz, out.b.frequency_Hz, out.a.damping_ratio, out.b.damping_ratio, ca));
  }
  FrictionParams p = base.friction;
  p.rho0_a_N_m = r0a;
  p.rho1_a_N_s_m = r1a;
  p.rho0_b_N_m = r0b;
  p.rho1_b_N_s_m = r1b;
  p.mass_fraction_a = ca;
  p.validate();
  out.params = p;
  return out;
}

}  // namespace mc::stickslip
