#include "microcobot/stickslip/ident_pe_modes.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "microcobot/core/error.h"
#include "microcobot/stickslip/ident_modal.h"
#include "microcobot/stickslip/ident_varpro.h"

namespace mc::stickslip {

namespace {

/// H applied to the reconstructed (monotone) step: the PI loading curve from u0.
std::vector<double> equivalent_input(const StepInput& step, const PiParams* pi) {
  std::vector<double> s = step.u_V;
  if (pi) {
    const double base = pi_loading_curve(*pi, step.u0_V);
    for (double& v : s) v = pi_loading_curve(*pi, v) - base;
  } else {
    for (double& v : s) v -= step.u0_V;
  }
  return s;
}

}  // namespace

PeModesResult identify_pe_modes(const MeasuredRecord& rec, const PiezoParams& base,
                                const PiParams* hysteresis) {
  base.validate();
  require_record_length(rec, 256, 0.0, "the PE modes");
  const StepInput step = fit_step_input(rec);
  const double fs = rec.fs_Hz(), h = rec.dt_s();
  // PSD of the dynamic response: resonances between 1 kHz and 0.45 fs.
  const std::vector<double> s = equivalent_input(step, hysteresis);
  const ModePeaks pk = dynamic_response_peaks(rec, s, 2, 1e3, 0.45 * fs);
  PeModesResult out;
  out.psd = pk.psd;
  out.psd_peaks_Hz = pk.peaks_Hz;
  std::vector<double> f0 = pk.peaks_Hz;
  if (f0.empty()) {
    throw ComputationFailed(rec.source + ": no resonance peak in the PSD of the PE step response");
  }
  if (f0.size() == 1) f0 = {f0[0] / 1.5, f0[0] * 1.5};  // one peak: bracket it, LM sorts them out
  const double free_s = rec.t_s.back() - step.t_settled_s();
  if (free_s * f0[0] < 5.0) {
    throw InvalidInput(
        rec.source, 0,
        fmt::format("record too short for the PE modes: {:.3g} s after the step, need >= 5 periods "
                    "of the {:.4g} Hz mode ({:.3g} s)",
                    free_s, f0[0], 5.0 / f0[0]));
  }
  const auto n = static_cast<Eigen::Index>(rec.size());
  const Eigen::VectorXd y = Eigen::Map<const Eigen::VectorXd>(rec.x_m.data(), n);
  // Without a known H, the loading curve's curvature along the step's ramp is a shape common to
  // both modes: s_H = s + s (s - 1) sum_k beta_k (2 s - 1)^k, k = 0..3, in the normalised input
  // s in [0, 1] (beta_k fitted with the modes); with H given, s_H = H(U) (no beta).
  const int n_theta = hysteresis ? 4 : 8;
  const double s_top = s.back() != 0.0 ? s.back() : 1.0;
  std::vector<double> sh(s.size());
  const BasisFn basis = [&](const Eigen::VectorXd& th) {
    for (std::size_t i = 0; i < s.size(); ++i) {
      const double v = s[i] / s_top;
      double shape = 0.0, p = 1.0;
      for (int k = 4; k < n_theta; ++k, p *= 2.0 * v - 1.0) shape += th[k] * p;
      sh[i] = v + v * (v - 1.0) * shape;
    }
    const auto ra = unit_mode_response(sh, h, std::exp(th[0]), std::exp(th[1]));
    const auto rb = unit_mode_response(sh, h, std::exp(th[2]), std::exp(th[3]));
    Eigen::MatrixXd phi(n, 3);
    for (Eigen::Index i = 0; i < n; ++i) {
      phi(i, 0) = ra[static_cast<std::size_t>(i)];
      phi(i, 1) = rb[static_cast<std::size_t>(i)];
      phi(i, 2) = 1.0;
    }
    return phi;
  };
  VarProResult best;
  best.rms = HUGE_VAL;
  for (double zeta0 : {0.03, 0.1}) {
    Eigen::VectorXd th0 = Eigen::VectorXd::Zero(n_theta);
    th0.head<4>() << std::log(2 * M_PI * f0[0]), std::log(zeta0), std::log(2 * M_PI * f0[1]), std::log(zeta0);
    VarProResult r = fit_varpro(basis, y, th0);
    if (r.rms < best.rms) best = std::move(r);
  }
  Eigen::VectorXd th = best.theta;
  double ca = best.coef[0], cb = best.coef[1];  // static contributions (s_H = 1 after the step)
  if (th[0] > th[2]) {
    std::swap(th[0], th[2]);
    std::swap(th[1], th[3]);
    std::swap(ca, cb);
  }
  out.a = {std::exp(th[0]) / (2 * M_PI), std::exp(th[1])};
  out.b = {std::exp(th[2]) / (2 * M_PI), std::exp(th[3])};
  const double du = step.u1_V - step.u0_V;
  out.step_V = du;
  // g: static displacement per (equivalent) volt of the step.
  out.static_gain_m_V = (ca + cb) / s_top;
  out.gain_fraction_a = ca / (ca + cb);
  out.rms_m = best.rms;
  out.fitted_m.assign(best.fitted.data(), best.fitted.data() + best.fitted.size());
  const bool ok = std::isfinite(out.a.frequency_Hz) && std::isfinite(out.b.frequency_Hz) &&
                  out.b.frequency_Hz > 1.05 * out.a.frequency_Hz && out.a.damping_ratio > 0 &&
                  out.a.damping_ratio < 1 && out.b.damping_ratio > 0 && out.b.damping_ratio < 1 &&
                  out.static_gain_m_V > 0 && out.gain_fraction_a > 0 && out.gain_fraction_a < 1 &&
                  out.b.frequency_Hz < 0.5 * fs;
  if (!ok) {
    throw ComputationFailed(
        fmt::format("{}: PE modal fit did not give two distinct damped modes (f = {:.4g}, {:.4g} Hz, zeta = "
                    "{:.3g}, {:.3g}, "
                    "phi = {:.3g}); check that the record is a PE step response sampled fast enough",
                    rec.source, out.a.frequency_Hz, out.b.frequency_Hz, out.a.damping_ratio,
                    out.b.damping_ratio, out.gain_fraction_a));
  }
  PiezoParams p = base;
  const double wa = 2 * M_PI * out.a.frequency_Hz, wb = 2 * M_PI * out.b.frequency_Hz;
  p.stiffness_a_N_m = p.mass_kg * wa * wa;
  p.damping_a_N_s_m = 2.0 * out.a.damping_ratio * wa * p.mass_kg;
  p.stiffness_b_N_m = p.mass_kg * wb * wb;
  p.damping_b_N_s_m = 2.0 * out.b.damping_ratio * wb * p.mass_kg;
  p.gain_fraction_a = out.gain_fraction_a;
  p.static_gain_m_V = out.static_gain_m_V;
  p.validate();
  out.params = p;
  return out;
}

}  // namespace mc::stickslip
