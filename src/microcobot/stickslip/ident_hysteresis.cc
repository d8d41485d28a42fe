#include "microcobot/stickslip/ident_hysteresis.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <Eigen/Dense>

#include "microcobot/core/error.h"
#include "microcobot/ident/nnls.h"
#include "microcobot/stickslip/ident_friction_modes.h"

namespace mc::stickslip {

std::vector<double> pi_thresholds(double range_V, int operators) {
  std::vector<double> r(static_cast<std::size_t>(operators));
  for (int i = 0; i < operators; ++i) {
    const double f = static_cast<double>(i) / static_cast<double>(operators);
    r[static_cast<std::size_t>(i)] = 0.5 * range_V * f * f;
  }
  return r;
}

namespace {

/// RMS of the white noise on a slowly varying record, from its second differences: for white
/// noise of variance s^2, d2 = u[i+1] - 2 u[i] + u[i-1] has variance 6 s^2, while a sine of
/// amplitude A sampled N times a period contributes at most A (2 pi / N)^2 (5e-3 V for 40 V at
/// 50 Hz and 25 kHz). The median absolute value (x 1.4826) ignores the rare spike.
double voltage_noise_rms(const std::vector<double>& u) {
  if (u.size() < 8) return 0.0;
  std::vector<double> d(u.size() - 2);
  for (std::size_t i = 1; i + 1 < u.size(); ++i) d[i - 1] = std::abs(u[i + 1] - 2.0 * u[i] + u[i - 1]);
  std::nth_element(d.begin(), d.begin() + static_cast<long>(d.size() / 2), d.end());
  return 1.4826 * d[d.size() / 2] / std::sqrt(6.0);
}

/// One hypothesis fitted: weights w (>= 0, as the operators' outputs scale), offset x0, the fit at
/// every sample and its RMS over the fitted samples [first, n).
struct PiFit {
  Eigen::VectorXd w;
  double x0 = 0.0, rms = 0.0;
  Eigen::VectorXd fit;  ///< y_all w (without x0)
};

/// x(t) = x0 + sum_i w_i y_i(t) by NNLS (thesis §2.5.2.2 (iii)-(iv)) over samples [first, n), the
/// operators starting in `initial`; the offset is the mean of the first 5 samples (`rest_offset`,
/// the record starts at rest) or free. Operator outputs pass through the slider's elastic
/// response when `dynamics` is given (its lag at the drive frequency is not hysteresis).
PiFit fit_pi(const MeasuredRecord& rec, const std::vector<double>& u, const PiParams& pi, PiState st,
             std::size_t first, bool rest_offset, const StickSlipParams* dynamics, double range) {
  const std::size_t n = u.size();
  const auto m = static_cast<Eigen::Index>(n - first);
  const auto k = static_cast<Eigen::Index>(pi.size());
  Eigen::MatrixXd y_all(static_cast<Eigen::Index>(n), k);
  for (std::size_t i = 0; i < n; ++i) {
    pi_update(pi, st, u[i]);
    for (Eigen::Index j = 0; j < k; ++j)
      y_all(static_cast<Eigen::Index>(i), j) = st.y[static_cast<std::size_t>(j)];
  }
  if (dynamics) {
    const auto& d = *dynamics;
    std::vector<double> col(n);
    for (Eigen::Index j = 0; j < k; ++j) {
      for (std::size_t i = 0; i < n; ++i) col[i] = y_all(static_cast<Eigen::Index>(i), j);
      const auto f =
          elastic_slider_response(col, rec.dt_s(), d.pe, d.slider.mass_kg, d.friction.coupling_stiffness_N_m,
                                  d.friction.rho0_a_N_m, d.friction.rho1_a_N_s_m, d.friction.rho0_b_N_m,
                                  d.friction.rho1_b_N_s_m, d.friction.mass_fraction_a);
      for (std::size_t i = 0; i < n; ++i) y_all(static_cast<Eigen::Index>(i), j) = f[i];
    }
  }
  // Centre: the free offset x0 drops out of the non-negative problem.
  Eigen::MatrixXd a = y_all.bottomRows(m);
  Eigen::VectorXd b = Eigen::Map<const Eigen::VectorXd>(rec.x_m.data() + first, m);
  Eigen::RowVectorXd a_mean = a.colwise().mean();
  double b_mean = b.mean();
  if (rest_offset) {
    // Offset = the rest position (mean of the first samples).
    const Eigen::Index k0 = std::min<Eigen::Index>(5, m);
    b_mean = b.head(k0).mean();
    a_mean = a.topRows(k0).colwise().mean();
  }
  a.rowwise() -= a_mean;
  b.array() -= b_mean;
  // Scale both sides to O(1) so that NNLS works on a well-conditioned problem.
  const double b_scale = std::max(b.cwiseAbs().maxCoeff(), 1e-300);
  const ident::NnlsResult sol = ident::nnls(a / range, b / b_scale);
  PiFit out;
  out.w = sol.x * (b_scale / range);
  const double total = out.w.sum();
  if (!(total > 0.0) || !out.w.allFinite()) {
    throw ComputationFailed(rec.source +
                            ": hysteresis fit gave no positive weight (the position does not follow "
                            "the voltage)");
  }
  // Invertibility needs w_0 > 0 (eq. of pi_inverse); a vanishing w_0 is lifted to 0.1% of the sum.
  out.w[0] = std::max(out.w[0], 1e-3 * total);
  out.x0 = b_mean - a_mean.dot(out.w);
  out.fit = y_all * out.w;
  double ss = 0.0;
  for (std::size_t i = first; i < n; ++i) {
    const double e = rec.x_m[i] - out.x0 - out.fit[static_cast<Eigen::Index>(i)];
    ss += e * e;
  }
  out.rms = std::sqrt(ss / static_cast<double>(m));
  return out;
}

}  // namespace

HysteresisResult identify_hysteresis(const MeasuredRecord& rec, int operators,
                                     const StickSlipParams* dynamics) {
  if (operators < 1 || operators > 200) {
    throw UsageError(fmt::format("--operators must be in 1..200 (got {})", operators));
  }
  require_record_length(rec, static_cast<std::size_t>(4 * operators), 0.0, "the hysteresis");
  const std::size_t n = rec.size();
  // Light smoothing of the recorded voltage (5-sample centred mean): the voltage noise would
  // otherwise chatter the narrow operators; a drive far slower than the sampling is unchanged.
  std::vector<double> u(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t a = i >= 2 ? i - 2 : 0, b = std::min(n - 1, i + 2);
    double s = 0.0;
    for (std::size_t k = a; k <= b; ++k) s += rec.u_V[k];
    u[i] = s / static_cast<double>(b - a + 1);
  }
  const auto [it_min, it_max] = std::minmax_element(u.begin(), u.end());
  const double u_min = *it_min, u_max = *it_max, range = u_max - u_min;
  if (!std::isfinite(range)) {
    throw InvalidInput(rec.source, 0,
                       fmt::format("column 'u_V': the voltage range overflows (values up to {:g} V): not a "
                                   "measured voltage",
                                   std::max(std::abs(*std::min_element(rec.u_V.begin(), rec.u_V.end())),
                                            std::abs(*std::max_element(rec.u_V.begin(), rec.u_V.end())))));
  }
  if (!(range >= 1.0)) {
    throw InvalidInput(
        rec.source, 0,
        fmt::format("the voltage spans only {:.3g} V: the hysteresis needs a sine of >= 1 V", range));
  }
  // The extremes of a noisy record are its noise's extremes (about 3.5 sigma beyond the drive's
  // over a few thousand samples): "near an extreme" allows 1% of the range or 4 sigma of the
  // smoothed noise, whichever is larger (at 0.5 V RMS on a 40 V sine 1% alone missed a trough of
  // a two-period record in 1 % of noise draws).
  const double noise_V = voltage_noise_rms(rec.u_V) / std::sqrt(5.0);
  const double tol = std::max(0.01 * range, 4.0 * noise_V);
  // Wiping-out: after the input has come near both extremes, every operator's state is set by
  // the input alone. Fit from there, and require a further half excursion to be recorded.
  std::size_t first = n;
  bool seen_lo = false, seen_hi = false;
  for (std::size_t i = 0; i < n; ++i) {
    seen_lo = seen_lo || u[i] <= u_min + tol;
    seen_hi = seen_hi || u[i] >= u_max - tol;
    if (seen_lo && seen_hi) {
      first = i;
      break;
    }
  }
  std::size_t next_extreme = n;
  if (first < n) {
    const bool at_hi = u[first] >= u_max - tol;
    for (std::size_t i = first; i < n; ++i) {
      if (at_hi ? u[i] <= u_min + tol : u[i] >= u_max - tol) {
        next_extreme = i;
        break;
      }
    }
  }
  if (next_extreme >= n || n - first < static_cast<std::size_t>(2 * operators)) {
    throw InvalidInput(
        rec.source, 0,
        "record too short for the hysteresis: it must contain a full excursion min -> max -> min "
        "(at least one sine period)");
  }
  // A record that starts at rest at its lowest voltage (the thesis's curve "shifted in the
  // positive section") also shows the initial loading: operators wider than half the range, which
  // after the first excursion only hold an offset, are then identifiable, so the thresholds span
  // the whole range and every sample is fitted with the offset fixed to the rest position.
  // Whether it does is decided from the whole record, not from its first noisy samples: a record
  // that starts near its lowest voltage is fitted both ways over all its samples, from rest
  // (operators relaxed) and as a steady loop (operators as a full excursion leaves them, free
  // offset), and the hypothesis with the smaller RMS residual is kept. The two differ by the
  // initial loading curve, which lies tens of nanometres from the loop's ascending branch, far
  // above the position noise.
  PiParams rest_pi, loop_pi;
  rest_pi.thresholds_V = pi_thresholds(2.0 * range, operators);
  loop_pi.thresholds_V = pi_thresholds(range, operators);
  rest_pi.weights.assign(static_cast<std::size_t>(operators), 1.0);
  loop_pi.weights = rest_pi.weights;
  // "Near": the first five samples' mean within the lowest tenth of the range (and the noise's
  // reach): generous on purpose, the fits decide; a record starting higher up cannot be at rest
  // at its lowest voltage.
  double start_V = 0.0;
  for (std::size_t i = 0; i < 5; ++i) start_V += rec.u_V[i] / 5.0;
  const bool near_lowest = start_V - u_min <= 0.1 * range + tol;
  bool from_rest = false;
  PiFit chosen;
  double rms_rest = std::nan(""), rms_loop = std::nan("");
  if (near_lowest) {
    PiFit rest = fit_pi(rec, u, rest_pi, make_pi_state(rest_pi, u[0]), 0, true, dynamics, range);
    PiState after = make_pi_state(loop_pi, u[0]);
    pi_update(loop_pi, after, u_max);
    pi_update(loop_pi, after, u[0]);
    const PiFit loop = fit_pi(rec, u, loop_pi, after, 0, false, dynamics, range);
    rms_rest = rest.rms;
    rms_loop = loop.rms;
    from_rest = rest.rms <= loop.rms;
    if (from_rest) chosen = std::move(rest);
  }
  if (from_rest) first = 0;
  const PiParams& pi = from_rest ? rest_pi : loop_pi;
  if (!from_rest) chosen = fit_pi(rec, u, pi, make_pi_state(pi, u[0]), first, false, dynamics, range);
  const Eigen::VectorXd& w = chosen.w;
  const auto k = static_cast<Eigen::Index>(operators);
  const double x0 = chosen.x0;
  HysteresisResult out;
  out.from_rest = from_rest;
  out.rms_from_rest_m = rms_rest;
  out.rms_steady_loop_m = rms_loop;
  out.voltage_noise_V = noise_V * std::sqrt(5.0);
  out.first_fitted = first;
  out.offset_m = x0;
  // g: loading curve maps u_max to u_max.
  PiParams unit = pi;
  for (Eigen::Index j = 0; j < k; ++j) unit.weights[static_cast<std::size_t>(j)] = w[j];
  const double g = pi_loading_curve(unit, u_max) / u_max;
  if (!(g > 0.0)) throw ComputationFailed(rec.source + ": hysteresis fit has zero static gain");
  for (double& v : unit.weights) v /= g;
  unit.validate();
  out.pi = unit;
  out.static_gain_m_V = g;
  out.inverse = pi_inverse(unit);
  out.fitted_m.resize(n);
  for (std::size_t i = 0; i < n; ++i) out.fitted_m[i] = x0 + chosen.fit[static_cast<Eigen::Index>(i)];
  out.rms_m = chosen.rms;
  const auto [x_lo, x_hi] = std::minmax_element(rec.x_m.begin() + static_cast<long>(first), rec.x_m.end());
  out.stroke_m = *x_hi - *x_lo;
  out.rms_fraction = out.stroke_m > 0 ? out.rms_m / out.stroke_m : 0.0;
  // Inverse check along the record: H^-1(H(U)) = U.
  PiState sf = make_pi_state(out.pi, 0.0), si = make_pi_state(out.inverse, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    const double hu = pi_update(out.pi, sf, std::max(u[i], 0.0));
    const double back = pi_update(out.inverse, si, hu);
    out.inverse_max_error_V = std::max(out.inverse_max_error_V, std::abs(back - std::max(u[i], 0.0)));
  }
  return out;
}

}  // namespace mc::stickslip
