#pragma once
/// @file
/// The rendering pipeline of the dual-stage interface (thesis §3.3.2, §3.4.3, Fig. 3.12):
/// the haptic force signal is split by a Linkwitz-Riley 4th-order crossover; the low band
/// goes through C_LF = K_sys / G_LF (eq. 3.7) to the Pantograph, the high band through
/// C_HF = K_sys / G_HF x F(f_max) (eq. 3.8) to the Haptuator; both outputs are limited.
/// Runs at 10 kHz; tick() never allocates.

#include <array>
#include <complex>
#include <vector>

#include "microcobot/core/params.h"
#include "microcobot/dsp/sos.h"

namespace mc::haptics {

/// The identified second-order model of the Haptuator channel (eq. 3.6):
/// G_HF(s) = (b1 s + b0) / (s^2 + a1 s + a0), in (m/s^2)/V.
struct HfModel {
  double b1 = 250.0;
  double b0 = 6.406e5;
  double a1 = 2135.0;
  double a0 = 4.559e6;
  std::complex<double> response(double f_Hz) const;
};

/// Parameters of the rendering pipeline.
struct RenderPipelineParams {
  double fs_Hz = 1.0e4;             ///< loop rate (§3.3.1: 10 kHz)
  double cutoff_Hz = 200.0;         ///< crossover frequency (§3.4.2: 200 Hz)
  double k_sys_m_s2_per_N = 4.0;    ///< desired interface gain K_sys (eq. 3.7-3.8)
  double lf_gain_m_s2_per_N = 4.0;  ///< identified static gain G_0^LF of the Pantograph (eq. 3.5)
  std::vector<double> hf_num = {250.0, 6.406e5};        ///< G_HF numerator [b1, b0] (eq. 3.6)
  std::vector<double> hf_den = {1.0, 2135.0, 4.559e6};  ///< G_HF denominator [1, a1, a0]
  /// F(f_max) of eq. 3.8: a unit-gain 2nd-order Butterworth low-pass at f_max. The thesis
  /// uses f_max = 1 kHz, which costs -3 dB at 1 kHz; 4 kHz keeps the band to 1.25 kHz flat
  /// (-0.002 dB at 1.25 kHz) while still making C_HF causal and bounded (docs/errata.md).
  double f_max_Hz = 4000.0;
  /// Time alignment of the high band (extension, docs/errata.md): the Haptuator path leads the
  /// Pantograph path by some 50 degrees at the cut-off (its 2nd-order model of eq. 3.6 cannot
  /// hold the magnet's suspension phase), so the two LR4 halves no longer add in phase there; a
  /// delay of the high band, as loudspeaker crossovers align their drivers, restores the sum.
  /// Rounded to whole loop samples; haptics::identify chooses it from the measured responses.
  double hf_delay_s = 4.0e-4;
  double max_force_N = 4.0;     ///< Pantograph force limit (motor saturation)
  double max_voltage_V = 30.0;  ///< Haptuator amplifier input limit

  template <class V>
  void visit(V& v) {
    v("fs_Hz", fs_Hz);
    v("cutoff_Hz", cutoff_Hz);
    v("k_sys_m_s2_per_N", k_sys_m_s2_per_N);
    v("lf_gain_m_s2_per_N", lf_gain_m_s2_per_N);
    v("hf_num", hf_num);
    v("hf_den", hf_den);
    v("f_max_Hz", f_max_Hz);
    v("hf_delay_s", hf_delay_s);
    v("max_force_N", max_force_N);
    v("max_voltage_V", max_voltage_V);
  }
  void validate() const;
  HfModel hf_model() const;
  /// hf_delay_s in whole loop samples.
  int hf_delay_samples() const;
  /// The longest high-band delay the pipeline holds, in samples.
  static constexpr int kMaxDelaySamples = 63;
};

/// Commands for the two channels.
struct RenderOutput {
  double f_m_N = 0.0;  ///< Pantograph force command (y axis)
  double u_V = 0.0;    ///< Haptuator amplifier command
};

/// The crossover + compensation pipeline of Fig. 3.12.
class RenderPipeline {
 public:
  /// Designs the filters (allocates). Throws InvalidParams on bad parameters.
  explicit RenderPipeline(const RenderPipelineParams& params);

  /// One 10 kHz sample: haptic force (N) in, channel commands out. Never allocates.
  RenderOutput tick(double force_N) {
    const double lo = lp_.process(force_N);
    // High band through the alignment delay line (a ring of kMaxDelaySamples + 1 samples).
    delay_line_[head_] = hp_.process(force_N);
    const double hi = delay_line_[(head_ - delay_) & kRingMask];
    head_ = (head_ + 1) & kRingMask;
    RenderOutput out;
    out.f_m_N = clamp(c_lf_ * lo, params_.max_force_N);
    out.u_V = clamp(c_hf_.process(hi), params_.max_voltage_V);
    return out;
  }
  /// Zeroes every filter state.
  void reset();

  const RenderPipelineParams& params() const { return params_; }
  /// Analog-exact and digital responses of the pieces, for plots and tests.
  std::complex<double> lowpass_response(double f_Hz) const;
  std::complex<double> highpass_response(double f_Hz) const;
  /// Digital C_HF(e^{j 2 pi f / fs}) in V/N, the alignment delay included.
  std::complex<double> c_hf_response(double f_Hz) const;
  /// Analog C_HF(j 2 pi f) = K_sys / G_HF x F(f_max) of eq. 3.8.
  std::complex<double> c_hf_analog(double f_Hz) const;
  double c_lf() const { return c_lf_; }

 private:
  static double clamp(double v, double lim) { return v > lim ? lim : (v < -lim ? -lim : v); }
  static constexpr unsigned kRingMask = RenderPipelineParams::kMaxDelaySamples;
  static_assert((kRingMask & (kRingMask + 1)) == 0, "the ring length must be a power of two");
  RenderPipelineParams params_;
  dsp::SosFilter lp_;
  dsp::SosFilter hp_;
  dsp::SosFilter c_hf_;
  double c_lf_ = 1.0;
  std::array<double, kRingMask + 1> delay_line_{};
  unsigned head_ = 0;
  unsigned delay_ = 0;
};

}  // namespace mc::haptics
