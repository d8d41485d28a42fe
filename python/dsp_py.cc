// microcobot.dsp: Butterworth and Linkwitz-Riley design, sosfilt, Welch spectra, MLS/PRBS and the
// rational transfer-function fit, with scipy.signal's names and signatures where they overlap
// (arrays in, arrays out). The numbers are the library's (dsp/, ident/tf_fit).

#include <complex>

#include "common.h"
#include "microcobot/dsp/butterworth.h"
#include "microcobot/dsp/signals.h"
#include "microcobot/dsp/sos.h"
#include "microcobot/dsp/welch.h"
#include "microcobot/ident/tf_fit.h"

namespace mc::py {
namespace {

using namespace pybind11::literals;

/// scipy's (n_sections, 6) sos array -> the library's cascade (checked: shape, finite, a0 != 0).
dsp::Sos sos_from(const DoubleArray& a) {
  if (a.ndim() != 2 || a.shape(1) != 6 || a.shape(0) < 1) {
    throw InvalidInput("sos: expected an array of shape (n_sections, 6)");
  }
  check_array(a, "sos", 2, 6);
  dsp::Sos sos;
  for (py::ssize_t i = 0; i < a.shape(0); ++i) {
    std::array<double, 6> row{};
    for (int j = 0; j < 6; ++j) row[static_cast<std::size_t>(j)] = a.at(i, j);
    if (row[3] == 0.0) throw InvalidInput("sos: a0 of section " + std::to_string(i) + " is 0");
    sos.push_back(dsp::Biquad::from_row(row));
  }
  return sos;
}

py::array_t<double> sos_array(const dsp::Sos& sos) {
  py::array_t<double> a({static_cast<py::ssize_t>(sos.size()), py::ssize_t{6}});
  auto r = a.mutable_unchecked<2>();
  for (std::size_t i = 0; i < sos.size(); ++i) {
    const auto row = sos[i].row();
    for (std::size_t j = 0; j < 6; ++j) r(static_cast<py::ssize_t>(i), static_cast<py::ssize_t>(j)) = row[j];
  }
  return a;
}

py::array_t<std::complex<double>> to_complex_array(const std::vector<std::complex<double>>& v) {
  py::array_t<std::complex<double>> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

/// scipy's (Wn, fs) convention: with fs, Wn is in Hz; without, Wn is a fraction of Nyquist (fs = 2).
std::pair<double, double> cutoff(double wn, std::optional<double> fs) {
  const double f = fs.value_or(2.0);
  require(std::isfinite(f) && f > 0.0, "fs", "must be > 0", f);
  return {wn, f};
}

dsp::WelchOptions welch_options(double fs, std::optional<std::size_t> nperseg,
                                std::optional<std::size_t> noverlap, std::optional<std::size_t> nfft,
                                const std::string& window, const std::string& detrend,
                                const std::string& scaling, bool onesided) {
  if (window != "hann" && window != "hanning") {
    throw InvalidInput("window: only 'hann' is supported (got '" + window + "')");
  }
  dsp::WelchOptions o;
  o.fs_Hz = fs;
  o.nperseg = nperseg.value_or(256);
  o.noverlap = noverlap;
  o.nfft = nfft.value_or(0);
  o.detrend = dsp::parse_detrend(detrend);
  o.scaling = dsp::parse_scaling(scaling);
  o.onesided = onesided;
  return o;
}

}  // namespace

void bind_dsp(py::module_& m) {
  m.def(
      "butter",
      [](int n, double wn, const std::string& btype, std::optional<double> fs, const std::string& output) {
        if (output != "sos") throw InvalidInput("output: only 'sos' is supported (got '" + output + "')");
        const auto [fc, f] = cutoff(wn, fs);
        return sos_array(dsp::butter(n, fc, f, dsp::parse_filter_type(btype)));
      },
      "N"_a, "Wn"_a, "btype"_a = "low", "fs"_a = py::none(), "output"_a = "sos",
      "Digital Butterworth filter as second-order sections, as scipy.signal.butter(N, Wn, btype, fs=fs, "
      "output='sos'): Wn in Hz when fs [Hz] is given, else a fraction of Nyquist. btype: 'low' | 'high'.");
  m.def(
      "linkwitz_riley",
      [](int n, double wn, const std::string& btype, std::optional<double> fs) {
        const auto [fc, f] = cutoff(wn, fs);
        return sos_array(dsp::linkwitz_riley(n, fc, f, dsp::parse_filter_type(btype)));
      },
      "N"_a, "Wn"_a, "btype"_a = "low", "fs"_a = py::none(),
      "Linkwitz-Riley filter of even order N (the Butterworth of order N/2 squared; -6 dB at Wn) as sos. The "
      "crossover of the dual-stage interface (thesis §3.3, Fig. 3.8) is LR4.");
  m.def(
      "crossover",
      [](int n, double wn, std::optional<double> fs) {
        const auto [fc, f] = cutoff(wn, fs);
        const auto c = dsp::linkwitz_riley_crossover(n, fc, f);
        return py::make_tuple(sos_array(c.low), sos_array(c.high));
      },
      "N"_a, "Wn"_a, "fs"_a = py::none(),
      "Linkwitz-Riley crossover pair (low, high) sharing cut-off Wn; for N = 4 |low + high| = 1 at every "
      "frequency (thesis §3.3).");
  m.def(
      "sosfilt",
      [](const DoubleArray& sos, const DoubleArray& x) {
        const auto s = sos_from(sos);
        const auto xs = span_of(x, "x");
        auto y = nogil([&] { return dsp::sosfilt(s, xs); });
        require_finite_result(y, "sosfilt");
        return to_array(y);
      },
      "sos"_a, "x"_a,
      "scipy.signal.sosfilt(sos, x) for a 1-D x from zero initial state (transposed direct form II).");
  m.def(
      "sosfreqz",
      [](const DoubleArray& sos, py::object worN, double fs) {
        const auto s = sos_from(sos);
        std::vector<double> f;
        if (py::isinstance<py::int_>(worN)) {
          const auto n = worN.cast<long>();
          require(n >= 1, "worN", "must be >= 1", static_cast<double>(n));
          for (long i = 0; i < n; ++i)
            f.push_back(0.5 * fs * static_cast<double>(i) / static_cast<double>(n));
        } else {
          const auto fa = worN.cast<DoubleArray>();
          const auto sp = span_of(fa, "worN");
          f.assign(sp.begin(), sp.end());
        }
        std::vector<std::complex<double>> h;
        for (double fi : f) h.push_back(dsp::sos_response(s, fi, fs));
        return py::make_tuple(to_array(f), to_complex_array(h));
      },
      "sos"_a, "worN"_a = 512, "fs"_a = 2 * M_PI,
      "Frequency response (f, h) of an sos cascade, as scipy.signal.sosfreqz(sos, worN, fs=fs): worN points "
      "on "
      "[0, fs/2) or the given frequencies (in the units of fs).");
  m.def(
      "welch",
      [](const DoubleArray& x, double fs, std::optional<std::size_t> nperseg,
         std::optional<std::size_t> noverlap, std::optional<std::size_t> nfft, const std::string& window,
         const std::string& detrend, const std::string& scaling, bool onesided) {
        const auto o = welch_options(fs, nperseg, noverlap, nfft, window, detrend, scaling, onesided);
        const auto xs = span_of(x, "x", 2);
        const auto s = nogil([&] { return dsp::welch(xs, o); });
        return py::make_tuple(to_array(s.f_Hz), to_array(s.value));
      },
      "x"_a, "fs"_a = 1.0, "nperseg"_a = py::none(), "noverlap"_a = py::none(), "nfft"_a = py::none(),
      "window"_a = "hann", "detrend"_a = "constant", "scaling"_a = "density", "return_onesided"_a = true,
      "Welch PSD (f [Hz], Pxx [unit^2/Hz]) as scipy.signal.welch(x, fs, window='hann', nperseg=..., ...); "
      "nperseg "
      "defaults to 256 (clamped to len(x)).");
  m.def(
      "csd",
      [](const DoubleArray& x, const DoubleArray& y, double fs, std::optional<std::size_t> nperseg,
         std::optional<std::size_t> noverlap, std::optional<std::size_t> nfft) {
        const auto o = welch_options(fs, nperseg, noverlap, nfft, "hann", "constant", "density", true);
        const auto xs = span_of(x, "x", 2), ys = span_of(y, "y", 2);
        const auto s = nogil([&] { return dsp::csd(xs, ys, o); });
        return py::make_tuple(to_array(s.f_Hz), to_complex_array(s.value));
      },
      "x"_a, "y"_a, "fs"_a = 1.0, "nperseg"_a = py::none(), "noverlap"_a = py::none(), "nfft"_a = py::none(),
      "Cross spectral density (f, Pxy) as scipy.signal.csd (Pxy = E[conj(X) Y]).");
  m.def(
      "coherence",
      [](const DoubleArray& x, const DoubleArray& y, double fs, std::optional<std::size_t> nperseg,
         std::optional<std::size_t> noverlap, std::optional<std::size_t> nfft) {
        const auto o = welch_options(fs, nperseg, noverlap, nfft, "hann", "constant", "density", true);
        const auto xs = span_of(x, "x", 2), ys = span_of(y, "y", 2);
        const auto s = nogil([&] { return dsp::coherence(xs, ys, o); });
        return py::make_tuple(to_array(s.f_Hz), to_array(s.value));
      },
      "x"_a, "y"_a, "fs"_a = 1.0, "nperseg"_a = py::none(), "noverlap"_a = py::none(), "nfft"_a = py::none(),
      "Magnitude-squared coherence (f, Cxy) as scipy.signal.coherence.");
  m.def(
      "tfestimate",
      [](const DoubleArray& x, const DoubleArray& y, double fs, std::optional<std::size_t> nperseg,
         std::optional<std::size_t> noverlap, std::optional<std::size_t> nfft) {
        const auto o = welch_options(fs, nperseg, noverlap, nfft, "hann", "constant", "density", true);
        const auto xs = span_of(x, "x", 2), ys = span_of(y, "y", 2);
        const auto e = nogil([&] { return dsp::frf_h1(xs, ys, o); });
        return py::make_tuple(to_array(e.f_Hz), to_complex_array(e.h), to_array(e.coherence));
      },
      "x"_a, "y"_a, "fs"_a = 1.0, "nperseg"_a = py::none(), "noverlap"_a = py::none(), "nfft"_a = py::none(),
      "H1 frequency-response estimate (f [Hz], H = Pxy / Pxx, coherence) from input x to output y: the "
      "estimator "
      "of the thesis's PRBS identifications (§3.4).");
  m.def(
      "max_len_seq",
      [](int nbits, std::optional<std::size_t> length) {
        const auto s = dsp::max_len_seq(nbits, length.value_or(0));
        py::array_t<std::int8_t> a(static_cast<py::ssize_t>(s.size()));
        std::copy(s.begin(), s.end(), a.mutable_data());
        return a;
      },
      "nbits"_a, "length"_a = py::none(),
      "Maximum-length sequence of 0/1 (int8), equal to scipy.signal.max_len_seq(nbits, length=length)[0] "
      "(scipy "
      "also returns the register state; this does not).");
  m.def(
      "prbs",
      [](int nbits, std::size_t length, int clock_divider, double amplitude) {
        require(clock_divider >= 1, "clock_divider", "must be >= 1", clock_divider);
        require(std::isfinite(amplitude), "amplitude", "must be finite", amplitude);
        return to_array(dsp::prbs(nbits, length, clock_divider, amplitude));
      },
      "nbits"_a, "length"_a, "clock_divider"_a = 1, "amplitude"_a = 1.0,
      "+-amplitude PRBS: the MLS of nbits, each bit held clock_divider samples (thesis §3.4's identification "
      "input).");
  m.def(
      "tffit",
      [](const DoubleArray& f, py::object h, int nz, int np, double fmin, double fmax, double dt,
         std::optional<DoubleArray> weights, const std::string& error) {
        const auto fs = span_of(f, "f");
        const auto ha =
            h.cast<py::array_t<std::complex<double>, py::array::c_style | py::array::forcecast>>();
        if (ha.ndim() != 1 || static_cast<std::size_t>(ha.size()) != fs.size()) {
          throw InvalidInput("h: expected a 1-D array of the same length as f");
        }
        for (py::ssize_t i = 0; i < ha.size(); ++i) {
          if (!std::isfinite(ha.data()[i].real()) || !std::isfinite(ha.data()[i].imag())) {
            throw InvalidInput("h: non-finite value at index " + std::to_string(i));
          }
        }
        ident::TfFitOptions o;
        o.nz = nz;
        o.np = np;
        o.fmin_Hz = fmin;
        o.fmax_Hz = fmax;
        o.dt = dt;
        if (weights) {
          const auto w = span_of(*weights, "weights");
          o.weights.assign(w.begin(), w.end());
        }
        if (error == "complex") {
          o.error = ident::TfFitError::kComplex;
        } else if (error == "log-magnitude") {
          o.error = ident::TfFitError::kLogMagnitude;
        } else {
          throw InvalidInput("error: expected 'complex' or 'log-magnitude' (got '" + error + "')");
        }
        const std::span<const std::complex<double>> hs(ha.data(), static_cast<std::size_t>(ha.size()));
        const auto r = nogil([&] { return ident::fit_tf(fs, hs, o); });
        return py::dict("num"_a = to_array(r.tf.num()), "den"_a = to_array(r.tf.den()), "dt"_a = r.tf.dt(),
                        "poles"_a = to_complex_array(r.tf.poles()),
                        "zeros"_a = to_complex_array(r.tf.zeros()),
                        "relative_rms_error"_a = r.relative_rms_error, "points"_a = r.points);
      },
      "f"_a, "h"_a, "nz"_a = 1, "np"_a = 2, "fmin"_a = 0.0,
      "fmax"_a = std::numeric_limits<double>::infinity(), "dt"_a = 0.0, "weights"_a = py::none(),
      "error"_a = "complex",
      "Rational transfer-function fit N/D of orders (nz, np) to the frequency response h at f [Hz] (thesis "
      "eq. "
      "3.6): Sanathanan-Koerner then Levenberg-Marquardt. dt = 0: continuous (s); > 0: discrete (z). Returns "
      "{'num', 'den' (monic, highest power first), 'dt', 'poles', 'zeros', 'relative_rms_error', 'points'}.");
}

}  // namespace mc::py
