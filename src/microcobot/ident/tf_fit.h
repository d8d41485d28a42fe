#pragma once
/// @file
/// Rational transfer-function fit to frequency-response data, the identification of the
/// thesis's eq. 3.6 (Pantograph + Haptuator plant from a PRBS experiment, §3.4).
///
/// Method: Sanathanan-Koerner iterations (linear least squares on N - H D, reweighted by
/// 1/|D_previous|) give a start; Levenberg-Marquardt then minimises the complex error
/// sum w_k^2 |N(x_k)/D(x_k) - H_k|^2 directly. Continuous models use x = j w / w0 (w0 the
/// band's upper edge, for conditioning); discrete models use x = exp(j w dt). Unstable poles
/// are reflected into the stable region before the refinement; if the final model is still
/// unstable the fit fails with ComputationFailed.

#include <complex>
#include <limits>
#include <span>
#include <vector>

#include "microcobot/dsp/lti.h"

namespace mc::ident {

struct TfFitOptions {
  int nz = 1;  ///< numerator order
  int np = 2;  ///< denominator order (den monic)
  double fmin_Hz = 0.0;
  double fmax_Hz = std::numeric_limits<double>::infinity();
  double dt = 0.0;  ///< 0: continuous model in s; > 0: discrete model in z with this period
  /// Per-point weights (same length as the data); empty = relative error (1/|H|).
  std::vector<double> weights;
  int sk_iterations = 30;
  int lm_iterations = 200;
};

struct TfFitResult {
  dsp::TransferFunction tf;       ///< den monic, highest power first
  double relative_rms_error = 0;  ///< sqrt(mean |N/D - H|^2 / |H|^2) over the band
  std::size_t points = 0;         ///< data points used (inside the band)
};

/// Fits a transfer function of orders (nz, np) to H(f). Throws InvalidParams for bad
/// orders, mismatched sizes or fewer points than unknowns in the band; ComputationFailed
/// when no stable model is found.
TfFitResult fit_tf(std::span<const double> f_Hz, std::span<const std::complex<double>> h,
                   const TfFitOptions& options);

}  // namespace mc::ident
