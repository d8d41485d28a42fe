#pragma once
/// @file
/// The thesis's chapter-2 experiments reproduced on the model (§2.5, Fig. 2.10-2.17). Each
/// returns plain data (the CLI turns it into JSON, CSV and report figures).

#include <string>
#include <vector>

#include "microcobot/dsp/welch.h"
#include "microcobot/stickslip/actuator.h"

namespace mc::studies {

/// A step response, the PSD of its transient and the PSD's peaks.
struct StepSpectrumResult {
  stickslip::Trajectory response;  ///< sampled at the experiment's rate
  dsp::Spectrum psd;               ///< PSD of x(t) - x(final) (m^2/Hz)
  std::vector<double> peaks_Hz;    ///< the two dominant resonances, ascending
};

/// §2.5.2.1, Fig. 2.10: slider removed, 90 V step, 1 MHz sampling; peaks near 64 and 118 kHz.
/// The step's edge is 0.9 us (a laboratory source, faster than a PE period), see docs/concepts/stick-slip.md.
StepSpectrumResult run_pe_step(const stickslip::StickSlipParams& params);

/// §2.5.2.1, Fig. 2.11: 40 V step, 25 kHz sampling; peaks near 595 and 1633 Hz.
StepSpectrumResult run_actuator_step(const stickslip::StickSlipParams& params);

/// One hysteresis loop x2(U) of Fig. 2.12 (last period of a sine 0..amplitude).
struct HysteresisLoop {
  double frequency_Hz = 0, amplitude_V = 0;
  std::vector<double> u_V, x2_m;  ///< one period, x2 relative to its minimum
  double area_V_m = 0;            ///< signed loop area (shoelace), > 0 for a counter-clockwise loop
  double range_m = 0;             ///< peak-to-peak x2
};

/// §2.5.2.2, Fig. 2.12: 50 Hz 40/25 V, 250 Hz 40/25 V, 595 Hz 25/14 V, 1633 Hz 14/12 V.
std::vector<HysteresisLoop> run_hysteresis(const stickslip::StickSlipParams& params);

/// One sawtooth run (Fig. 2.14-2.16): `periods` periods after one settling period.
struct SawtoothCase {
  double amplitude_V = 0, frequency_Hz = 0;
  stickslip::Direction direction = stickslip::Direction::kForward;
  double net_displacement_m = 0;     ///< mean x2 over the last period minus over the first counted one
  double velocity_m_s = 0;           ///< net displacement / (periods / frequency)
  double stroke_m = 0;               ///< one period's nominal PE stroke g * amplitude
  bool stepping = false;             ///< |net| >= 2% of the stroke in the commanded direction
  stickslip::Trajectory trajectory;  ///< decimated to <= ~4000 samples (for plots)
};

SawtoothCase run_sawtooth(const stickslip::StickSlipParams& params, double amplitude_V, double frequency_Hz,
                          stickslip::Direction direction, int periods = 20);

/// §2.5.3, Fig. 2.14: 20 V at 50, 100, 500 Hz, both directions (scanning: no stepping).
std::vector<SawtoothCase> run_scanning(const stickslip::StickSlipParams& params);
/// §2.5.3, Fig. 2.15-2.16: 40 and 60 V at 50, 100, 500 Hz, both directions.
std::vector<SawtoothCase> run_stepping(const stickslip::StickSlipParams& params);

/// §2.5.2: the smallest sawtooth amplitude that steps (bisection to 0.25 V), per direction.
struct ThresholdResult {
  double frequency_Hz = 50;
  double forward_V = 0, backward_V = 0;
};
ThresholdResult run_threshold(const stickslip::StickSlipParams& params, double frequency_Hz = 50.0);

/// Fig. 2.17: output PSDs for 20 V / 500 Hz and 40 V / 50 Hz.
struct PsdCase {
  double amplitude_V = 0, frequency_Hz = 0;
  dsp::Spectrum psd;  ///< PSD of x2 sampled at 25 kHz (m^2/Hz)
  double dominant_peak_Hz = 0;
};
std::vector<PsdCase> run_psd(const stickslip::StickSlipParams& params);

/// Names accepted by `microcobot stickslip experiment NAME`.
std::vector<std::string> experiment_names();

}  // namespace mc::studies
