#include "microcobot/dsp/lti.h"

#include <cmath>
#include <numbers>

#include <unsupported/Eigen/MatrixFunctions>

#include "microcobot/core/error.h"

namespace mc::dsp {
namespace {

using Cplx = std::complex<double>;

std::vector<double> strip_leading_zeros(std::vector<double> p) {
  std::size_t i = 0;
  while (i + 1 < p.size() && p[i] == 0.0) ++i;
  p.erase(p.begin(), p.begin() + static_cast<std::ptrdiff_t>(i));
  return p;
}

void require_finite(const std::vector<double>& v, const char* field) {
  for (double x : v) require(std::isfinite(x), field, "coefficients must be finite");
}

double uniform_step(std::span<const double> t) {
  require(t.size() >= 2, "t", "needs at least two times");
  const double dt = t[1] - t[0];
  require(dt > 0, "t", "must increase", dt);
  for (std::size_t i = 2; i < t.size(); ++i) {
    require(std::abs((t[i] - t[i - 1]) - dt) <= 1e-9 * std::max(dt, std::abs(t[i])), "t",
            "must be uniformly spaced");
  }
  return dt;
}

// e^M by scaling and squaring (Eigen), after a diagonal similarity by powers of two that
// balances row and column norms (Parlett-Reinsch). Companion-form matrices of physical
// systems span many decades (4.559e6 next to 1); without balancing their exponential
// loses up to 5 digits.
Eigen::MatrixXd expm_balanced(const Eigen::MatrixXd& m) {
  const Eigen::Index n = m.rows();
  Eigen::VectorXd d = Eigen::VectorXd::Ones(n);
  Eigen::MatrixXd b = m;
  for (int sweep = 0; sweep < 100; ++sweep) {
    bool changed = false;
    for (Eigen::Index i = 0; i < n; ++i) {
      double c = 0.0, r = 0.0;
      for (Eigen::Index j = 0; j < n; ++j) {
        if (j == i) continue;
        c += std::abs(b(j, i));
        r += std::abs(b(i, j));
      }
      if (c == 0.0 || r == 0.0) continue;
      double f = 1.0;
      const double s = c + r;
      while (c < r / 2.0) {
        c *= 2.0;
        r /= 2.0;
        f *= 2.0;
      }
      while (c >= r * 2.0) {
        c /= 2.0;
        r *= 2.0;
        f /= 2.0;
      }
      if ((c + r) < 0.95 * s) {
        changed = true;
        d(i) *= f;
        b.row(i) /= f;
        b.col(i) *= f;
      }
    }
    if (!changed) break;
  }
  // b = D^-1 M D, so e^M = D e^b D^-1.
  const Eigen::MatrixXd e = b.exp();
  return d.asDiagonal() * e * d.cwiseInverse().asDiagonal();
}

}  // namespace

std::complex<double> polyval(std::span<const double> poly, std::complex<double> x) {
  Cplx acc(0.0, 0.0);
  for (double c : poly) acc = acc * x + c;
  return acc;
}

std::vector<std::complex<double>> roots(std::span<const double> poly_in) {
  std::vector<double> p(poly_in.begin(), poly_in.end());
  p = strip_leading_zeros(p);
  std::vector<Cplx> out;
  // Trailing zeros are roots at the origin.
  std::size_t n = p.size();
  while (n > 1 && p[n - 1] == 0.0) {
    out.emplace_back(0.0, 0.0);
    --n;
  }
  const std::size_t deg = n - 1;
  if (deg == 0) return out;
  Eigen::MatrixXd comp =
      Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(deg), static_cast<Eigen::Index>(deg));
  for (std::size_t j = 0; j < deg; ++j) comp(0, static_cast<Eigen::Index>(j)) = -p[j + 1] / p[0];
  for (std::size_t i = 1; i < deg; ++i)
    comp(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(i - 1)) = 1.0;
  Eigen::EigenSolver<Eigen::MatrixXd> es(comp, false);
  for (Eigen::Index i = 0; i < es.eigenvalues().size(); ++i) out.push_back(es.eigenvalues()(i));
  return out;
}

TransferFunction::TransferFunction(std::vector<double> num, std::vector<double> den, double dt)
    : num_(strip_leading_zeros(std::move(num))), den_(strip_leading_zeros(std::move(den))), dt_(dt) {
  require(!num_.empty(), "num", "must not be empty");
  require(!den_.empty() && den_[0] != 0.0, "den", "must not be zero");
  require_finite(num_, "num");
  require_finite(den_, "den");
  require(num_.size() <= den_.size(), "num", "degree must not exceed the denominator's (proper system)",
          static_cast<double>(num_.size() - 1));
  require(std::isfinite(dt) && dt >= 0.0, "dt", "must be >= 0", dt);
}

TransferFunction TransferFunction::from_zpk(const Zpk& zpk, double dt) {
  auto num = poly_from_roots(zpk.z);
  for (double& c : num) c *= zpk.k;
  return TransferFunction(num, poly_from_roots(zpk.p), dt);
}

std::complex<double> TransferFunction::eval(std::complex<double> x) const {
  return polyval(num_, x) / polyval(den_, x);
}

std::complex<double> TransferFunction::response(double w_rad_s) const {
  return eval(is_discrete() ? std::exp(Cplx(0.0, w_rad_s * dt_)) : Cplx(0.0, w_rad_s));
}

std::vector<std::complex<double>> TransferFunction::poles() const { return roots(den_); }
std::vector<std::complex<double>> TransferFunction::zeros() const { return roots(num_); }

double TransferFunction::dc_gain() const {
  const Cplx x = is_discrete() ? Cplx(1.0, 0.0) : Cplx(0.0, 0.0);
  const Cplx d = polyval(den_, x);
  if (d == 0.0) return std::copysign(std::numeric_limits<double>::infinity(), polyval(num_, x).real());
  return (polyval(num_, x) / d).real();
}

bool TransferFunction::is_stable() const {
  for (const Cplx& p : poles()) {
    if (is_discrete() ? !(std::abs(p) < 1.0) : !(p.real() < 0.0)) return false;
  }
  return true;
}

TransferFunction TransferFunction::normalized() const {
  auto num = num_, den = den_;
  const double a0 = den[0];
  for (double& c : num) c /= a0;
  for (double& c : den) c /= a0;
  return TransferFunction(num, den, dt_);
}

void StateSpace::validate() const {
  require(A.rows() == A.cols(), "A", "must be square");
  require(B.rows() == A.rows(), "B", "must have as many rows as A");
  require(C.cols() == A.cols(), "C", "must have as many columns as A");
  require(D.rows() == C.rows() && D.cols() == B.cols(), "D", "must be outputs x inputs");
  require(A.allFinite() && B.allFinite() && C.allFinite() && D.allFinite(), "ss", "values must be finite");
  require(std::isfinite(dt) && dt >= 0.0, "dt", "must be >= 0", dt);
}

std::complex<double> StateSpace::response(double w_rad_s, int in, int out) const {
  const Cplx x = dt > 0 ? std::exp(Cplx(0.0, w_rad_s * dt)) : Cplx(0.0, w_rad_s);
  const Eigen::Index n = A.rows();
  if (n == 0) return D(out, in);
  Eigen::MatrixXcd m = x * Eigen::MatrixXcd::Identity(n, n) - A.cast<Cplx>();
  const Eigen::VectorXcd v = m.partialPivLu().solve(B.col(in).cast<Cplx>());
  return (C.row(out).cast<Cplx>() * v)(0) + D(out, in);
}

std::vector<std::complex<double>> StateSpace::poles() const {
  std::vector<Cplx> out;
  if (A.rows() == 0) return out;
  Eigen::EigenSolver<Eigen::MatrixXd> es(A, false);
  for (Eigen::Index i = 0; i < es.eigenvalues().size(); ++i) out.push_back(es.eigenvalues()(i));
  return out;
}

bool StateSpace::is_stable() const {
  for (const Cplx& p : poles()) {
    if (dt > 0 ? !(std::abs(p) < 1.0) : !(p.real() < 0.0)) return false;
  }
  return true;
}

StateSpace tf2ss(const TransferFunction& tf_in) {
  const auto tf = tf_in.normalized();
  const auto& den = tf.den();
  std::vector<double> num(den.size() - tf.num().size(), 0.0);
  num.insert(num.end(), tf.num().begin(), tf.num().end());
  const auto n = static_cast<Eigen::Index>(den.size() - 1);
  StateSpace ss;
  ss.dt = tf.dt();
  ss.D = Eigen::MatrixXd::Constant(1, 1, num[0]);
  ss.A = Eigen::MatrixXd::Zero(n, n);
  ss.B = Eigen::MatrixXd::Zero(n, 1);
  ss.C = Eigen::MatrixXd::Zero(1, n);
  if (n == 0) return ss;
  for (Eigen::Index j = 0; j < n; ++j) {
    const auto u = static_cast<std::size_t>(j + 1);
    ss.A(0, j) = -den[u];
    ss.C(0, j) = num[u] - num[0] * den[u];
  }
  for (Eigen::Index i = 1; i < n; ++i) ss.A(i, i - 1) = 1.0;
  ss.B(0, 0) = 1.0;
  return ss;
}

TransferFunction ss2tf(const StateSpace& ss, int in, int out) {
  ss.validate();
  const Eigen::Index n = ss.A.rows();
  const double d = ss.D(out, in);
  if (n == 0) return TransferFunction({d}, {1.0}, ss.dt);
  auto charpoly = [](const Eigen::MatrixXd& m) {
    Eigen::EigenSolver<Eigen::MatrixXd> es(m, false);
    std::vector<Cplx> r(static_cast<std::size_t>(es.eigenvalues().size()));
    for (std::size_t i = 0; i < r.size(); ++i) r[i] = es.eigenvalues()(static_cast<Eigen::Index>(i));
    return poly_from_roots(r);
  };
  const auto den = charpoly(ss.A);
  // det(sI - A + B C) = den(s) (1 + C (sI - A)^-1 B), so num = poly(A - B C) + (D - 1) den.
  const auto num0 = charpoly(ss.A - ss.B.col(in) * ss.C.row(out));
  std::vector<double> num(den.size());
  for (std::size_t i = 0; i < den.size(); ++i) num[i] = num0[i] + (d - 1.0) * den[i];
  // Clean rounding residue of exactly-zero coefficients (e.g. the s^n term when D = 0).
  double scale = 0.0;
  for (double c : num) scale = std::max(scale, std::abs(c));
  for (double& c : num) {
    if (std::abs(c) < 1e-14 * scale) c = 0.0;
  }
  return TransferFunction(num, den, ss.dt);
}

StateSpace c2d_zoh(const StateSpace& ss, double dt) {
  ss.validate();
  require(ss.dt == 0.0, "ss", "must be continuous");
  require_positive(dt, "dt_s");
  const Eigen::Index n = ss.A.rows(), m = ss.B.cols();
  Eigen::MatrixXd big = Eigen::MatrixXd::Zero(n + m, n + m);
  big.topLeftCorner(n, n) = ss.A * dt;
  big.topRightCorner(n, m) = ss.B * dt;
  const Eigen::MatrixXd e = expm_balanced(big);
  StateSpace d{e.topLeftCorner(n, n), e.topRightCorner(n, m), ss.C, ss.D, dt};
  if (!d.A.allFinite() || !d.B.allFinite()) throw ComputationFailed("c2d_zoh: matrix exponential overflowed");
  return d;
}

StateSpace c2d_tustin(const StateSpace& ss, double dt, std::optional<double> prewarp_rad_s) {
  ss.validate();
  require(ss.dt == 0.0, "ss", "must be continuous");
  require_positive(dt, "dt_s");
  double h = dt;
  if (prewarp_rad_s) {
    const double w = *prewarp_rad_s;
    require(std::isfinite(w) && w > 0 && w * dt < std::numbers::pi, "prewarp_rad_s", "must be in (0, pi/dt)",
            w);
    h = 2.0 * std::tan(w * dt / 2.0) / w;
  }
  const Eigen::Index n = ss.A.rows();
  const Eigen::MatrixXd eye = Eigen::MatrixXd::Identity(n, n);
  const Eigen::MatrixXd ima = eye - 0.5 * h * ss.A;
  const auto lu = ima.partialPivLu();
  StateSpace d;
  d.dt = dt;
  d.A = lu.solve(eye + 0.5 * h * ss.A);
  d.B = lu.solve(h * ss.B);
  d.C = ima.transpose().partialPivLu().solve(ss.C.transpose()).transpose();
  d.D = ss.D + 0.5 * ss.C * d.B;
  return d;
}

TransferFunction c2d_matched(const TransferFunction& tf, double dt) {
  require(!tf.is_discrete(), "tf", "must be continuous");
  require_positive(dt, "dt_s");
  const auto z = tf.zeros(), p = tf.poles();
  Zpk d;
  for (const Cplx& s : z) d.z.push_back(std::exp(s * dt));
  for (const Cplx& s : p) d.p.push_back(std::exp(s * dt));
  for (std::size_t i = z.size(); i < p.size(); ++i) d.z.emplace_back(-1.0, 0.0);
  bool at_origin = false;
  for (const Cplx& s : z) at_origin = at_origin || std::abs(s) < 1e-12;
  for (const Cplx& s : p) at_origin = at_origin || std::abs(s) < 1e-12;
  const double w = at_origin ? 0.01 * std::numbers::pi / dt : 0.0;
  d.k = 1.0;
  const auto unit = TransferFunction::from_zpk(d, dt);
  const double want = std::abs(tf.response(w)), got = std::abs(unit.response(w));
  if (!(got > 0) || !std::isfinite(want)) throw ComputationFailed("c2d_matched: cannot match the gain");
  // Sign: keep the continuous system's DC sign (the real part at w, where phase ~ 0 or +-pi).
  const double sign = (tf.response(w) / unit.response(w)).real() < 0 ? -1.0 : 1.0;
  d.k = sign * want / got;
  return TransferFunction::from_zpk(d, dt);
}

StateSpace d2c_zoh(const StateSpace& ss) {
  ss.validate();
  require(ss.dt > 0.0, "ss", "must be discrete");
  const Eigen::Index n = ss.A.rows(), m = ss.B.cols();
  for (const Cplx& p : ss.poles()) {
    if (p.real() <= 0 && std::abs(p.imag()) < 1e-12 * std::max(1.0, std::abs(p))) {
      throw ComputationFailed("d2c_zoh: a pole on the negative real axis has no continuous ZOH equivalent");
    }
  }
  Eigen::MatrixXd big = Eigen::MatrixXd::Identity(n + m, n + m);
  big.topLeftCorner(n, n) = ss.A;
  big.topRightCorner(n, m) = ss.B;
  const Eigen::MatrixXd l = big.log() / ss.dt;
  StateSpace c{l.topLeftCorner(n, n), l.topRightCorner(n, m), ss.C, ss.D, 0.0};
  if (!c.A.allFinite() || !c.B.allFinite()) throw ComputationFailed("d2c_zoh: matrix logarithm failed");
  return c;
}

TransferFunction c2d(const TransferFunction& tf, double dt, Discretization method,
                     std::optional<double> prewarp) {
  switch (method) {
    case Discretization::kZoh:
      return ss2tf(c2d_zoh(tf2ss(tf), dt));
    case Discretization::kTustin:
      return ss2tf(c2d_tustin(tf2ss(tf), dt, prewarp));
    case Discretization::kMatched:
      return c2d_matched(tf, dt);
  }
  throw UsageError("unknown discretization");
}

std::vector<std::complex<double>> freqresp(const TransferFunction& tf, std::span<const double> w_rad_s) {
  std::vector<Cplx> out(w_rad_s.size());
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = tf.response(w_rad_s[i]);
  return out;
}

std::vector<double> lsim(const StateSpace& ss, std::span<const double> u, std::span<const double> t,
                         bool interpolate, const Eigen::VectorXd& x0) {
  ss.validate();
  require(ss.B.cols() == 1 && ss.C.rows() == 1, "ss", "lsim takes a single-input single-output system");
  require(u.size() == t.size(), "u", "must have one sample per time", static_cast<double>(u.size()));
  const Eigen::Index n = ss.A.rows();
  Eigen::VectorXd x = x0.size() == 0 ? Eigen::VectorXd::Zero(n) : x0;
  require(x.size() == n, "x0", "must have one value per state", static_cast<double>(x0.size()));
  std::vector<double> y(u.size());
  if (u.empty()) return y;
  const double d = ss.D(0, 0);
  Eigen::MatrixXd ad, bd0, bd1;
  if (ss.dt > 0) {
    ad = ss.A;
    bd0 = ss.B;
    bd1 = Eigen::MatrixXd::Zero(n, 1);
  } else {
    const double h = uniform_step(t);
    // scipy.signal.lsim: the exponential of the augmented matrix holds the input terms.
    if (interpolate) {
      Eigen::MatrixXd m = Eigen::MatrixXd::Zero(n + 2, n + 2);
      m.topLeftCorner(n, n) = ss.A * h;
      m.block(0, n, n, 1) = ss.B * h;
      m(n, n + 1) = 1.0;
      const Eigen::MatrixXd e = expm_balanced(m);
      ad = e.topLeftCorner(n, n);
      bd1 = e.block(0, n + 1, n, 1);
      bd0 = e.block(0, n, n, 1) - bd1;
    } else {
      Eigen::MatrixXd m = Eigen::MatrixXd::Zero(n + 1, n + 1);
      m.topLeftCorner(n, n) = ss.A * h;
      m.block(0, n, n, 1) = ss.B * h;
      const Eigen::MatrixXd e = expm_balanced(m);
      ad = e.topLeftCorner(n, n);
      bd0 = e.block(0, n, n, 1);
      bd1 = Eigen::MatrixXd::Zero(n, 1);
    }
  }
  const Eigen::RowVectorXd c = ss.C.row(0);
  Eigen::VectorXd next(n);
  for (std::size_t k = 0; k < u.size(); ++k) {
    y[k] = (n > 0 ? c.dot(x) : 0.0) + d * u[k];
    if (!std::isfinite(y[k])) throw ComputationFailed("lsim: the response diverged (non-finite output)");
    if (k + 1 < u.size()) {
      next.noalias() = ad * x;
      next += bd0 * u[k];
      if (interpolate && ss.dt == 0) next += bd1 * u[k + 1];
      x.swap(next);
    }
  }
  return y;
}

std::vector<double> lsim(const TransferFunction& tf, std::span<const double> u, std::span<const double> t,
                         bool interpolate) {
  return lsim(tf2ss(tf), u, t, interpolate);
}

std::vector<double> step(const TransferFunction& tf, std::span<const double> t) {
  const std::vector<double> u(t.size(), 1.0);
  return lsim(tf2ss(tf), u, t, false);
}

std::vector<double> impulse(const TransferFunction& tf, std::span<const double> t) {
  const auto ss = tf2ss(tf);
  const std::vector<double> u(t.size(), 0.0);
  Eigen::VectorXd x0 = ss.B.col(0);
  if (tf.is_discrete()) {
    // Discrete impulse: y[0] = D, then C A^(k-1) B.
    auto y = lsim(ss, u, t, false, x0);
    for (std::size_t k = y.size(); k-- > 1;) y[k] = y[k - 1];
    if (!y.empty()) y[0] = ss.D(0, 0);
    return y;
  }
  return lsim(ss, u, t, false, x0);
}

}  // namespace mc::dsp
