#pragma once
/// @file
/// Step 2 of the identification (thesis §2.5.2.2, Fig. 2.12): the Prandtl-Ishlinskii model H(U)
/// of eq. 2.5 from the slider's response to a sine voltage in scanning mode (thesis: 40 V, 50 Hz,
/// n = 35 operators), following the procedure of §2.5.2.2 (i)-(v):
///  - n play operators with half-widths r_i on a non-uniform (quadratic, finer at small widths)
///    partition of half the input range, r_i = (range / 2) (i / n)^2;
///  - the operator outputs y_i(t) are computed from the measured voltage; the position is
///    x2 = x0 + sum_i w'_i y_i (the PE follows quasi-statically far below the 600 Hz mode);
///  - the weights w'_i >= 0 by non-negative least squares (Lawson-Hanson, ident/nnls.h), the
///    offset x0 free (the "shift to the positive section" of step (ii));
///  - a record starting at rest at its lowest voltage is fitted whole, with thresholds over the
///    whole range (the initial loading identifies the wide operators) and the offset fixed to the
///    rest position; otherwise only samples after the input has visited its minimum and maximum
///    are fitted (from then on every operator's state is set by the input alone: wiping-out), with
///    thresholds over half the range and a free offset. "At rest" is decided from the whole record
///    (voltage noise makes its first samples useless for it): a record starting near its lowest
///    voltage is fitted both as from rest and as a steady loop over all samples, the smaller RMS
///    residual wins.
/// The weights are split as w'_i = g w_i, with g (the PE's static gain, m/V) chosen so that the
/// loading curve maps the top of the input range to itself (the convention of the defaults).

#include <vector>

#include "microcobot/stickslip/ident_record.h"
#include "microcobot/stickslip/prandtl_ishlinskii.h"
#include "microcobot/stickslip/stickslip_params.h"

namespace mc::stickslip {

struct HysteresisResult {
  PiParams pi;                       ///< thresholds r_i [V] and normalised weights w_i
  PiParams inverse;                  ///< pi_inverse(pi): the exact inverse (for feed-forward)
  double static_gain_m_V = 0.0;      ///< g
  double offset_m = 0.0;             ///< x0
  double rms_m = 0.0;                ///< RMS of the loop fit over the fitted samples
  double stroke_m = 0.0;             ///< peak-to-peak of the measured loop
  double rms_fraction = 0.0;         ///< rms_m / stroke_m
  double inverse_max_error_V = 0.0;  ///< max |H^-1(H(U)) - U| over the record
  std::size_t first_fitted = 0;      ///< first sample used (after the wiping-out; 0 from rest)
  /// Whether the record was taken as starting at rest (virgin operators, the initial loading
  /// fitted), decided by fitting both hypotheses over the whole record when it starts near its
  /// lowest voltage; their RMS residuals [m] (NaN when the record starts elsewhere: a steady loop).
  bool from_rest = false;
  double rms_from_rest_m = 0.0, rms_steady_loop_m = 0.0;
  double voltage_noise_V = 0.0;  ///< RMS voltage noise estimated from the record
  std::vector<double> fitted_m;  ///< x0 + g H(U) at every sample
};

/// Identifies the PI model from `rec` (x_m = slider position) with `operators` play operators.
/// Throws mc::UsageError for operators < 1, mc::InvalidInput for a record whose voltage spans
/// less than 1 V or does not complete an excursion min -> max -> min (too short), and
/// mc::ComputationFailed for a degenerate fit (zero gain).
/// With `dynamics` (the PE and asperities of step 1), each operator output is passed through the
/// elastic-phase response of the slider (elastic_slider_response) before the regression, so that
/// the slider's lag at the sine frequency is not mistaken for hysteresis; without it the PE and
/// slider are taken as quasi-static (the thesis's procedure).
HysteresisResult identify_hysteresis(const MeasuredRecord& rec, int operators = 35,
                                     const StickSlipParams* dynamics = nullptr);

/// The partition used above: r_i = (span / 2) (i / n)^2, i = 0..n-1 (span = range or 2 range).
std::vector<double> pi_thresholds(double range_V, int operators);

}  // namespace mc::stickslip
