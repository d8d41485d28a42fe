#include "microcobot/dsp/welch.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>
#include <unsupported/Eigen/FFT>

#include "microcobot/core/error.h"

namespace mc::dsp {

using C = std::complex<double>;

SpectrumOverflow::SpectrumOverflow(std::string signal, double max_abs)
    : ComputationFailed(
          fmt::format("{}: the power spectrum overflows (values up to {:g}; their squares exceed "
                      "the largest double)",
                      signal, max_abs)),
      signal_(std::move(signal)),
      max_abs_(max_abs) {}

namespace {

double max_abs(std::span<const double> x) {
  double m = 0.0;
  for (double v : x) m = std::max(m, std::abs(v));
  return m;
}

// Throws SpectrumOverflow naming `signal` unless every value of the estimate is finite.
template <class T>
void require_finite_spectrum(const std::vector<T>& p, const char* signal, std::span<const double> data) {
  for (const auto& v : p) {
    if (std::isfinite(std::abs(v))) continue;
    for (double d : data) {
      if (!std::isfinite(d))
        throw ComputationFailed(std::string(signal) + ": the data hold a non-finite value");
    }
    throw SpectrumOverflow(signal, max_abs(data));
  }
}

// A spectrum that overflows although the data's periodogram cannot (|X|^2 <= (n max|x|)^2, finite)
// was made so by the density's scale 1 / (fs S2): a sampling rate near the smallest double.
template <class T>
void require_finite_scaling(const std::vector<T>& p, std::span<const double> data, std::size_t n,
                            double fs_Hz) {
  if (std::all_of(p.begin(), p.end(), [](const T& v) { return std::isfinite(std::abs(v)); })) return;
  const double bound = max_abs(data) * static_cast<double>(n);
  if (std::isfinite(bound * bound))
    throw InvalidParams("fs_Hz", "too small: the spectral density |X|^2 / (fs_Hz sum(w^2)) overflows", fs_Hz);
}

}  // namespace

Detrend parse_detrend(const std::string& text) {
  if (text == "constant") return Detrend::kConstant;
  if (text == "none" || text == "false") return Detrend::kNone;
  throw UsageError("detrend must be constant or none (got '" + text + "')");
}

Scaling parse_scaling(const std::string& text) {
  if (text == "density") return Scaling::kDensity;
  if (text == "spectrum") return Scaling::kSpectrum;
  throw UsageError("scaling must be density or spectrum (got '" + text + "')");
}

std::vector<double> hann_periodic(std::size_t n) {
  std::vector<double> w(n);
  for (std::size_t i = 0; i < n; ++i) {
    w[i] = 0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * static_cast<double>(i) / static_cast<double>(n));
  }
  if (n == 1) w[0] = 1.0;
  return w;
}

struct WelchEstimator::Impl {
  WelchOptions opt;
  std::size_t length = 0;
  std::size_t step = 0;
  std::size_t nseg = 0;
  std::size_t nout = 0;
  std::vector<double> window;
  double scale = 1.0;
  std::vector<double> f;
  Eigen::FFT<double> fft;
  std::vector<double> buf_x, buf_y;
  std::vector<C> spec_x, spec_y;

  // Detrends, windows and zero-pads segment `seg` of `x` into `buf`, then transforms it.
  void transform(std::span<const double> x, std::size_t seg, std::vector<double>& buf, std::vector<C>& spec) {
    const double* src = x.data() + seg * step;
    const std::size_t n = opt.nperseg;
    double mean = 0.0;
    if (opt.detrend == Detrend::kConstant) {
      for (std::size_t i = 0; i < n; ++i) mean += src[i];
      mean /= static_cast<double>(n);
    }
    for (std::size_t i = 0; i < n; ++i) buf[i] = (src[i] - mean) * window[i];
    fft.fwd(spec.data(), buf.data(), static_cast<Eigen::Index>(opt.nfft));
  }

  // One-sided doubling and scaling (scipy's _spectral_helper).
  double factor(std::size_t k) const {
    if (!opt.onesided) return scale;
    const bool edge = k == 0 || (opt.nfft % 2 == 0 && k == nout - 1);
    return edge ? scale : 2.0 * scale;
  }
};

WelchEstimator::WelchEstimator(const WelchOptions& options, std::size_t signal_length)
    : impl_(std::make_unique<Impl>()) {
  auto& m = *impl_;
  m.opt = options;
  require_positive(options.fs_Hz, "fs_Hz");
  // A one-point FFT has no spectrum (and Eigen's half-spectrum real FFT of length 1 reads
  // out of bounds): segments and signals need two samples at least.
  require(signal_length >= 2, "x", "signal must have at least 2 samples", static_cast<double>(signal_length));
  require(options.nperseg >= 2, "nperseg", "must be >= 2", static_cast<double>(options.nperseg));
  m.opt.nperseg = std::min(options.nperseg, signal_length);
  const std::size_t noverlap = options.noverlap.value_or(m.opt.nperseg / 2);
  require(noverlap < m.opt.nperseg, "noverlap", "must be < nperseg", static_cast<double>(noverlap));
  m.opt.noverlap = noverlap;
  m.opt.nfft = options.nfft == 0 ? m.opt.nperseg : options.nfft;
  require(m.opt.nfft >= m.opt.nperseg, "nfft", "must be >= nperseg", static_cast<double>(options.nfft));
  // The work budget: buffers of ~48 bytes per FFT point are made before any data is read.
  require(m.opt.nfft <= kMaxNfft, options.nfft == 0 ? "nperseg" : "nfft",
          fmt::format("must be <= {} (the FFT length limit)", kMaxNfft), static_cast<double>(m.opt.nfft));
  m.length = signal_length;
  m.step = m.opt.nperseg - noverlap;
  m.nseg = (signal_length - noverlap) / m.step;
  m.window = hann_periodic(m.opt.nperseg);
  double sum = 0.0, sum2 = 0.0;
  for (double w : m.window) {
    sum += w;
    sum2 += w * w;
  }
  m.scale = m.opt.scaling == Scaling::kDensity ? 1.0 / (m.opt.fs_Hz * sum2) : 1.0 / (sum * sum);
  // The density's scale 1 / (fs S2) overflows for a sampling rate near the smallest double: the
  // rate is wrong, not the data.
  require(std::isfinite(m.scale), "fs_Hz", "too small: the density's scale 1 / (fs_Hz sum(w^2)) overflows",
          options.fs_Hz);
  const std::size_t nfft = m.opt.nfft;
  m.nout = m.opt.onesided ? nfft / 2 + 1 : nfft;
  m.f.resize(m.nout);
  const double df = m.opt.fs_Hz / static_cast<double>(nfft);
  for (std::size_t k = 0; k < m.nout; ++k) {
    // fftfreq: the upper half are negative frequencies.
    const bool negative = !m.opt.onesided && k >= (nfft + 1) / 2;
    m.f[k] =
        negative ? (static_cast<double>(k) - static_cast<double>(nfft)) * df : static_cast<double>(k) * df;
  }
  if (m.opt.onesided) m.fft.SetFlag(Eigen::FFT<double>::HalfSpectrum);
  m.buf_x.assign(nfft, 0.0);
  m.buf_y.assign(nfft, 0.0);
  m.spec_x.assign(nfft, C(0, 0));
  m.spec_y.assign(nfft, C(0, 0));
}

WelchEstimator::~WelchEstimator() = default;
WelchEstimator::WelchEstimator(WelchEstimator&&) noexcept = default;
WelchEstimator& WelchEstimator::operator=(WelchEstimator&&) noexcept = default;

const std::vector<double>& WelchEstimator::frequencies() const { return impl_->f; }
std::size_t WelchEstimator::segments() const { return impl_->nseg; }
const WelchOptions& WelchEstimator::options() const { return impl_->opt; }

std::vector<double> WelchEstimator::psd(std::span<const double> x) {
  auto& m = *impl_;
  require(x.size() == m.length, "x", "length differs from the estimator's", static_cast<double>(x.size()));
  std::vector<double> p(m.nout, 0.0);
  for (std::size_t s = 0; s < m.nseg; ++s) {
    m.transform(x, s, m.buf_x, m.spec_x);
    for (std::size_t k = 0; k < m.nout; ++k) p[k] += std::norm(m.spec_x[k]);
  }
  const double inv = 1.0 / static_cast<double>(m.nseg);
  for (std::size_t k = 0; k < m.nout; ++k) p[k] *= m.factor(k) * inv;
  require_finite_scaling(p, x, m.opt.nperseg, m.opt.fs_Hz);
  require_finite_spectrum(p, "x", x);
  return p;
}

std::vector<std::complex<double>> WelchEstimator::csd(std::span<const double> x, std::span<const double> y) {
  std::vector<double> pxx, pyy;
  std::vector<C> pxy;
  all(x, y, pxx, pyy, pxy);
  return pxy;
}

void WelchEstimator::all(std::span<const double> x, std::span<const double> y, std::vector<double>& pxx,
                         std::vector<double>& pyy, std::vector<std::complex<double>>& pxy) {
  auto& m = *impl_;
  require(x.size() == m.length, "x", "length differs from the estimator's", static_cast<double>(x.size()));
  require(y.size() == m.length, "y", "must have the length of x", static_cast<double>(y.size()));
  pxx.assign(m.nout, 0.0);
  pyy.assign(m.nout, 0.0);
  pxy.assign(m.nout, C(0, 0));
  for (std::size_t s = 0; s < m.nseg; ++s) {
    m.transform(x, s, m.buf_x, m.spec_x);
    m.transform(y, s, m.buf_y, m.spec_y);
    for (std::size_t k = 0; k < m.nout; ++k) {
      pxx[k] += std::norm(m.spec_x[k]);
      pyy[k] += std::norm(m.spec_y[k]);
      pxy[k] += std::conj(m.spec_x[k]) * m.spec_y[k];
    }
  }
  const double inv = 1.0 / static_cast<double>(m.nseg);
  for (std::size_t k = 0; k < m.nout; ++k) {
    const double g = m.factor(k) * inv;
    pxx[k] *= g;
    pyy[k] *= g;
    pxy[k] *= g;
  }
  require_finite_scaling(pxx, x, m.opt.nperseg, m.opt.fs_Hz);
  require_finite_scaling(pyy, y, m.opt.nperseg, m.opt.fs_Hz);
  require_finite_spectrum(pxx, "x", x);
  require_finite_spectrum(pyy, "y", y);
  // Both finite, their cross spectrum is bounded by sqrt(Pxx Pyy) up to rounding; checked all the same.
  require_finite_spectrum(pxy, max_abs(x) >= max_abs(y) ? "x" : "y", max_abs(x) >= max_abs(y) ? x : y);
}

Spectrum welch(std::span<const double> x, const WelchOptions& options) {
  WelchEstimator est(options, x.size());
  return {est.frequencies(), est.psd(x)};
}

ComplexSpectrum csd(std::span<const double> x, std::span<const double> y, const WelchOptions& options) {
  require(y.size() == x.size(), "y", "must have the length of x", static_cast<double>(y.size()));
  WelchEstimator est(options, x.size());
  return {est.frequencies(), est.csd(x, y)};
}

Spectrum coherence(std::span<const double> x, std::span<const double> y, const WelchOptions& options) {
  const auto e = frf_h1(x, y, options);
  return {e.f_Hz, e.coherence};
}

FrfEstimate frf_h1(std::span<const double> x, std::span<const double> y, const WelchOptions& options) {
  require(y.size() == x.size(), "y", "must have the length of x", static_cast<double>(y.size()));
  WelchEstimator est(options, x.size());
  std::vector<double> pxx, pyy;
  std::vector<C> pxy;
  est.all(x, y, pxx, pyy, pxy);
  FrfEstimate out;
  out.f_Hz = est.frequencies();
  out.h.resize(pxx.size());
  out.coherence.resize(pxx.size());
  for (std::size_t k = 0; k < pxx.size(); ++k) {
    // A bin where the input has no power carries no information: H = 0, coherence 0.
    const bool empty = !(pxx[k] > 0.0) || !(pyy[k] > 0.0);
    out.h[k] = pxx[k] > 0.0 ? pxy[k] / pxx[k] : C(0, 0);
    out.coherence[k] = empty ? 0.0 : std::norm(pxy[k]) / (pxx[k] * pyy[k]);
  }
  return out;
}

}  // namespace mc::dsp
