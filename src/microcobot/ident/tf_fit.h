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
///
/// With `error = TfFitError::kLogMagnitude` the refinement minimises
/// sum w_k^2 (ln|N/D| - ln|H_k|)^2 instead: the magnitude alone, as a fit to a power
/// spectrum (the thesis identifies eq. 3.6 from PSDs, Fig. 3.11), for data whose phase
/// carries effects the model order cannot hold. The start is still the complex SK fit. The
/// magnitude leaves each zero's and pole's side of the stability boundary and the sign
/// free: the model returned is the stable, minimum-phase one, with the sign whose phase
/// agrees best with the data.

#include <complex>
#include <limits>
#include <span>
#include <vector>

#include "microcobot/dsp/lti.h"

namespace mc::ident {

/// What the Levenberg-Marquardt refinement minimises.
enum class TfFitError {
  kComplex,       ///< w_k |N/D - H_k| (magnitude and phase)
  kLogMagnitude,  ///< w_k |ln|N/D| - ln|H_k|| (magnitude only; default weights 1)
};

struct TfFitOptions {
  int nz = 1;  ///< numerator order
  int np = 2;  ///< denominator order (den monic)
  double fmin_Hz = 0.0;
  double fmax_Hz = std::numeric_limits<double>::infinity();
  double dt = 0.0;  ///< 0: continuous model in s; > 0: discrete model in z with this period
  /// Per-point weights (same length as the data); empty = relative error (1/|H| for
  /// kComplex, 1 for kLogMagnitude, whose error is already relative).
  std::vector<double> weights;
  TfFitError error = TfFitError::kComplex;
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
