#pragma once
/// @file
/// Sine-dwell measurement: the magnitude and phase of a system at one frequency from its
/// input and output records under a steady sine, by least-squares fits of
/// a sin(w t) + b cos(w t) + c to both signals. Exact for any record length (no leakage
/// from a non-integer number of periods), unlike a single DFT bin. Used for the stepwise
/// frequency-response measurements of the thesis (Bode points of §3.4, §4.4).

#include <complex>
#include <span>

namespace mc::dsp {

struct SineDwellResult {
  std::complex<double> h;  ///< Y/U at the dwell frequency
  double magnitude = 0.0;  ///< |Y/U|
  double phase_rad = 0.0;  ///< arg(Y/U) in (-pi, pi]
  double input_amplitude = 0.0;
  double output_amplitude = 0.0;
  double output_residual_rms = 0.0;  ///< what the output sine fit does not explain (noise, distortion)
};

/// Measures Y/U at f_Hz from samples taken at fs_Hz, skipping the first `settle` samples
/// (the transient). Throws InvalidParams for mismatched sizes, fewer than one period after
/// settling, or an input without a component at f.
SineDwellResult sine_dwell(std::span<const double> u, std::span<const double> y, double f_Hz, double fs_Hz,
                           std::size_t settle = 0);

}  // namespace mc::dsp
