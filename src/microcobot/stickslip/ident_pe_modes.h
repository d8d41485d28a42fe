#pragma once
/// @file
/// Step 1a of the identification (thesis §2.5.2.1, Fig. 2.10): the two vibration modes of the PE
/// without slider, from its response to a voltage step sampled at ~1 MHz.
///
/// The model is eq. 2.1-2.7 with F_f = 0: x1(t) = g [phi G_a + (1 - phi) G_b] H(U)(t), where
/// G_i = K_pi / (M_p s^2 + D_pi s + K_pi) has unit static gain. Method: (1) the PSD of the dynamic
/// part of the response gives the two resonance peaks; (2) separable nonlinear least squares
/// on the whole time response fits (f_i, zeta_i), with the two modal amplitudes and the offset
/// linear. phi is the split of the static gain between the modes, g the static gain.
/// Only frequencies and damping ratios are identifiable: K_pi = M_p w_i^2 and D_pi = 2 zeta_i w_i M_p
/// use the PE mass M_p of the base parameters (Table 2.8).

#include <vector>

#include "microcobot/dsp/welch.h"
#include "microcobot/stickslip/ident_record.h"
#include "microcobot/stickslip/piezo_element.h"
#include "microcobot/stickslip/prandtl_ishlinskii.h"

namespace mc::stickslip {

/// One identified mode.
struct ModeEstimate {
  double frequency_Hz = 0.0;  ///< undamped natural frequency
  double damping_ratio = 0.0;
};

struct PeModesResult {
  ModeEstimate a, b;                 ///< a: the lower mode
  double gain_fraction_a = 0.0;      ///< phi
  double static_gain_m_V = 0.0;      ///< g (per equivalent volt of H, or per volt without H)
  double step_V = 0.0;               ///< applied step height
  double rms_m = 0.0;                ///< RMS residual of the time fit
  std::vector<double> psd_peaks_Hz;  ///< resonances seen in the PSD (initial guesses)
  dsp::Spectrum psd;                 ///< PSD of the free response (Fig. 2.10 left)
  std::vector<double> fitted_m;      ///< model response at the record's samples (Fig. 2.10 right)
  PiezoParams params;                ///< `base` with the identified modes, phi and g
};

/// Identifies the PE modes from `rec` (columns t_s, u_V, x_m = x1). `hysteresis`, if given, maps
/// the input through H (loading curve) before the linear part; otherwise H is unknown and its
/// curvature along the step's ramp is fitted as a cubic shape common to both modes.
/// Throws mc::InvalidInput for a record without a step or too short (< 5 periods of the expected
/// lower mode after the step) and
/// mc::ComputationFailed if the fit does not converge to two distinct, damped modes.
PeModesResult identify_pe_modes(const MeasuredRecord& rec, const PiezoParams& base,
                                const PiParams* hysteresis = nullptr);

}  // namespace mc::stickslip
