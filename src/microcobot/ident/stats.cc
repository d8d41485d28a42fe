#include "microcobot/ident/stats.h"

#include <cmath>

#include <Eigen/Dense>

#include "microcobot/core/error.h"

namespace mc::ident {
namespace {

void require_data(std::span<const double> x) { require(!x.empty(), "x", "must not be empty"); }

double central_moment(std::span<const double> x, int order) {
  const double m = mean(x);
  double acc = 0.0;
  for (double v : x) acc += std::pow(v - m, order);
  return acc / static_cast<double>(x.size());
}

}  // namespace

double mean(std::span<const double> x) {
  require_data(x);
  double acc = 0.0;
  for (double v : x) acc += v;
  return acc / static_cast<double>(x.size());
}

double rms(std::span<const double> x) {
  require_data(x);
  double acc = 0.0;
  for (double v : x) acc += v * v;
  return std::sqrt(acc / static_cast<double>(x.size()));
}

double stddev(std::span<const double> x) { return std::sqrt(central_moment(x, 2)); }

double skewness(std::span<const double> x) {
  const double m2 = central_moment(x, 2);
  if (m2 == 0.0) throw ComputationFailed("skewness of constant data is undefined");
  return central_moment(x, 3) / std::pow(m2, 1.5);
}

double kurtosis(std::span<const double> x) {
  const double m2 = central_moment(x, 2);
  if (m2 == 0.0) throw ComputationFailed("kurtosis of constant data is undefined");
  return central_moment(x, 4) / (m2 * m2) - 3.0;
}

Histogram histogram(std::span<const double> x, std::size_t bins, double lo, double hi) {
  require(bins >= 1, "bins", "must be >= 1");
  require(std::isfinite(lo) && std::isfinite(hi) && hi > lo, "hi", "must be > lo", hi);
  Histogram h;
  h.width = (hi - lo) / static_cast<double>(bins);
  h.counts.assign(bins, 0.0);
  h.centres.resize(bins);
  for (std::size_t i = 0; i < bins; ++i) h.centres[i] = lo + (static_cast<double>(i) + 0.5) * h.width;
  for (double v : x) {
    if (!(v >= lo && v <= hi)) continue;
    auto i = static_cast<std::size_t>((v - lo) / h.width);
    if (i >= bins) i = bins - 1;
    h.counts[i] += 1.0;
  }
  return h;
}

GaussianFit fit_gaussian(std::span<const double> centres, std::span<const double> counts) {
  require(centres.size() == counts.size(), "counts", "must have one value per bin centre");
  require(centres.size() >= 3, "centres", "need at least 3 bins", static_cast<double>(centres.size()));
  double total = 0.0, m1 = 0.0, peak = 0.0;
  for (std::size_t i = 0; i < counts.size(); ++i) {
    require(std::isfinite(counts[i]) && std::isfinite(centres[i]), "counts", "must be finite");
    total += counts[i];
    m1 += counts[i] * centres[i];
    peak = std::max(peak, counts[i]);
  }
  require(total > 0.0, "counts", "histogram is empty");
  m1 /= total;
  double m2 = 0.0;
  for (std::size_t i = 0; i < counts.size(); ++i) m2 += counts[i] * (centres[i] - m1) * (centres[i] - m1);
  double sigma = std::sqrt(m2 / total);
  if (!(sigma > 0)) sigma = std::abs(centres[1] - centres[0]);
  Eigen::Vector3d p(peak, m1, sigma);
  const auto n = static_cast<Eigen::Index>(counts.size());
  auto residual = [&](const Eigen::Vector3d& q, Eigen::VectorXd& r, Eigen::MatrixXd* jac) {
    r.resize(n);
    if (jac) jac->resize(n, 3);
    for (Eigen::Index i = 0; i < n; ++i) {
      const double x = centres[static_cast<std::size_t>(i)];
      const double d = (x - q(1)) / q(2);
      const double g = std::exp(-0.5 * d * d);
      r(i) = q(0) * g - counts[static_cast<std::size_t>(i)];
      if (jac) {
        (*jac)(i, 0) = g;
        (*jac)(i, 1) = q(0) * g * d / q(2);
        (*jac)(i, 2) = q(0) * g * d * d / q(2);
      }
    }
  };
  Eigen::VectorXd r;
  Eigen::MatrixXd jac;
  residual(p, r, &jac);
  double cost = r.squaredNorm(), lambda = 1e-3;
  for (int it = 0; it < 200; ++it) {
    const Eigen::Matrix3d jtj = jac.transpose() * jac;
    const Eigen::Vector3d g = jac.transpose() * r;
    Eigen::Matrix3d a = jtj;
    a.diagonal() += lambda * jtj.diagonal();
    const Eigen::Vector3d step = a.ldlt().solve(-g);
    Eigen::Vector3d trial = p + step;
    trial(2) = std::abs(trial(2));
    Eigen::VectorXd rt;
    residual(trial, rt, nullptr);
    const double ct = rt.squaredNorm();
    if (std::isfinite(ct) && ct < cost) {
      const bool done = cost - ct < 1e-14 * cost;
      p = trial;
      cost = ct;
      residual(p, r, &jac);
      lambda = std::max(lambda / 3.0, 1e-12);
      if (done) break;
    } else {
      lambda *= 4.0;
      if (lambda > 1e12) break;
    }
  }
  if (!p.allFinite() || !(p(2) > 0)) throw ComputationFailed("fit_gaussian: the fit did not converge");
  const double mean_count = total / static_cast<double>(n);
  double ss_tot = 0.0;
  for (double c : counts) ss_tot += (c - mean_count) * (c - mean_count);
  return {p(0), p(1), p(2), ss_tot > 0 ? 1.0 - cost / ss_tot : 0.0};
}

}  // namespace mc::ident
