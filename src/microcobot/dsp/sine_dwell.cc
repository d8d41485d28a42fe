#include "microcobot/dsp/sine_dwell.h"

#include <cmath>
#include <numbers>

#include <Eigen/Dense>

#include "microcobot/core/error.h"

namespace mc::dsp {
namespace {

// Phasor a + j b of x ~ Re{(a + jb)^* ...}: returns A e^{j phi} with x ~ A sin(w t + phi) + c.
std::complex<double> fit_phasor(std::span<const double> x, const Eigen::MatrixXd& basis,
                                const Eigen::ColPivHouseholderQR<Eigen::MatrixXd>& qr, std::size_t settle,
                                double& residual_rms) {
  Eigen::VectorXd v(basis.rows());
  for (Eigen::Index i = 0; i < v.size(); ++i) v(i) = x[settle + static_cast<std::size_t>(i)];
  const Eigen::Vector3d c = qr.solve(v);
  residual_rms = std::sqrt((basis * c - v).squaredNorm() / static_cast<double>(v.size()));
  // a sin + b cos = A sin(wt + phi) with A cos(phi) = a, A sin(phi) = b.
  return {c(0), c(1)};
}

}  // namespace

SineDwellResult sine_dwell(std::span<const double> u, std::span<const double> y, double f_Hz, double fs_Hz,
                           std::size_t settle) {
  require(u.size() == y.size(), "y", "must have the length of u", static_cast<double>(y.size()));
  require_positive(fs_Hz, "fs_Hz");
  require(std::isfinite(f_Hz) && f_Hz > 0 && f_Hz < fs_Hz / 2, "f_Hz", "must be in (0, fs/2)", f_Hz);
  require(settle < u.size() && static_cast<double>(u.size() - settle) >= fs_Hz / f_Hz, "settle",
          "leaves less than one period of data", static_cast<double>(settle));
  const auto n = static_cast<Eigen::Index>(u.size() - settle);
  Eigen::MatrixXd basis(n, 3);
  const double w = 2 * std::numbers::pi * f_Hz;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double t = static_cast<double>(settle + static_cast<std::size_t>(i)) / fs_Hz;
    basis(i, 0) = std::sin(w * t);
    basis(i, 1) = std::cos(w * t);
    basis(i, 2) = 1.0;
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(basis);
  SineDwellResult r;
  double ures = 0.0;
  const auto pu = fit_phasor(u, basis, qr, settle, ures);
  const auto py = fit_phasor(y, basis, qr, settle, r.output_residual_rms);
  r.input_amplitude = std::abs(pu);
  r.output_amplitude = std::abs(py);
  require(r.input_amplitude > 0, "u", "has no component at the dwell frequency");
  r.h = py / pu;
  r.magnitude = std::abs(r.h);
  r.phase_rad = std::arg(r.h);
  return r;
}

}  // namespace mc::dsp
