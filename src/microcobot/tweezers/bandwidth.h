#pragma once
/// @file
/// Frequency-bandwidth identification of the TéléTweez (thesis section 4.5.2, Fig. 4.24-4.25):
/// a PRBS motor torque at 10 kHz, the finger-contact acceleration measured by an accelerometer,
/// the H1 frequency response by Welch averaging, then the dominant mode, the antiresonance and
/// the flat band read off the estimate.

#include <vector>

#include "microcobot/tweezers/teletweez.h"

namespace mc::tweezers {

struct BandwidthIdentParams {
  double fs_Hz = 10e3;                    ///< sampling rate of the PRBS and the DAQ (section 4.5.2)
  int prbs_bits = 15;                     ///< MLS register length: period 2^15 - 1 samples (3.3 s)
  double duration_s = 8.0;                ///< recorded length
  double settle_s = 0.5;                  ///< discarded start (transient from rest)
  double torque_amplitude_N_m = 0.5e-3;   ///< +- PRBS level, within the 2.2 mN m continuous torque
  double accel_noise_m_s2 = 0.05;         ///< accelerometer noise rms (choice)
  int seed = 7;                           ///< the PRBS's and the noise's seed
  int nperseg = 8192;                     ///< Welch segment: 1.2 Hz resolution at 10 kHz
  double band_low_Hz = 20.0;              ///< flat band starts above the hand-held rigid mode (~12 Hz)
  double flatness_dB = 3.0;               ///< flat: within +- this of the band's mid level
  double mode_search_max_Hz = 1000.0;     ///< dominant mode: highest peak in [band_low, this]
  double antires_search_max_Hz = 2000.0;  ///< antiresonance: deepest notch in (mode, this]

  template <class V>
  void visit(V& v) {
    v("fs_Hz", fs_Hz);
    v("prbs_bits", prbs_bits);
    v("duration_s", duration_s);
    v("settle_s", settle_s);
    v("torque_amplitude_N_m", torque_amplitude_N_m);
    v("accel_noise_m_s2", accel_noise_m_s2);
    v("seed", seed);
    v("nperseg", nperseg);
    v("band_low_Hz", band_low_Hz);
    v("flatness_dB", flatness_dB);
    v("mode_search_max_Hz", mode_search_max_Hz);
    v("antires_search_max_Hz", antires_search_max_Hz);
  }
  void validate() const;
};

/// Features of a measured FRF magnitude.
struct FrfFeatures {
  double mode_Hz = 0;           ///< highest resonance peak above band_low
  double antiresonance_Hz = 0;  ///< most prominent notch between the mode and the search limit
  double bandwidth_Hz = 0;      ///< upper edge of the flat band starting at band_low
};

/// Reads the features off |H| sampled at f (ascending, uniformly spaced). Throws
/// ComputationFailed when no peak or notch is found.
FrfFeatures frf_features(const std::vector<double>& f_Hz, const std::vector<double>& magnitude,
                         const BandwidthIdentParams& params);

struct BandwidthIdentResult {
  FrfFeatures features;
  std::vector<double> t_s, torque_N_m, accel_m_s2;            ///< the recorded experiment (after settling)
  std::vector<double> f_Hz, magnitude, phase_rad, coherence;  ///< H1 estimate [m/s^2 / (N m)]
  std::vector<double> model_magnitude;                        ///< analytic |H| at the same f
};

/// Runs the experiment on the model and identifies the bandwidth.
BandwidthIdentResult identify_bandwidth(const TeleTweezParams& model, const BandwidthIdentParams& params);

}  // namespace mc::tweezers
