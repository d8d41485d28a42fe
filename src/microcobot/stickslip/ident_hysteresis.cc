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
  // Wiping-out: after the input has come within 1% of both extremes, every operator's state is
  // set by the input alone. Fit from there, and require a further half excursion to be recorded.
  const double tol = 0.01 * range;
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
  const bool from_rest = std::abs(u[0] - u_min) <= tol;
  if (from_rest) first = 0;
  PiParams pi;
  pi.thresholds_V = pi_thresholds(from_rest ? 2.0 * range : range, operators);
  pi.weights.assign(static_cast<std::size_t>(operators), 1.0);
  PiState st = make_pi_state(pi, u[0]);
  const auto m = static_cast<Eigen::Index>(n - first);
  const auto k = static_cast<Eigen::Index>(operators);
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
  if (from_rest) {
    // Offset = the rest position (mean of the first samples); operators start relaxed at u[0].
    const Eigen::Index k0 = std::min<Eigen::Index>(5, m);
    b_mean = b.head(k0).mean();
    a_mean = a.topRows(k0).colwise().mean();
  }
  a.rowwise() -= a_mean;
  b.array() -= b_mean;
  // Scale both sides to O(1) so that NNLS works on a well-conditioned problem.
  const double b_scale = std::max(b.cwiseAbs().maxCoeff(), 1e-300);
  const ident::NnlsResult sol = ident::nnls(a / range, b / b_scale);
  Eigen::VectorXd w = sol.x * (b_scale / range);
  double total = w.sum();
  if (!(total > 0.0) || !w.allFinite()) {
    throw ComputationFailed(rec.source +
                            ": hysteresis fit gave no positive weight (the position does not follow "
                            "the voltage)");
  }
  // Invertibility needs w_0 > 0 (eq. of pi_inverse); a vanishing w_0 is lifted to 0.1% of the sum.
  w[0] = std::max(w[0], 1e-3 * total);
  const double x0 = b_mean - a_mean.dot(w);
  HysteresisResult out;
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
  const Eigen::VectorXd fit = y_all * w;
  out.fitted_m.resize(n);
  double ss = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    out.fitted_m[i] = x0 + fit[static_cast<Eigen::Index>(i)];
    if (i >= first) ss += (rec.x_m[i] - out.fitted_m[i]) * (rec.x_m[i] - out.fitted_m[i]);
  }
  out.rms_m = std::sqrt(ss / static_cast<double>(m));
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
