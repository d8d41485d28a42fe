#include "microcobot/haptics/evaluation.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>

#include "microcobot/core/error.h"
#include "microcobot/core/rng.h"
#include "microcobot/dsp/sine_dwell.h"
#include "microcobot/haptics/identification.h"
#include "microcobot/ident/stats.h"

namespace mc::haptics {

double sine_dwell_gain(const DualStagePlant& plant, const RenderPipelineParams& rp, EvalMode mode, double f,
                       const EvaluationOptions& o, std::uint64_t seed) {
  RenderPipeline pipe(rp);
  DualStagePlantState s;
  Rng rng(seed);
  const double dt = plant.params().dt_s;
  const auto settle = static_cast<std::size_t>(std::ceil(o.settle_s / dt));
  const double periods = std::max(1.0, std::round(o.measure_s * f));
  const auto n = static_cast<std::size_t>(std::round(periods / f / dt));
  const double c_lf = rp.k_sys_m_s2_per_N / rp.lf_gain_m_s2_per_N;
  // Only the magnitude is kept: the accelerometer's read at the end of each held sample (one
  // sample after the command) shifts the phase, not |Y/F|.
  std::vector<double> force(settle + n), y(settle + n);
  for (std::size_t k = 0; k < settle + n; ++k) {
    const double cmd = o.amplitude_N * std::sin(2.0 * std::numbers::pi * f * static_cast<double>(k) * dt);
    const RenderOutput out = pipe.tick(cmd);
    double fm = 0.0, u = 0.0;
    switch (mode) {
      case EvalMode::kLowOnly:
        fm = out.f_m_N;
        break;
      case EvalMode::kHighOnly:
        u = out.u_V;
        break;
      case EvalMode::kBoth:
        fm = out.f_m_N;
        u = out.u_V;
        break;
      case EvalMode::kPantographOnly:
        fm = std::clamp(c_lf * cmd, -rp.max_force_N, rp.max_force_N);
        break;
    }
    plant.step(s, fm, u);
    force[k] = cmd;
    y[k] = s.accel_m_s2 + o.noise_m_s2 * rng.normal();
  }
  const double g = dsp::sine_dwell(force, y, f, 1.0 / dt, settle).magnitude / rp.k_sys_m_s2_per_N;
  if (!std::isfinite(g)) throw ComputationFailed("sine dwell: non-finite gain");
  return g;
}

EvaluationResult evaluate(const DualStagePlant& plant, const RenderPipelineParams& rp,
                          const EvaluationOptions& o) {
  EvaluationResult r;
  r.fc_Hz = table_3_4_centres_Hz();
  std::uint64_t seed = o.seed;
  auto db = [](double g) { return 20.0 * std::log10(std::max(g, 1e-12)); };
  for (double f : r.fc_Hz) {
    r.lf_dB.push_back(db(sine_dwell_gain(plant, rp, EvalMode::kLowOnly, f, o, seed++)));
    r.hf_dB.push_back(db(sine_dwell_gain(plant, rp, EvalMode::kHighOnly, f, o, seed++)));
    r.combined_dB.push_back(db(sine_dwell_gain(plant, rp, EvalMode::kBoth, f, o, seed++)));
    r.pantograph_dB.push_back(db(sine_dwell_gain(plant, rp, EvalMode::kPantographOnly, f, o, seed++)));
  }
  const auto [mn, mx] = std::minmax_element(r.combined_dB.begin(), r.combined_dB.end());
  r.flatness_dB = *mx - *mn;
  return r;
}

std::vector<double> replay(const DualStagePlant& plant, const RenderPipelineParams& rp,
                           std::span<const double> force_N, double noise, std::uint64_t seed) {
  RenderPipeline pipe(rp);
  DualStagePlantState s;
  Rng rng(seed);
  std::vector<double> a(force_N.size());
  for (std::size_t k = 0; k < force_N.size(); ++k) {
    const RenderOutput out = pipe.tick(force_N[k]);
    plant.step(s, out.f_m_N, out.u_V);
    a[k] = s.accel_m_s2 + noise * rng.normal();
  }
  return a;
}

}  // namespace mc::haptics

namespace mc::haptics {

GaussianStats gaussian_stats(std::span<const double> x, int bins) {
  if (x.size() < 100 || bins < 5) throw ComputationFailed("gaussian_stats: too few samples");
  GaussianStats g;
  g.mean = ident::mean(x);
  g.stddev = ident::stddev(x);
  if (!(g.stddev > 0.0)) throw ComputationFailed("gaussian_stats: zero variance");
  g.kurtosis = ident::kurtosis(x) + 3.0;  // Pearson's m4 / m2^2
  const ident::Histogram h =
      ident::histogram(x, static_cast<std::size_t>(bins), g.mean - 4.0 * g.stddev, g.mean + 4.0 * g.stddev);
  const ident::GaussianFit fit = ident::fit_gaussian(h.centres, h.counts);
  const double to_density = 1.0 / (static_cast<double>(x.size()) * h.width);
  g.bin_centre = h.centres;
  for (std::size_t b = 0; b < h.centres.size(); ++b) {
    const double z = (h.centres[b] - fit.mean) / fit.sigma;
    g.density.push_back(h.counts[b] * to_density);
    g.gaussian.push_back(fit.amplitude * std::exp(-0.5 * z * z) * to_density);
  }
  g.r2 = fit.r2;
  return g;
}

}  // namespace mc::haptics
