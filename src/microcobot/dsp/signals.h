#pragma once
/// @file
/// Test and excitation signals: maximum-length sequences (identical to
/// scipy.signal.max_len_seq), +-1 PRBS with a clock divider (the identification input of
/// thesis §3.4), logarithmic sine sweeps, white noise, sawtooth with a rise fraction (the
/// stick-slip drive waveform of §2.2), sine and step. All sampled at fs with t_k = k / fs.

#include <cstdint>
#include <vector>

namespace mc::dsp {

/// Maximum-length sequence of 0s and 1s from a Fibonacci shift register of `nbits` (2..32)
/// with scipy's default taps, seeded with all ones: exactly scipy.signal.max_len_seq(nbits,
/// length=length)[0]. `length` = 0 gives the full period 2^nbits - 1.
/// Throws InvalidParams for nbits outside 2..32.
std::vector<std::uint8_t> max_len_seq(int nbits, std::size_t length = 0);

/// The feedback taps scipy uses for `nbits` (e.g. {7, 6, 1} for 8 bits).
std::vector<int> mls_taps(int nbits);

/// +-amplitude pseudo-random binary sequence of `length` samples: the MLS of `nbits`
/// (1 -> +amplitude, 0 -> -amplitude), each bit held for `clock_divider` samples, repeated
/// periodically. Its spectrum is flat (within the sinc^2 of the hold) up to fs/(2 divider).
std::vector<double> prbs(int nbits, std::size_t length, int clock_divider = 1, double amplitude = 1.0);

/// Logarithmic sine sweep from f0 to f1 over `duration_s` (scipy.signal.chirp(t, f0, T, f1,
/// method='logarithmic') times amplitude: a cosine whose instantaneous frequency is
/// f0 (f1/f0)^(t/T)). Requires 0 < f0, f1 <= fs/2.
std::vector<double> log_sweep(double f0_Hz, double f1_Hz, double duration_s, double fs_Hz,
                              double amplitude = 1.0);

/// Gaussian white noise of standard deviation `stddev`, from mc::Rng(seed).
std::vector<double> white_noise(std::size_t n, double stddev, std::uint64_t seed);

/// One value of a unit sawtooth at `phase_rad` (scipy.signal.sawtooth(phase, width)): rises
/// linearly from -1 to +1 over the fraction `rise_fraction` of each period, then falls back.
/// rise_fraction near 1 is the forward stick-slip waveform (slow rise, fast drop), near 0
/// the backward one (fast rise, slow drop).
double sawtooth_value(double phase_rad, double rise_fraction);

/// Sawtooth of frequency f and amplitude `amplitude` (peak), n samples at fs.
std::vector<double> sawtooth(std::size_t n, double f_Hz, double fs_Hz, double amplitude,
                             double rise_fraction);

/// amplitude * sin(2 pi f t + phase).
std::vector<double> sine(std::size_t n, double f_Hz, double fs_Hz, double amplitude = 1.0,
                         double phase_rad = 0.0);

/// 0 before t0, amplitude from t0 on.
std::vector<double> step_signal(std::size_t n, double fs_Hz, double t0_s, double amplitude = 1.0);

}  // namespace mc::dsp
