#include "microcobot/ident/tf_fit.h"

#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include <Eigen/Dense>

#include "microcobot/core/error.h"

namespace mc::ident {
namespace {

using Cplx = std::complex<double>;

// Polynomial with coefficients c[0] + c[1] x + ... (lowest power first), for the fit.
Cplx eval_low(const Eigen::VectorXd& c, Eigen::Index count, Eigen::Index offset, Cplx x) {
  Cplx acc(0, 0);
  for (Eigen::Index i = count; i-- > 0;) acc = acc * x + c(offset + i);
  return acc;
}

struct Problem {
  std::vector<Cplx> x, h;
  std::vector<double> w;     // weights of the refinement's error
  std::vector<double> w_sk;  // weights of the (complex) Sanathanan-Koerner start
  int nz, np;
  bool log_magnitude = false;
  // Parameters p = [b_0..b_nz, a_0..a_{np-1}], D = x^np + sum a_i x^i.
  Cplx num(const Eigen::VectorXd& p, Cplx xi) const { return eval_low(p, nz + 1, 0, xi); }
  Cplx den(const Eigen::VectorXd& p, Cplx xi) const { return eval_low(p, np, nz + 1, xi) + std::pow(xi, np); }
  Eigen::Index params() const { return nz + 1 + np; }
};

Eigen::VectorXd sanathanan_koerner(const Problem& pb, int iterations) {
  const auto m = static_cast<Eigen::Index>(pb.x.size());
  const Eigen::Index np = pb.params();
  Eigen::VectorXd p = Eigen::VectorXd::Zero(np);
  std::vector<double> inv_d(pb.x.size(), 1.0);
  for (int it = 0; it < iterations; ++it) {
    Eigen::MatrixXd a(2 * m, np);
    Eigen::VectorXd rhs(2 * m);
    for (Eigen::Index k = 0; k < m; ++k) {
      const auto uk = static_cast<std::size_t>(k);
      const double s = pb.w_sk[uk] * inv_d[uk];
      const Cplx xk = pb.x[uk], hk = pb.h[uk];
      Cplx xp(1, 0);
      for (int i = 0; i <= pb.nz; ++i, xp *= xk) {
        a(2 * k, i) = s * xp.real();
        a(2 * k + 1, i) = s * xp.imag();
      }
      xp = Cplx(1, 0);
      for (int i = 0; i < pb.np; ++i, xp *= xk) {
        const Cplx v = -hk * xp;
        a(2 * k, pb.nz + 1 + i) = s * v.real();
        a(2 * k + 1, pb.nz + 1 + i) = s * v.imag();
      }
      const Cplx r = hk * std::pow(xk, pb.np);
      rhs(2 * k) = s * r.real();
      rhs(2 * k + 1) = s * r.imag();
    }
    const Eigen::VectorXd next = a.colPivHouseholderQr().solve(rhs);
    const double change = (next - p).norm() / std::max(next.norm(), 1e-300);
    p = next;
    for (std::size_t k = 0; k < pb.x.size(); ++k) inv_d[k] = 1.0 / std::abs(pb.den(p, pb.x[k]));
    if (change < 1e-14) break;
  }
  return p;
}

// Log-magnitude error w (ln|N/D| - ln|H|); d ln|N| / d b_i = Re(x^i / N), likewise for D.
Eigen::VectorXd log_magnitude_residual(const Problem& pb, const Eigen::VectorXd& p, Eigen::MatrixXd* jac) {
  const auto m = static_cast<Eigen::Index>(pb.x.size());
  Eigen::VectorXd r(m);
  if (jac) jac->resize(m, pb.params());
  for (Eigen::Index k = 0; k < m; ++k) {
    const auto uk = static_cast<std::size_t>(k);
    const Cplx xk = pb.x[uk];
    const Cplx n = pb.num(p, xk), d = pb.den(p, xk);
    r(k) = pb.w[uk] * (std::log(std::abs(n)) - std::log(std::abs(d)) - std::log(std::abs(pb.h[uk])));
    if (jac) {
      Cplx xp(1, 0);
      for (int i = 0; i <= pb.nz; ++i, xp *= xk) (*jac)(k, i) = pb.w[uk] * (xp / n).real();
      xp = Cplx(1, 0);
      for (int i = 0; i < pb.np; ++i, xp *= xk) (*jac)(k, pb.nz + 1 + i) = -pb.w[uk] * (xp / d).real();
    }
  }
  return r;
}

Eigen::VectorXd residual(const Problem& pb, const Eigen::VectorXd& p, Eigen::MatrixXd* jac) {
  if (pb.log_magnitude) return log_magnitude_residual(pb, p, jac);
  const auto m = static_cast<Eigen::Index>(pb.x.size());
  Eigen::VectorXd r(2 * m);
  if (jac) jac->resize(2 * m, pb.params());
  for (Eigen::Index k = 0; k < m; ++k) {
    const auto uk = static_cast<std::size_t>(k);
    const Cplx xk = pb.x[uk];
    const Cplx n = pb.num(p, xk), d = pb.den(p, xk);
    const Cplx e = pb.w[uk] * (n / d - pb.h[uk]);
    r(2 * k) = e.real();
    r(2 * k + 1) = e.imag();
    if (jac) {
      Cplx xp(1, 0);
      for (int i = 0; i <= pb.nz; ++i, xp *= xk) {
        const Cplx v = pb.w[uk] * xp / d;
        (*jac)(2 * k, i) = v.real();
        (*jac)(2 * k + 1, i) = v.imag();
      }
      xp = Cplx(1, 0);
      for (int i = 0; i < pb.np; ++i, xp *= xk) {
        const Cplx v = -pb.w[uk] * n * xp / (d * d);
        (*jac)(2 * k, pb.nz + 1 + i) = v.real();
        (*jac)(2 * k + 1, pb.nz + 1 + i) = v.imag();
      }
    }
  }
  return r;
}

Eigen::VectorXd levenberg_marquardt(const Problem& pb, Eigen::VectorXd p, int iterations) {
  Eigen::MatrixXd jac;
  Eigen::VectorXd r = residual(pb, p, &jac);
  double cost = r.squaredNorm(), lambda = 1e-3;
  for (int it = 0; it < iterations; ++it) {
    const Eigen::MatrixXd jtj = jac.transpose() * jac;
    const Eigen::VectorXd g = jac.transpose() * r;
    Eigen::MatrixXd a = jtj;
    a.diagonal() += lambda * jtj.diagonal().cwiseMax(1e-300);
    const Eigen::VectorXd step = a.ldlt().solve(-g);
    const Eigen::VectorXd trial = p + step;
    const Eigen::VectorXd rt = residual(pb, trial, nullptr);
    const double ct = rt.squaredNorm();
    if (std::isfinite(ct) && ct <= cost) {
      const bool done = cost - ct <= 1e-15 * cost || step.norm() <= 1e-15 * p.norm();
      p = trial;
      cost = ct;
      r = residual(pb, p, &jac);
      lambda = std::max(lambda / 5.0, 1e-15);
      if (done) break;
    } else {
      lambda *= 5.0;
      if (lambda > 1e15) break;
    }
  }
  return p;
}

bool stable(const std::vector<Cplx>& poles, bool discrete) {
  for (const Cplx& s : poles) {
    if (discrete ? !(std::abs(s) < 1.0) : !(s.real() < 0.0)) return false;
  }
  return true;
}

// Denominator roots of the parameter vector (in the fit variable x).
std::vector<Cplx> fit_poles(const Problem& pb, const Eigen::VectorXd& p) {
  std::vector<double> den(static_cast<std::size_t>(pb.np) + 1);
  den[0] = 1.0;
  for (int i = 0; i < pb.np; ++i) den[static_cast<std::size_t>(pb.np - i)] = p(pb.nz + 1 + i);
  return dsp::roots(den);
}

// Roots of a low-first coefficient block of p, reflected into the left half plane
// (continuous) or the unit disc (discrete); returns the factor by which |poly| shrank.
double reflect_block(Eigen::VectorXd& p, Eigen::Index offset, int degree, bool monic, bool discrete) {
  if (degree < 1) return 1.0;
  std::vector<double> hi(static_cast<std::size_t>(degree) + 1);
  for (int i = 0; i <= degree; ++i)
    hi[static_cast<std::size_t>(degree - i)] = (monic && i == degree) ? 1.0 : p(offset + i);
  const double lead = hi[0];
  auto r = dsp::roots(hi);
  double shrink = 1.0;
  for (Cplx& z : r) {
    if (!discrete && z.real() > 0.0) z = -std::conj(z);  // |j w - z| unchanged
    if (discrete && std::abs(z) > 1.0) {
      shrink *= std::abs(z);  // |e^{jw} - z| = |z| |e^{jw} - 1/conj(z)|
      z = 1.0 / std::conj(z);
    }
  }
  const auto rebuilt = dsp::poly_from_roots(r);  // monic, highest power first
  const int top = monic ? degree - 1 : degree;
  for (int i = 0; i <= top; ++i) p(offset + i) = lead * rebuilt[static_cast<std::size_t>(degree - i)];
  return shrink;
}

// A magnitude-only fit leaves each zero's and pole's half plane (and the sign) free: take the
// stable, minimum-phase model with the sign that agrees best with the data's phase.
void to_minimum_phase(const Problem& pb, Eigen::VectorXd& p, bool discrete) {
  const double zero_shrink = reflect_block(p, 0, pb.nz, false, discrete);
  const double pole_shrink = reflect_block(p, pb.nz + 1, pb.np, true, discrete);
  const double gain = zero_shrink / pole_shrink;
  Cplx agree(0.0, 0.0);
  for (std::size_t k = 0; k < pb.x.size(); ++k)
    agree += std::conj(pb.num(p, pb.x[k]) / pb.den(p, pb.x[k])) * pb.h[k];
  const double sign = agree.real() < 0.0 ? -1.0 : 1.0;
  for (int i = 0; i <= pb.nz; ++i) p(i) *= sign * gain;
}

}  // namespace

TfFitResult fit_tf(std::span<const double> f_Hz, std::span<const std::complex<double>> h,
                   const TfFitOptions& o) {
  require(o.nz >= 0 && o.np >= 1 && o.nz <= o.np && o.np <= 20, "np", "need 0 <= nz <= np <= 20", o.np);
  require(f_Hz.size() == h.size(), "h", "must have one value per frequency", static_cast<double>(h.size()));
  require(o.weights.empty() || o.weights.size() == h.size(), "weights", "must have one value per frequency");
  require(std::isfinite(o.dt) && o.dt >= 0, "dt", "must be >= 0", o.dt);
  const bool discrete = o.dt > 0;
  Problem pb;
  pb.nz = o.nz;
  pb.np = o.np;
  pb.log_magnitude = o.error == TfFitError::kLogMagnitude;
  double wmax = 0.0;
  std::vector<std::size_t> used;
  for (std::size_t k = 0; k < f_Hz.size(); ++k) {
    require(std::isfinite(f_Hz[k]) && std::isfinite(h[k].real()) && std::isfinite(h[k].imag()), "h",
            "data must be finite");
    if (f_Hz[k] >= o.fmin_Hz && f_Hz[k] <= o.fmax_Hz && f_Hz[k] > 0 && std::abs(h[k]) > 0) {
      used.push_back(k);
      wmax = std::max(wmax, 2 * std::numbers::pi * f_Hz[k]);
    }
  }
  // Points left out for a zero response are the data's fault, not the band's.
  std::size_t in_band = 0;
  for (std::size_t k = 0; k < f_Hz.size(); ++k)
    in_band += f_Hz[k] >= o.fmin_Hz && f_Hz[k] <= o.fmax_Hz && f_Hz[k] > 0;
  const auto needed = static_cast<std::size_t>(o.nz + 1 + o.np) + 1;
  if (2 * in_band >= needed)
    require(2 * used.size() >= needed, "h",
            fmt::format("the response is zero at {} of the band's {} frequencies: too few left for the model "
                        "order",
                        in_band - used.size(), in_band),
            static_cast<double>(used.size()));
  require(2 * used.size() >= needed, "fmin_Hz", "too few frequency points in the band for the model order",
          static_cast<double>(used.size()));
  const double w0 = discrete ? 1.0 : wmax;  // continuous: x = j w / w0
  for (std::size_t k : used) {
    const double w = 2 * std::numbers::pi * f_Hz[k];
    pb.x.push_back(discrete ? std::exp(Cplx(0, w * o.dt)) : Cplx(0, w / w0));
    pb.h.push_back(h[k]);
    const double user = o.weights.empty() ? 1.0 : o.weights[k];
    // The SK start always fits the complex data with relative weights; the log-magnitude
    // error is relative already.
    pb.w_sk.push_back(pb.log_magnitude || o.weights.empty() ? user / std::abs(h[k]) : user);
    pb.w.push_back(pb.log_magnitude || !o.weights.empty() ? user : 1.0 / std::abs(h[k]));
  }
  Eigen::VectorXd p = sanathanan_koerner(pb, o.sk_iterations);
  if (!p.allFinite()) throw ComputationFailed("tf fit: the linear start is singular (check orders and band)");
  auto poles = fit_poles(pb, p);
  if (!stable(poles, discrete)) {
    // Reflect unstable poles (continuous: mirror in the imaginary axis; discrete: 1/conj).
    for (Cplx& s : poles) {
      if (discrete && std::abs(s) >= 1.0) s = 1.0 / std::conj(s) * 0.999;
      if (!discrete && s.real() >= 0.0) s = Cplx(-std::abs(s.real()) - 1e-6, s.imag());
    }
    const auto den = dsp::poly_from_roots(poles);
    for (int i = 0; i < pb.np; ++i) p(pb.nz + 1 + i) = den[static_cast<std::size_t>(pb.np - i)];
  }
  p = levenberg_marquardt(pb, p, o.lm_iterations);
  if (!p.allFinite()) throw ComputationFailed("tf fit: Levenberg-Marquardt diverged");
  if (pb.log_magnitude) to_minimum_phase(pb, p, discrete);
  if (!stable(fit_poles(pb, p), discrete)) {
    throw ComputationFailed("tf fit: no stable model of orders (" + std::to_string(o.nz) + ", " +
                            std::to_string(o.np) + ") fits the data in the band");
  }
  // Back to the physical variable: x = s / w0 -> coefficient of s^i scales by w0^(np - i).
  std::vector<double> num(static_cast<std::size_t>(o.nz) + 1), den(static_cast<std::size_t>(o.np) + 1);
  den[0] = 1.0;
  for (int i = 0; i < o.np; ++i)
    den[static_cast<std::size_t>(o.np - i)] = p(o.nz + 1 + i) * std::pow(w0, o.np - i);
  for (int i = 0; i <= o.nz; ++i) num[static_cast<std::size_t>(o.nz - i)] = p(i) * std::pow(w0, o.np - i);
  TfFitResult out{dsp::TransferFunction(num, den, o.dt), 0.0, used.size()};
  double acc = 0.0;
  for (std::size_t k : used) {
    acc += std::norm(out.tf.response(2 * std::numbers::pi * f_Hz[k]) - h[k]) / std::norm(h[k]);
  }
  out.relative_rms_error = std::sqrt(acc / static_cast<double>(used.size()));
  return out;
}

}  // namespace mc::ident
