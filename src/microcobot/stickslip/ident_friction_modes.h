#pragma once
/// @file
/// Step 1b of the identification (thesis §2.5.2.1, Fig. 2.11): the two asperities
/// (rho0_a, rho1_a), (rho0_b, rho1_b) of eq. 2.20-2.21 from the actuator's step response in
/// scanning mode (slider attached, a step small enough not to slip, ~25 kHz sampling).
///
/// In the elastic phase (|z| < z_ba, eq. 2.13: alpha = 0, z' = x') each slider part i (mass share
/// c_i M_s, docs/concepts/stick-slip.md) is a spring-damper on the PE:
///   c_i M_s x2i'' = c_i [rho0_i (x1 - x2i) + rho1_i (x1' - x2i')] + k_c (x2j - x2i),
///   x2 = c_a x2a + c_b x2b,
/// and the PE's two modes (eq. 2.1-2.2, parameters from step 1a or the base) carry the contact's
/// reaction: the PE's compliance in series with the contact lowers the asperity modes by ~1%. Method: the PSD
/// peaks of the free response seed separable nonlinear least squares on the time response over (f_a, zeta_a,
/// f_b, zeta_b, c_a) with f_i = sqrt(rho0_i / M_s) / 2 pi and zeta_i = rho1_i / (2 sqrt(rho0_i M_s)); the
/// input scale and the offset are linear. M_s, k_c and the PE come from the base parameters (Table 2.8;
/// erratum 2 (docs/errata.md)).

#include <vector>

#include "microcobot/dsp/welch.h"
#include "microcobot/stickslip/elasto_plastic_friction.h"
#include "microcobot/stickslip/ident_pe_modes.h"
#include "microcobot/stickslip/ident_record.h"
#include "microcobot/stickslip/stickslip_params.h"

namespace mc::stickslip {

struct FrictionModesResult {
  ModeEstimate a, b;             ///< asperity modes sqrt(rho0_i / M_s), a the lower
  double mass_fraction_a = 0.0;  ///< c_a
  double static_gain_m_V = 0.0;  ///< x2 per (equivalent) volt of the step
  double step_V = 0.0;
  double rms_m = 0.0;
  std::vector<double> psd_peaks_Hz;
  dsp::Spectrum psd;             ///< PSD of the free response (Fig. 2.11 bottom)
  std::vector<double> fitted_m;  ///< model response (Fig. 2.11 top)
  FrictionParams params;         ///< base.friction with rho0/rho1 of both asperities and c_a
};

/// Identifies the asperities from `rec` (x_m = slider position x2). `base` supplies M_s, k_c and
/// the fields not identified here; `hysteresis`, if given, maps the step through H.
/// Throws mc::InvalidInput (no step, record shorter than 5 periods of the lower peak after the
/// step) and mc::ComputationFailed (fit without two distinct damped modes).
FrictionModesResult identify_friction_modes(const MeasuredRecord& rec, const StickSlipParams& base,
                                            const PiParams* hysteresis = nullptr);

/// The elastic-phase slider response x2 to the static PE displacement x1_static = g H(U) (same
/// model, with the PE's two modes of `pe` loaded by the contact), sampled every h, from rest.
/// Used by the fit and by its plots.
std::vector<double> elastic_slider_response(const std::vector<double>& x1_static, double h,
                                            const PiezoParams& pe, double slider_mass_kg, double coupling_N_m,
                                            double rho0_a, double rho1_a, double rho0_b, double rho1_b,
                                            double mass_fraction_a);

}  // namespace mc::stickslip
