#pragma once
/// @file
/// Tools shared by the modal identification steps of thesis §2.5.2.1 (PE modes, asperity modes):
/// the applied voltage step reconstructed from its noisy record, the PSD of the free response and
/// its resonance peaks (the initial guesses), and the unit-gain mode response used as a basis.

#include <vector>

#include "microcobot/dsp/welch.h"
#include "microcobot/stickslip/ident_record.h"

namespace mc::stickslip {

/// The commanded slew-limited step U(t) = u0 + (u1 - u0) clamp((t - t_start) / t_ramp, 0, 1),
/// reconstructed from the recorded (noisy) voltage: the command is known to be a step, so the
/// 1% voltage noise of the record does not enter the model's input.
struct StepInput {
  double u0_V = 0.0, u1_V = 0.0;
  double t_start_s = 0.0, t_ramp_s = 0.0;
  std::vector<double> u_V;  ///< the reconstructed input at the record's samples

  double t_settled_s() const { return t_start_s + t_ramp_s; }
  double value(double t) const;
};

/// Finds the step in `rec`. Throws mc::InvalidInput "<source>: no voltage step ..." if the voltage
/// never steps (change below 1 V or below 6 sigma of its noise), and "record too short" if fewer
/// than 64 samples follow the step.
StepInput fit_step_input(const MeasuredRecord& rec);

/// Welch PSD of the dynamic part of a step response (the record minus its best affine fit on
/// the quasi-static response `static_input`, so the step itself does not leak) and its `count`
/// most prominent peaks in [f_min_Hz, f_max_Hz], sorted by frequency. Short Hann segments
/// (256 samples, half overlap, zero-padded x8) average the transient with the noise floor.
struct ModePeaks {
  dsp::Spectrum psd;
  std::vector<double> peaks_Hz;
};
ModePeaks dynamic_response_peaks(const MeasuredRecord& rec, const std::vector<double>& static_input,
                                 int count, double f_min_Hz, double f_max_Hz);

/// Response of the unit-static-gain mode x'' + 2 zeta w x' + w^2 x = w^2 s(t) (eq. 2.7 normalised
/// by K as in eq. 2.5), sampled every h from rest at s[0], with a first-order hold on s (exact for a
/// piecewise-linear input).
std::vector<double> unit_mode_response(const std::vector<double>& s, double h, double omega_rad_s,
                                       double zeta);

}  // namespace mc::stickslip
