#include "microcobot/tweezers/bandwidth.h"

#include <algorithm>
#include <cmath>

#include "microcobot/core/error.h"
#include "microcobot/core/rng.h"
#include "microcobot/dsp/peaks.h"
#include "microcobot/dsp/signals.h"
#include "microcobot/dsp/welch.h"

namespace mc::tweezers {

void BandwidthIdentParams::validate() const {
  require_positive(fs_Hz, "fs_Hz");
  require(prbs_bits >= 4 && prbs_bits <= 24, "prbs_bits", "must be in 4..24", prbs_bits);
  require_positive(duration_s, "duration_s");
  // The work budget, before the record is made (docs/cli.md, "Limits").
  require_budget(duration_s * fs_Hz, kMaxRecordedSamples, "identify.duration_s",
                 "recorded samples (duration_s x fs_Hz)");
  require_non_negative(settle_s, "settle_s");
  require(settle_s < duration_s, "settle_s", "must be shorter than duration_s", settle_s);
  require_positive(torque_amplitude_N_m, "torque_amplitude_N_m");
  require_non_negative(accel_noise_m_s2, "accel_noise_m_s2");
  require(nperseg >= 64, "nperseg", "must be >= 64", nperseg);
  require((duration_s - settle_s) * fs_Hz >= 2.0 * nperseg, "nperseg", "must fit twice in the record",
          nperseg);
  require_positive(band_low_Hz, "band_low_Hz");
  require_positive(flatness_dB, "flatness_dB");
  require(mode_search_max_Hz > band_low_Hz && mode_search_max_Hz < fs_Hz / 2, "mode_search_max_Hz",
          "must be in (band_low_Hz, fs/2)", mode_search_max_Hz);
  require(antires_search_max_Hz <= fs_Hz / 2, "antires_search_max_Hz", "must be <= fs/2",
          antires_search_max_Hz);
}

FrfFeatures frf_features(const std::vector<double>& f, const std::vector<double>& mag,
                         const BandwidthIdentParams& p) {
  require(f.size() == mag.size() && f.size() > 8, "frf", "needs matching f and |H| of > 8 points");
  std::vector<double> db(mag.size());
  for (std::size_t i = 0; i < mag.size(); ++i) db[i] = 20.0 * std::log10(std::max(mag[i], 1e-300));
  auto index_of = [&](double hz) {
    return static_cast<std::size_t>(std::lower_bound(f.begin(), f.end(), hz) - f.begin());
  };
  FrfFeatures out;
  // Dominant mode: the highest local maximum in [band_low, mode_search_max].
  const std::size_t lo = index_of(p.band_low_Hz), hi = std::min(index_of(p.mode_search_max_Hz), f.size() - 1);
  if (hi <= lo + 2) throw ComputationFailed("bandwidth: search band holds too few frequencies");
  {
    const std::span<const double> xs(f.data() + lo, hi - lo + 1), ys(db.data() + lo, hi - lo + 1);
    dsp::PeakOptions o;
    o.min_prominence = 1.0;
    const auto peaks = dsp::find_peaks_xy(xs, ys, o);
    if (peaks.empty()) throw ComputationFailed("bandwidth: no resonance peak found in the FRF");
    const auto best = std::max_element(peaks.begin(), peaks.end(),
                                       [](const auto& a, const auto& b) { return a.height < b.height; });
    out.mode_Hz = best->x;
  }
  // Antiresonance: the most prominent notch (peak of -dB) above the mode.
  {
    const std::size_t a0 = index_of(out.mode_Hz) + 1,
                      a1 = std::min(index_of(p.antires_search_max_Hz), f.size() - 1);
    if (a1 <= a0 + 2) throw ComputationFailed("bandwidth: no room above the mode for an antiresonance");
    std::vector<double> neg(db.begin() + static_cast<std::ptrdiff_t>(a0),
                            db.begin() + static_cast<std::ptrdiff_t>(a1) + 1);
    for (double& v : neg) v = -v;
    dsp::PeakOptions o;
    o.min_prominence = 3.0;
    const auto notches = dsp::find_peaks_xy(std::span<const double>(f.data() + a0, a1 - a0 + 1), neg, o);
    if (notches.empty()) throw ComputationFailed("bandwidth: no antiresonance found above the mode");
    const auto best = std::max_element(notches.begin(), notches.end(), [](const auto& a, const auto& b) {
      return a.prominence < b.prominence;
    });
    out.antiresonance_Hz = best->x;
  }
  // Flat band: the longest [band_low, f_b] whose dB spread stays within +- flatness_dB.
  double mn = db[lo], mx = db[lo];
  out.bandwidth_Hz = f[lo];
  for (std::size_t i = lo; i < f.size() && f[i] < out.mode_Hz; ++i) {
    mn = std::min(mn, db[i]);
    mx = std::max(mx, db[i]);
    if (mx - mn > 2.0 * p.flatness_dB) break;
    out.bandwidth_Hz = f[i];
  }
  return out;
}

BandwidthIdentResult identify_bandwidth(const TeleTweezParams& model_params, const BandwidthIdentParams& p) {
  p.validate();
  const double dt = 1.0 / p.fs_Hz;
  const TeleTweez model(model_params, dt);
  const auto n_total = static_cast<std::size_t>(std::llround(p.duration_s * p.fs_Hz));
  const auto n_settle = static_cast<std::size_t>(std::llround(p.settle_s * p.fs_Hz));
  const std::vector<double> u = dsp::prbs(p.prbs_bits, n_total, 1, p.torque_amplitude_N_m);
  Rng rng(static_cast<std::uint64_t>(p.seed));
  BandwidthIdentResult r;
  const std::size_t n = n_total - n_settle;
  r.t_s.reserve(n);
  r.torque_N_m.reserve(n);
  r.accel_m_s2.reserve(n);
  TeleTweezState s;
  Input in = Input::Zero();
  for (std::size_t k = 0; k < n_total; ++k) {
    in[kTorque] = u[k];
    // The DAQ samples the accelerometer at t_k, while u[k] is applied (ZOH) over [t_k, t_k+1).
    const double a = model.finger_acceleration(s, in) + p.accel_noise_m_s2 * rng.normal();
    if (k >= n_settle) {
      r.t_s.push_back(static_cast<double>(k) * dt);
      r.torque_N_m.push_back(u[k]);
      r.accel_m_s2.push_back(a);
    }
    model.step(s, in);
  }
  if (!std::all_of(r.accel_m_s2.begin(), r.accel_m_s2.end(), [](double v) { return std::isfinite(v); })) {
    throw ComputationFailed("bandwidth: the simulated acceleration diverged");
  }
  dsp::WelchOptions w;
  w.fs_Hz = p.fs_Hz;
  w.nperseg = static_cast<std::size_t>(p.nperseg);
  const dsp::FrfEstimate h = dsp::frf_h1(r.torque_N_m, r.accel_m_s2, w);
  // Drop DC (the PRBS mean is not an input the acceleration can follow).
  for (std::size_t i = 1; i < h.f_Hz.size(); ++i) {
    r.f_Hz.push_back(h.f_Hz[i]);
    r.magnitude.push_back(std::abs(h.h[i]));
    r.phase_rad.push_back(std::arg(h.h[i]));
    r.coherence.push_back(h.coherence[i]);
    r.model_magnitude.push_back(std::abs(model.finger_acceleration_frf(h.f_Hz[i])));
  }
  r.features = frf_features(r.f_Hz, r.magnitude, p);
  return r;
}

}  // namespace mc::tweezers
