#pragma once
/// @file
/// Butterworth and Linkwitz-Riley filter design, digital (second-order sections matching
/// scipy.signal.butter(..., output='sos')) and analog (zero-pole-gain).
///
/// The Linkwitz-Riley filter of order 2n is the Butterworth filter of order n squared
/// (cascaded twice). For LR4 the low and high outputs sum to an all-pass,
/// |LP + HP| = 1 at every frequency, which is what the dual-stage haptic interface's
/// crossover between the Pantograph and the Haptuator relies on (thesis §3.3, Fig. 3.8).

#include <complex>
#include <string>

#include "microcobot/dsp/sos.h"
#include "microcobot/dsp/zpk.h"

namespace mc::dsp {

enum class FilterType { kLowPass, kHighPass };

/// Parses "low"/"lowpass" or "high"/"highpass"; throws UsageError otherwise.
FilterType parse_filter_type(const std::string& text);

/// Analog Butterworth filter of `order` (1..20) with cut-off `wc_rad_s` (-3 dB), zpk in s.
Zpk butter_analog(int order, double wc_rad_s, FilterType type);

/// Digital Butterworth filter: analog prototype, prewarped so that the -3 dB point is at
/// `fc_Hz`, bilinear transform at `fs_Hz` (scipy.signal.butter(order, fc, type, fs=fs)).
/// Throws InvalidParams unless 1 <= order <= 20 and 0 < fc < fs/2.
Zpk butter_zpk(int order, double fc_Hz, double fs_Hz, FilterType type);

/// butter_zpk as second-order sections with scipy's 'nearest' pairing.
Sos butter(int order, double fc_Hz, double fs_Hz, FilterType type);

/// Analog Linkwitz-Riley filter of even `order` (2 or 4, or any even order up to 40):
/// the Butterworth filter of order/2 squared. -6 dB at wc.
Zpk linkwitz_riley_analog(int order, double wc_rad_s, FilterType type);

/// Digital Linkwitz-Riley filter: the sections of butter(order/2, ...) twice over.
Sos linkwitz_riley(int order, double fc_Hz, double fs_Hz, FilterType type);

/// A crossover pair sharing one cut-off.
struct Crossover {
  Sos low;
  Sos high;
};

/// Linkwitz-Riley crossover pair (LR4 when order = 4). For order 4 (and 8, 12, ...),
/// |low + high| = 1 at all frequencies; for LR2 the sum is all-pass only with the high
/// output inverted (low - high).
Crossover linkwitz_riley_crossover(int order, double fc_Hz, double fs_Hz);

/// Frequency response of a digital SOS cascade at `f_Hz` (scipy.signal.sosfreqz).
std::complex<double> sos_response(const Sos& sos, double f_Hz, double fs_Hz);

/// Frequency response of an analog zpk system at `w_rad_s` (s = j w).
std::complex<double> zpk_response_analog(const Zpk& zpk, double w_rad_s);

}  // namespace mc::dsp
