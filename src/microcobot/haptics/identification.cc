#include "microcobot/haptics/identification.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <numbers>

#include "microcobot/core/error.h"
#include "microcobot/core/rng.h"
#include "microcobot/dsp/octave.h"
#include "microcobot/dsp/signals.h"
#include "microcobot/dsp/welch.h"
#include "microcobot/ident/tf_fit.h"

namespace mc::haptics {

std::vector<double> table_3_4_centres_Hz() {
  // The bands labelled 63 Hz .. 1.25 kHz; an exact centre lies within 10^(+-1/20) of its label.
  const double half_band = std::pow(10.0, 1.0 / 20.0);
  return dsp::third_octave_centres(63.0 / half_band, 1250.0 * half_band);
}

ChannelFrf measure_frf(const DualStagePlant& plant, Channel channel, double amplitude,
                       const IdentificationOptions& o) {
  const std::size_t n = (std::size_t{1} << o.prbs_bits) - 1;
  const std::vector<double> u = dsp::prbs(o.prbs_bits, n, 1, amplitude);
  std::vector<double> y(n);
  DualStagePlantState s;
  Rng rng(o.seed + (channel == Channel::kPantograph ? 0 : 1));
  for (std::size_t k = 0; k < n; ++k) {
    const bool lf = channel == Channel::kPantograph;
    plant.step(s, lf ? u[k] : 0.0, lf ? 0.0 : u[k]);
    y[k] = s.accel_m_s2 + o.noise_m_s2 * rng.normal();
  }
  dsp::WelchOptions w;
  w.fs_Hz = 1.0 / plant.params().dt_s;
  w.nperseg = o.nperseg;
  const dsp::FrfEstimate e = dsp::frf_h1(u, y, w);
  ChannelFrf out;
  out.f_Hz = e.f_Hz;
  out.h = e.h;
  out.coherence = e.coherence;
  return out;
}

HfModel fit_second_order(const ChannelFrf& frf, double lo, double hi, double hold_s) {
  // Remove the known half-sample delay of the zero-order hold before fitting a rational model
  // (the SK start would otherwise absorb it as a right-half-plane zero).
  std::vector<std::complex<double>> h(frf.h.size());
  for (std::size_t i = 0; i < h.size(); ++i)
    h[i] = frf.h[i] * std::exp(std::complex<double>(0.0, -std::numbers::pi * frf.f_Hz[i] * hold_s));
  ident::TfFitOptions o;
  o.nz = 1;
  o.np = 2;
  o.fmin_Hz = lo;
  o.fmax_Hz = hi;
  // The channel's phase in the band also carries the magnet's suspension mode, which a
  // 2nd-order model cannot hold: as the thesis (PSD-based, Fig. 3.11) the model is refined on
  // the log-magnitude only.
  o.error = ident::TfFitError::kLogMagnitude;
  std::size_t in_band = 0;
  for (double f : frf.f_Hz) in_band += f >= lo && f <= hi ? 1 : 0;
  if (in_band < 8) throw ComputationFailed("HF fit: fewer than 8 FRF bins in the fit band");
  const ident::TfFitResult fit = ident::fit_tf(frf.f_Hz, h, o);
  const std::vector<double>& num = fit.tf.num();
  const std::vector<double>& den = fit.tf.den();  // monic
  if (num.size() != 2 || den.size() != 3) throw ComputationFailed("HF fit: the model lost its order");
  const HfModel m{num[0], num[1], den[1], den[2]};
  if (!(m.b1 > 0 && m.b0 > 0 && m.a1 > 0 && m.a0 > 0) || !std::isfinite(m.b1 + m.b0 + m.a1 + m.a0)) {
    throw ComputationFailed("HF fit: model is unstable or non-minimum-phase");
  }
  return m;
}

namespace {
// Magnitude smoothed over +-half bins (log domain): the band-edge tests see the response,
// not the scatter of single Welch bins.
std::vector<double> smoothed_db(const std::vector<std::complex<double>>& h, std::size_t half) {
  std::vector<double> out(h.size());
  for (std::size_t i = 0; i < h.size(); ++i) {
    const std::size_t a = i > half ? i - half : 0;
    const std::size_t b = std::min(h.size() - 1, i + half);
    double s = 0.0;
    for (std::size_t j = a; j <= b; ++j) s += 20.0 * std::log10(std::max(std::abs(h[j]), 1e-300));
    out[i] = s / static_cast<double>(b - a + 1);
  }
  return out;
}
}  // namespace

IdentificationResult identify(const DualStagePlant& plant, const IdentificationOptions& o) {
  IdentificationResult r;
  r.lf = measure_frf(plant, Channel::kPantograph, o.lf_amplitude_N, o);
  r.hf = measure_frf(plant, Channel::kHaptuator, o.hf_amplitude_V, o);
  // LF static gain (eq. 3.5): mean magnitude over the reference band.
  double sum = 0.0;
  int cnt = 0;
  for (std::size_t i = 0; i < r.lf.f_Hz.size(); ++i) {
    if (r.lf.f_Hz[i] >= o.lf_ref_lo_Hz && r.lf.f_Hz[i] <= o.lf_ref_hi_Hz) {
      sum += std::abs(r.lf.h[i]);
      ++cnt;
    }
  }
  if (cnt == 0) throw ComputationFailed("LF identification: empty reference band");
  r.lf_gain = sum / cnt;
  const double tol_db = o.flat_tol_dB;
  const std::vector<double> lf_db = smoothed_db(r.lf.h, 4);
  const std::vector<double> hf_db = smoothed_db(r.hf.h, 4);
  const double lf_gain_db = 20.0 * std::log10(r.lf_gain);
  // LF flat band: from the reference band upward until the first bin outside tolerance.
  r.lf_flat_upper_Hz = o.lf_ref_hi_Hz;
  for (std::size_t i = 0; i < r.lf.f_Hz.size(); ++i) {
    if (r.lf.f_Hz[i] < o.lf_ref_lo_Hz) continue;
    if (std::abs(lf_db[i] - lf_gain_db) > tol_db) break;
    r.lf_flat_upper_Hz = r.lf.f_Hz[i];
  }
  // HF model and the lower edge of its validity (downward from the fit band's top).
  r.hf_model = fit_second_order(r.hf, o.fit_lo_Hz, o.fit_hi_Hz, plant.params().dt_s);
  r.hf_valid_lower_Hz = o.fit_hi_Hz;
  for (std::size_t i = r.hf.f_Hz.size(); i-- > 0;) {
    if (r.hf.f_Hz[i] > o.fit_hi_Hz) continue;
    const double model_db = 20.0 * std::log10(std::abs(r.hf_model.response(r.hf.f_Hz[i])));
    if (std::abs(hf_db[i] - model_db) > tol_db) break;
    r.hf_valid_lower_Hz = r.hf.f_Hz[i];
  }
  if (r.hf_valid_lower_Hz >= r.lf_flat_upper_Hz) {
    throw ComputationFailed("identification: the channels do not overlap (HF valid from " +
                            std::to_string(r.hf_valid_lower_Hz) + " Hz, LF flat to " +
                            std::to_string(r.lf_flat_upper_Hz) + " Hz)");
  }
  // Cut-off (§3.3.2): as high as the Pantograph allows inside the overlap, on the 1/3-octave grid.
  r.cutoff_Hz = 0.0;
  for (double fc : table_3_4_centres_Hz()) {
    if (fc <= r.lf_flat_upper_Hz && fc >= r.hf_valid_lower_Hz) r.cutoff_Hz = dsp::third_octave_nominal(fc);
  }
  if (r.cutoff_Hz == 0.0) r.cutoff_Hz = r.lf_flat_upper_Hz;
  RenderPipelineParams at_plant_rate;
  at_plant_rate.fs_Hz = 1.0 / plant.params().dt_s;
  r.hf_delay_s = choose_hf_delay_s(r, at_plant_rate);
  return r;
}

namespace {

// The measured FRF at f: the complex mean of the five Welch bins nearest to f (less scatter
// than one bin; the responses barely turn over 5 bins of 2.4 Hz).
std::complex<double> frf_near(const ChannelFrf& frf, double f_Hz) {
  const auto it = std::lower_bound(frf.f_Hz.begin(), frf.f_Hz.end(), f_Hz);
  const auto i = static_cast<std::size_t>(std::distance(frf.f_Hz.begin(), it));
  const std::size_t a = i > 2 ? i - 2 : 0;
  const std::size_t b = std::min(frf.f_Hz.size(), a + 5);
  std::complex<double> sum = 0.0;
  for (std::size_t j = a; j < b; ++j) sum += frf.h[j];
  return sum / static_cast<double>(b - a);
}

RenderPipelineParams with_models(const IdentificationResult& id, RenderPipelineParams base) {
  base.cutoff_Hz = id.cutoff_Hz;
  base.lf_gain_m_s2_per_N = id.lf_gain;
  base.hf_num = {id.hf_model.b1, id.hf_model.b0};
  base.hf_den = {1.0, id.hf_model.a1, id.hf_model.a0};
  return base;
}

}  // namespace

double choose_hf_delay_s(const IdentificationResult& id, RenderPipelineParams base) {
  for (const ChannelFrf* c : {&id.lf, &id.hf}) {
    if (c->f_Hz.empty() || c->h.size() != c->f_Hz.size())
      throw ComputationFailed(
          "high-band delay: a measured FRF is empty or its bins and values differ in count");
  }
  base = with_models(id, base);
  base.hf_delay_s = 0.0;
  const RenderPipeline pipe(base);
  // Each path's response without the delay, predicted from the measured FRFs.
  std::vector<double> f = table_3_4_centres_Hz();
  std::vector<std::complex<double>> low(f.size()), high(f.size());
  for (std::size_t i = 0; i < f.size(); ++i) {
    low[i] = pipe.lowpass_response(f[i]) * pipe.c_lf() * frf_near(id.lf, f[i]);
    high[i] = pipe.highpass_response(f[i]) * pipe.c_hf_response(f[i]) * frf_near(id.hf, f[i]);
  }
  int best = 0;
  double best_spread = std::numeric_limits<double>::infinity();
  for (int n = 0; n <= RenderPipelineParams::kMaxDelaySamples; ++n) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (std::size_t i = 0; i < f.size(); ++i) {
      const double w = 2.0 * std::numbers::pi * f[i] / base.fs_Hz;
      const double g = std::abs(low[i] + high[i] * std::exp(std::complex<double>(0.0, -w * n)));
      const double v = 20.0 * std::log10(std::max(g / base.k_sys_m_s2_per_N, 1e-300));
      lo = std::min(lo, v), hi = std::max(hi, v);
    }
    if (hi - lo < best_spread) best_spread = hi - lo, best = n;
  }
  return best / base.fs_Hz;
}

RenderPipelineParams pipeline_from(const IdentificationResult& id, RenderPipelineParams base) {
  base = with_models(id, base);
  // The delay was chosen at the plant's rate; the same time rounds to whole samples at base's.
  base.hf_delay_s = id.hf_delay_s;
  base.validate();
  return base;
}

}  // namespace mc::haptics
