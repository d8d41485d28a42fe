#pragma once
/// @file
/// Averaged-periodogram spectra (Welch's method) with scipy.signal's defaults and options:
/// PSD (scipy.signal.welch), cross spectral density (scipy.signal.csd), magnitude-squared
/// coherence (scipy.signal.coherence) and the H1 frequency-response estimate
/// H1 = Pxy / Pxx, the estimator the thesis uses for its PRBS identifications (§3.4).
///
/// Segments of `nperseg` samples overlapping by `noverlap` are detrended, multiplied by a
/// periodic Hann window, zero-padded to `nfft` and transformed; trailing samples that do
/// not fill a segment are ignored (scipy's welch/csd: boundary=None, padded=False).

#include <complex>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "microcobot/core/error.h"

namespace mc::dsp {

enum class Detrend { kConstant, kNone };
enum class Scaling { kDensity, kSpectrum };

/// Parses "constant"/"none" and "density"/"spectrum"; throw UsageError otherwise.
Detrend parse_detrend(const std::string& text);
Scaling parse_scaling(const std::string& text);

/// The longest FFT (nperseg, nfft) an estimator accepts: 2^22 points, about 200 MB of
/// buffers; beyond it the request is refused before anything is allocated.
inline constexpr std::size_t kMaxNfft = std::size_t{1} << 22;

struct WelchOptions {
  double fs_Hz = 1.0;                    ///< sample rate
  std::size_t nperseg = 256;             ///< segment length (clamped to the signal length, as scipy)
  std::optional<std::size_t> noverlap;   ///< overlap; default nperseg / 2
  std::size_t nfft = 0;                  ///< FFT length >= nperseg; 0 means nperseg
  Detrend detrend = Detrend::kConstant;  ///< remove each segment's mean, or not
  Scaling scaling = Scaling::kDensity;   ///< V^2/Hz (density) or V^2 (spectrum)
  bool onesided = true;                  ///< one-sided (doubled) spectrum for real data
};

/// A real spectrum: frequencies and values (PSD in unit^2/Hz or unit^2).
struct Spectrum {
  std::vector<double> f_Hz;
  std::vector<double> value;
};

/// A complex cross spectrum or frequency response.
struct ComplexSpectrum {
  std::vector<double> f_Hz;
  std::vector<std::complex<double>> value;
};

/// The H1 frequency-response estimate with its coherence.
struct FrfEstimate {
  std::vector<double> f_Hz;
  std::vector<std::complex<double>> h;  ///< Pxy / Pxx (output over input)
  std::vector<double> coherence;        ///< |Pxy|^2 / (Pxx Pyy), in [0, 1]
};

/// A spectrum that overflows: data so large (|x| near 1e154 and beyond) that their squares
/// exceed the largest double, so the estimate would hold infinities (an H1 estimate would read
/// 0). A failed computation (exit 4); signal() is "x" or "y", the argument that overflowed.
class SpectrumOverflow : public ComputationFailed {
 public:
  SpectrumOverflow(std::string signal, double max_abs);
  const std::string& signal() const { return signal_; }
  double max_abs() const { return max_abs_; }

 private:
  std::string signal_;
  double max_abs_;
};

/// A reusable Welch estimator: the window, FFT plan and buffers are made once for a given
/// options set and signal length, so repeated estimates do not allocate beyond their results.
class WelchEstimator {
 public:
  /// Throws InvalidParams for a signal or nperseg shorter than 2, nfft > kMaxNfft, noverlap >= nperseg, nfft
  /// < nperseg, fs <= 0.
  WelchEstimator(const WelchOptions& options, std::size_t signal_length);
  ~WelchEstimator();
  WelchEstimator(WelchEstimator&&) noexcept;
  WelchEstimator& operator=(WelchEstimator&&) noexcept;

  /// Frequencies of the estimates (rfftfreq for one-sided, fftfreq order otherwise).
  const std::vector<double>& frequencies() const;
  /// Number of averaged segments.
  std::size_t segments() const;
  /// The effective options (nperseg clamped, noverlap and nfft resolved).
  const WelchOptions& options() const;

  /// PSD of x (x.size() must equal the signal length given at construction). Throws
  /// SpectrumOverflow when it is not finite (as all() does).
  std::vector<double> psd(std::span<const double> x);
  /// Cross spectral density Pxy = E[conj(X) Y] (scipy's convention).
  std::vector<std::complex<double>> csd(std::span<const double> x, std::span<const double> y);
  /// Pxx, Pyy and Pxy in one pass over the data.
  void all(std::span<const double> x, std::span<const double> y, std::vector<double>& pxx,
           std::vector<double>& pyy, std::vector<std::complex<double>>& pxy);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// scipy.signal.welch(x, fs, nperseg=..., ...) (window 'hann', average 'mean').
/// Throws InvalidParams for an empty signal or bad options.
Spectrum welch(std::span<const double> x, const WelchOptions& options);

/// scipy.signal.csd(x, y, ...). x and y must have the same length.
ComplexSpectrum csd(std::span<const double> x, std::span<const double> y, const WelchOptions& options);

/// scipy.signal.coherence(x, y, ...).
Spectrum coherence(std::span<const double> x, std::span<const double> y, const WelchOptions& options);

/// H1 estimate of the system from input x to output y, with coherence.
FrfEstimate frf_h1(std::span<const double> x, std::span<const double> y, const WelchOptions& options);

/// The periodic Hann window of length n (scipy.signal.get_window('hann', n)).
std::vector<double> hann_periodic(std::size_t n);

}  // namespace mc::dsp
