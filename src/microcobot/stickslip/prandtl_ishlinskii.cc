#include "microcobot/stickslip/prandtl_ishlinskii.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "microcobot/core/error.h"

namespace mc::stickslip {

void PiParams::validate() const {
  require(!thresholds_V.empty(), "hysteresis.thresholds_V", "must hold at least one operator");
  require(thresholds_V.size() == weights.size(), "hysteresis.weights",
          "must have as many entries as thresholds_V", static_cast<double>(weights.size()));
  double partial = 0.0;
  for (std::size_t i = 0; i < thresholds_V.size(); ++i) {
    const std::string idx = "[" + std::to_string(i) + "]";
    require(std::isfinite(thresholds_V[i]) && thresholds_V[i] >= 0.0, "hysteresis.thresholds_V" + idx,
            "must be >= 0", thresholds_V[i]);
    if (i > 0) {
      require(thresholds_V[i] > thresholds_V[i - 1], "hysteresis.thresholds_V" + idx,
              "must be strictly increasing", thresholds_V[i]);
    }
    require(std::isfinite(weights[i]), "hysteresis.weights" + idx, "must be finite", weights[i]);
    partial += weights[i];
    require(partial > 0.0, "hysteresis.weights" + idx, "partial sums must stay > 0 (invertible PI model)",
            partial);
  }
  require(weights[0] > 0.0, "hysteresis.weights[0]", "must be > 0", weights[0]);
}

PiParams default_pi_params(int n) {
  PiParams p;
  // Non-uniform partition of 0..100 V: finer at low voltage, where the thesis's loops (Fig. 2.12)
  // bend most (thesis §2.5.2.2 (iv): "n+1 non uniform partitions").
  const double span = 100.0;
  for (int i = 0; i < n; ++i) {
    const double f = static_cast<double>(i) / static_cast<double>(n);
    p.thresholds_V.push_back(0.5 * span * f * f);
  }
  // w_0 carries the linear part; the rest decay geometrically (loop width ~11% of the stroke).
  const double w0 = 0.80;
  double sum_rest = 0.0;
  std::vector<double> rest;
  for (int i = 1; i < n; ++i) {
    rest.push_back(std::exp(-3.0 * static_cast<double>(i) / static_cast<double>(n)));
    sum_rest += rest.back();
  }
  p.weights.push_back(w0);
  for (double r : rest) p.weights.push_back((1.0 - w0) * r / sum_rest * 4.0);
  // Normalise so that the loading curve maps 100 V to 100 V equivalent.
  const double top = pi_loading_curve(p, span);
  for (double& w : p.weights) w *= span / top;
  return p;
}

PiState make_pi_state(const PiParams& p, double u0) {
  PiState s;
  s.y.assign(p.size(), 0.0);
  for (std::size_t i = 0; i < p.size(); ++i) {
    s.y[i] = std::max(u0 - p.thresholds_V[i], std::min(u0 + p.thresholds_V[i], 0.0));
  }
  return s;
}

double pi_update(const PiParams& p, PiState& s, double u) noexcept {
  double out = 0.0;
  const std::size_t n = s.y.size();
  for (std::size_t i = 0; i < n; ++i) {
    const double r = p.thresholds_V[i];
    const double y = std::max(u - r, std::min(u + r, s.y[i]));
    s.y[i] = y;
    out += p.weights[i] * y;
  }
  return out;
}

double pi_peek(const PiParams& p, const PiState& s, double u) noexcept {
  double out = 0.0;
  const std::size_t n = s.y.size();
  for (std::size_t i = 0; i < n; ++i) {
    const double r = p.thresholds_V[i];
    out += p.weights[i] * std::max(u - r, std::min(u + r, s.y[i]));
  }
  return out;
}

double pi_peek_inverse(const PiParams& p, const PiState& s, double h, double u_lo, double u_hi) noexcept {
  double f_lo = pi_peek(p, s, u_lo) - h;
  if (f_lo >= 0.0) return u_lo;
  double f_hi = pi_peek(p, s, u_hi) - h;
  if (f_hi <= 0.0) return u_hi;
  const double resolution = std::ldexp(u_hi - u_lo, -40);
  double best_u = u_lo, best_f = -f_lo;  // the evaluated input nearest the root, |residual|
  if (f_hi < best_f) best_u = u_hi, best_f = f_hi;
  int retained = 0;  // the end the last step kept (-1 low, +1 high); kept twice, its residual is halved
  for (int i = 0; i < 200 && u_hi - u_lo > resolution; ++i) {
    const double u = std::clamp((u_lo * f_hi - u_hi * f_lo) / (f_hi - f_lo), u_lo, u_hi);
    const double f = pi_peek(p, s, u) - h;
    if (std::abs(f) < best_f) best_u = u, best_f = std::abs(f);
    if (f == 0.0) break;
    if (f < 0.0) {
      u_lo = u, f_lo = f;
      if (retained == 1) f_hi *= 0.5;
      retained = 1;
    } else {
      u_hi = u, f_hi = f;
      if (retained == -1) f_lo *= 0.5;
      retained = -1;
    }
  }
  return best_u;
}

double pi_loading_curve(const PiParams& p, double u) noexcept {
  double out = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) out += p.weights[i] * std::max(u - p.thresholds_V[i], 0.0);
  return out;
}

PiParams pi_inverse(const PiParams& p) {
  p.validate();
  const std::size_t n = p.size();
  PiParams q;
  q.thresholds_V.resize(n);
  q.weights.resize(n);
  // r'_i = sum_{j<=i} w_j (r_i - r_j);  w'_0 = 1/w_0;
  // w'_i = -w_i / ((w_0 + ... + w_i)(w_0 + ... + w_{i-1})).
  double partial_prev = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    double r = 0.0;
    for (std::size_t j = 0; j <= i; ++j) r += p.weights[j] * (p.thresholds_V[i] - p.thresholds_V[j]);
    q.thresholds_V[i] = r;
    const double partial = partial_prev + p.weights[i];
    q.weights[i] = (i == 0) ? 1.0 / p.weights[0] : -p.weights[i] / (partial * partial_prev);
    partial_prev = partial;
  }
  return q;
}

}  // namespace mc::stickslip
