#pragma once
/// @file
/// Identification of the two channels of the dual-stage interface (thesis §3.4.2): PRBS at
/// 10 kHz into one channel with the other passive, Welch H1 FRF of the handle acceleration,
/// the Pantograph's static gain (eq. 3.5), a second-order model of the Haptuator on
/// 100-1000 Hz (eq. 3.6), the overlap band and the crossover cut-off.

#include <complex>
#include <cstdint>
#include <vector>

#include "microcobot/haptics/dual_stage_plant.h"
#include "microcobot/haptics/render_pipeline.h"

namespace mc::haptics {

struct IdentificationOptions {
  int prbs_bits = 16;            ///< MLS order (2^16 - 1 samples = 6.6 s at 10 kHz)
  double lf_amplitude_N = 0.5;   ///< PRBS level into the Pantograph
  double hf_amplitude_V = 12.0;  ///< PRBS level into the Haptuator (hits the stops at low f)
  double noise_m_s2 = 0.05;      ///< accelerometer noise (std), MMA7361-like
  std::uint64_t seed = 1;
  std::size_t nperseg = 4096;  ///< Welch segment (2.4 Hz resolution)
  double fit_lo_Hz = 100.0;    ///< HF model band (§3.4.2: 100 Hz - 1 kHz)
  double fit_hi_Hz = 1000.0;
  double lf_ref_lo_Hz = 40.0;  ///< band over which the LF static gain is averaged
  double lf_ref_hi_Hz = 120.0;
  double flat_tol_dB = 1.0;  ///< "uniform magnitude" tolerance for both channels
};

/// A measured frequency response.
struct ChannelFrf {
  std::vector<double> f_Hz;
  std::vector<std::complex<double>> h;
  std::vector<double> coherence;
};

struct IdentificationResult {
  ChannelFrf lf;
  ChannelFrf hf;
  double lf_gain = 0.0;            ///< G_0^LF, (m/s^2)/N (eq. 3.5)
  HfModel hf_model;                ///< G^HF (eq. 3.6), (m/s^2)/V
  double lf_flat_upper_Hz = 0.0;   ///< the Pantograph stays within flat_tol_dB up to here
  double hf_valid_lower_Hz = 0.0;  ///< the Haptuator follows its model from here up
  double cutoff_Hz = 0.0;          ///< crossover frequency chosen by the §3.3.2 rule (nominal label)
  double hf_delay_s = 0.0;         ///< high-band time alignment chosen by choose_hf_delay_s
};

/// Drives `channel` of `plant` with a PRBS (the other input at zero) and estimates the H1 FRF
/// from the command to the noisy accelerometer signal.
ChannelFrf measure_frf(const DualStagePlant& plant, Channel channel, double amplitude,
                       const IdentificationOptions& options);

/// Second-order model (b1 s + b0)/(s^2 + a1 s + a0) fitted to `frf` on [lo, hi] Hz by
/// ident::fit_tf (Sanathanan-Koerner start, Levenberg-Marquardt on the log-magnitude).
/// Throws ComputationFailed if the fit is unstable or non-minimum-phase. `hold_s` is the sample period of the
/// zero-order hold that fed the plant: its half-sample shift (the accelerometer is read at the end of each
/// held sample) is removed before the fit.
HfModel fit_second_order(const ChannelFrf& frf, double lo_Hz, double hi_Hz, double hold_s);

/// The full §3.4.2 procedure. Cut-off rule (§3.3.2): the highest frequency the Pantograph
/// allows inside the overlap [hf_valid_lower, lf_flat_upper], rounded down to the 1/3-octave
/// grid of Table 3.4; then the high-band delay (choose_hf_delay_s for the default pipeline at
/// the plant's rate). Throws ComputationFailed if the channels do not overlap.
IdentificationResult identify(const DualStagePlant& plant, const IdentificationOptions& options);

/// The high-band alignment delay (RenderPipelineParams::hf_delay_s, an extension of §3.3.2):
/// for 0, 1, ... RenderPipelineParams::kMaxDelaySamples loop samples, the combined response
/// that `base` with the identified compensators would give is predicted at the centres of
/// Table 3.4 from the measured FRFs, (LP C_LF H_LF + HP C_HF z^-n H_HF) / K_sys, and the delay
/// with the smallest spread (max - min, dB) is returned (the shortest on a tie).
double choose_hf_delay_s(const IdentificationResult& id, RenderPipelineParams base);

/// Pipeline parameters built from an identification (compensators from identified models).
RenderPipelineParams pipeline_from(const IdentificationResult& id, RenderPipelineParams base = {});

/// Table 3.4: the exact base-10 1/3-octave centres (dsp::third_octave_centres) of the bands
/// labelled 63 Hz - 1.25 kHz (dsp::third_octave_nominal gives the labels).
std::vector<double> table_3_4_centres_Hz();

}  // namespace mc::haptics
