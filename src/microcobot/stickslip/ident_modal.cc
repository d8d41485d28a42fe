#include "microcobot/stickslip/ident_modal.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <fmt/format.h>

#include "microcobot/core/error.h"
#include "microcobot/dsp/peaks.h"
#include "microcobot/stickslip/ident_varpro.h"
#include "microcobot/stickslip/piezo_element.h"

namespace mc::stickslip {

double StepInput::value(double t) const {
  if (t_ramp_s <= 0.0) return t >= t_start_s ? u1_V : u0_V;
  const double f = std::clamp((t - t_start_s) / t_ramp_s, 0.0, 1.0);
  return u0_V + (u1_V - u0_V) * f;
}

StepInput fit_step_input(const MeasuredRecord& rec) {
  const std::size_t n = rec.size();
  const auto& u = rec.u_V;
  // Final level: mean of the last half; its noise from the spread there.
  const std::size_t half = n / 2;
  double u1 = 0.0;
  for (std::size_t i = half; i < n; ++i) u1 += u[i];
  u1 /= static_cast<double>(n - half);
  double var = 0.0;
  for (std::size_t i = half; i < n; ++i) var += (u[i] - u1) * (u[i] - u1);
  const double sigma = std::sqrt(var / static_cast<double>(n - half));
  const double u0 = u[0];
  const double du = u1 - u0;
  if (!(std::abs(du) >= 1.0 && std::abs(du) >= 6.0 * sigma)) {
    throw InvalidInput(
        rec.source, 0,
        fmt::format("no voltage step in u_V (change {:.3g} V, noise {:.3g} V): a step response is "
                    "needed",
                    du, sigma));
  }
  // Smooth (5-sample mean) and find the 10% and 90% crossings, linearly interpolated.
  std::vector<double> sm(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t a = i >= 2 ? i - 2 : 0, b = std::min(n - 1, i + 2);
    double s = 0.0;
    for (std::size_t k = a; k <= b; ++k) s += u[k];
    sm[i] = s / static_cast<double>(b - a + 1);
  }
  auto crossing = [&](double level) {
    for (std::size_t i = 1; i < n; ++i) {
      const double a = (sm[i - 1] - u0) / du, b = (sm[i] - u0) / du;
      if (a < level && b >= level)
        return rec.t_s[i - 1] + (level - a) / (b - a) * (rec.t_s[i] - rec.t_s[i - 1]);
    }
    return rec.t_s.front();
  };
  const double t10 = crossing(0.1), t90 = crossing(0.9);
  // Refine the ramp's start and length by least squares on the raw samples (levels linear).
  const double dt = rec.dt_s();
  const double t_ref = rec.t_s.front();
  const double ramp0 = std::max((t90 - t10) / 0.8 - 4.0 * dt, 0.5 * dt);
  const double start0 = 0.5 * (t10 + t90) - 0.5 * ramp0;
  auto shape = [&](double start, double ramp, double t) { return std::clamp((t - start) / ramp, 0.0, 1.0); };
  const BasisFn basis = [&](const Eigen::VectorXd& th) {
    const double start = t_ref + th[0] * dt, ramp = std::exp(th[1]) * dt;
    Eigen::MatrixXd phi(static_cast<Eigen::Index>(n), 2);
    for (std::size_t i = 0; i < n; ++i) {
      phi(static_cast<Eigen::Index>(i), 0) = 1.0;
      phi(static_cast<Eigen::Index>(i), 1) = shape(start, ramp, rec.t_s[i]);
    }
    return phi;
  };
  Eigen::VectorXd y = Eigen::Map<const Eigen::VectorXd>(u.data(), static_cast<Eigen::Index>(n));
  Eigen::VectorXd th0(2);
  th0 << (start0 - t_ref) / dt, std::log(ramp0 / dt);
  const VarProResult fit = fit_varpro(basis, y, th0, 200);
  StepInput s;
  s.u0_V = fit.coef[0];
  s.u1_V = fit.coef[0] + fit.coef[1];
  s.t_start_s = t_ref + fit.theta[0] * dt;
  s.t_ramp_s = std::exp(fit.theta[1]) * dt;
  if (!(std::isfinite(s.t_start_s) && std::isfinite(s.t_ramp_s))) {
    s.t_start_s = start0;
    s.t_ramp_s = ramp0;
  }
  s.u_V.resize(n);
  for (std::size_t i = 0; i < n; ++i) s.u_V[i] = s.value(rec.t_s[i]);
  std::size_t after = 0;
  for (double t : rec.t_s) after += t > s.t_settled_s() ? 1 : 0;
  if (after < 64) {
    throw InvalidInput(
        rec.source, 0,
        fmt::format("record too short for a step response: {} samples after the step (need >= 64)", after));
  }
  return s;
}

ModePeaks dynamic_response_peaks(const MeasuredRecord& rec, const std::vector<double>& static_input,
                                 int count, double f_min_Hz, double f_max_Hz) {
  const auto n = static_cast<Eigen::Index>(rec.size());
  Eigen::MatrixXd a(n, 2);
  for (Eigen::Index i = 0; i < n; ++i) {
    a(i, 0) = 1.0;
    a(i, 1) = static_input[static_cast<std::size_t>(i)];
  }
  const Eigen::VectorXd y = Eigen::Map<const Eigen::VectorXd>(rec.x_m.data(), n);
  const Eigen::VectorXd c = a.colPivHouseholderQr().solve(y);
  const Eigen::VectorXd r = y - a * c;
  // Positions near the largest double (1e308 is finite, and no measured position) overflow the
  // static fit or the spectrum: named by the record's column, not by the peak finder that
  // would meet the infinities.
  const auto overflow = [&] {
    double top = 0.0, top_u = 0.0;
    for (double x : rec.x_m) top = std::max(top, std::abs(x));
    for (double u : rec.u_V) top_u = std::max(top_u, std::abs(u));
    // Positions within a metre (any positioner's) and a voltage beyond any amplifier's: the input.
    if (top <= 1.0 && top_u > 1e150)
      return InvalidInput(rec.source, 0,
                          fmt::format("column 'u_V': the static fit overflows (values up to {:g} V): not a "
                                      "measured voltage",
                                      top_u));
    return InvalidInput(
        rec.source, 0,
        fmt::format("column 'x_m': the response's power spectrum overflows (values up to {:g} m): "
                    "not a measured position",
                    top));
  };
  if (!r.allFinite()) throw overflow();
  std::vector<double> seg(r.data(), r.data() + r.size());
  dsp::WelchOptions o;
  o.fs_Hz = rec.fs_Hz();
  o.nperseg = std::min<std::size_t>(256, seg.size());
  o.noverlap = o.nperseg / 2;
  o.nfft = 8 * o.nperseg;
  o.detrend = dsp::Detrend::kConstant;
  ModePeaks out;
  try {
    out.psd = dsp::welch(seg, o);
  } catch (const dsp::SpectrumOverflow&) {
    throw overflow();
  }
  std::vector<double> logp(out.psd.value.size());
  for (std::size_t i = 0; i < logp.size(); ++i) logp[i] = std::log(std::max(out.psd.value[i], 1e-300));
  dsp::PeakOptions po;
  auto peaks = dsp::find_peaks_xy(out.psd.f_Hz, logp, po);
  std::erase_if(peaks, [&](const dsp::Peak& p) { return p.x < f_min_Hz || p.x > f_max_Hz; });
  std::sort(peaks.begin(), peaks.end(),
            [](const auto& p1, const auto& p2) { return p1.prominence > p2.prominence; });
  if (peaks.size() > static_cast<std::size_t>(count)) peaks.resize(static_cast<std::size_t>(count));
  for (const auto& p : peaks) out.peaks_Hz.push_back(p.x);
  std::sort(out.peaks_Hz.begin(), out.peaks_Hz.end());
  return out;
}

std::vector<double> unit_mode_response(const std::vector<double>& s, double h, double omega_rad_s,
                                       double zeta) {
  const double w2 = omega_rad_s * omega_rad_s;
  const ModeDiscretization d = ModeDiscretization::make(1.0, 2.0 * zeta * omega_rad_s, w2, h);
  std::vector<double> x(s.size());
  if (s.empty()) return x;
  double xi = s[0], vi = 0.0;
  x[0] = xi;
  for (std::size_t k = 1; k < s.size(); ++k) {
    d.step(xi, vi, w2 * s[k - 1], w2 * s[k]);
    x[k] = xi;
  }
  return x;
}

}  // namespace mc::stickslip
