#pragma once
/// @file
/// One-third-octave bands (IEC 61260-1, base 10): centres f_k = 1000 * 10^(k/10) Hz, edges
/// f_k * 10^(+-1/20), and band averages of a frequency response. The thesis reports the
/// rendering quality of the dual-stage interface per 1/3-octave band (§3.5).

#include <complex>
#include <span>
#include <vector>

namespace mc::dsp {

/// Exact base-10 centres 1000 * 10^(k/10) Hz of the bands whose centre lies in [fmin, fmax].
std::vector<double> third_octave_centres(double fmin_Hz, double fmax_Hz);

/// IEC 61260-1 nominal label of the 1/3-octave band whose exact base-10 centre is nearest to
/// fc_Hz: the R10 preferred numbers 1, 1.25, 1.6, 2, 2.5, 3.15, 4, 5, 6.3, 8 times a power of
/// ten (199.53 Hz -> 200 Hz, 63.096 Hz -> 63 Hz, 1258.9 Hz -> 1250 Hz). Tables quote bands by
/// these labels (thesis Table 3.4); measurements use the exact centres. Throws InvalidParams
/// for fc_Hz <= 0.
double third_octave_nominal(double fc_Hz);

struct OctaveBands {
  std::vector<double> fc_Hz;
  std::vector<double> mag_dB;       ///< 10 log10(mean |H|^2) over the points inside the band
  std::vector<std::size_t> points;  ///< how many FRF points each band averaged
};

/// Band averages of an FRF sampled at f_Hz (power average of |H|, so a flat |H| = g gives
/// 20 log10 g). Bands with centres in [fmin, fmax] that contain no point are left out.
/// Throws InvalidParams for mismatched sizes or fmin >= fmax.
OctaveBands third_octave_average(std::span<const double> f_Hz, std::span<const std::complex<double>> h,
                                 double fmin_Hz, double fmax_Hz);

}  // namespace mc::dsp
