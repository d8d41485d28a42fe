#include "microcobot/haptics/evaluation.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>

#include "microcobot/core/error.h"
#include "microcobot/core/rng.h"
#include "microcobot/haptics/identification.h"

namespace mc::haptics {

double sine_dwell_gain(const DualStagePlant& plant, const RenderPipelineParams& rp, EvalMode mode, double f,
                       const EvaluationOptions& o, std::uint64_t seed) {
  RenderPipeline pipe(rp);
  DualStagePlantState s;
  Rng rng(seed);
  const double dt = plant.params().dt_s;
  const auto settle = static_cast<long>(std::ceil(o.settle_s / dt));
  const double periods = std::max(1.0, std::round(o.measure_s * f));
  const auto n = static_cast<long>(std::round(periods / f / dt));
  const double c_lf = rp.k_sys_m_s2_per_N / rp.lf_gain_m_s2_per_N;
  std::complex<double> acc = 0.0;
  for (long k = 0; k < settle + n; ++k) {
    const double force = o.amplitude_N * std::sin(2.0 * std::numbers::pi * f * k * dt);
    const RenderOutput out = pipe.tick(force);
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
        fm = std::clamp(c_lf * force, -rp.max_force_N, rp.max_force_N);
        break;
    }
    plant.step(s, fm, u);
    if (k >= settle) {
      const double y = s.accel_m_s2 + o.noise_m_s2 * rng.normal();
      acc += y * std::exp(std::complex<double>(0.0, -2.0 * std::numbers::pi * f * (k + 1) * dt));
    }
  }
  const double amp = 2.0 * std::abs(acc) / static_cast<double>(n);
  const double g = amp / (rp.k_sys_m_s2_per_N * o.amplitude_N);
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
  const double n = static_cast<double>(x.size());
  for (double v : x) g.mean += v;
  g.mean /= n;
  double m2 = 0.0, m4 = 0.0;
  for (double v : x) {
    const double d = (v - g.mean) * (v - g.mean);
    m2 += d;
    m4 += d * d;
  }
  m2 /= n;
  m4 /= n;
  if (!(m2 > 0.0)) throw ComputationFailed("gaussian_stats: zero variance");
  g.stddev = std::sqrt(m2);
  g.kurtosis = m4 / (m2 * m2);
  const double lo = g.mean - 4.0 * g.stddev, width = 8.0 * g.stddev / bins;
  std::vector<double> count(static_cast<std::size_t>(bins), 0.0);
  for (double v : x) {
    const auto b = static_cast<long>(std::floor((v - lo) / width));
    if (b >= 0 && b < bins) count[static_cast<std::size_t>(b)] += 1.0;
  }
  double ss_res = 0.0, ss_tot = 0.0, mean_d = 0.0;
  for (int b = 0; b < bins; ++b) {
    const double c = lo + (b + 0.5) * width;
    const double z = (c - g.mean) / g.stddev;
    g.bin_centre.push_back(c);
    g.density.push_back(count[static_cast<std::size_t>(b)] / (n * width));
    g.gaussian.push_back(std::exp(-0.5 * z * z) / (g.stddev * std::sqrt(2.0 * std::numbers::pi)));
    mean_d += g.density.back();
  }
  mean_d /= bins;
  for (int b = 0; b < bins; ++b) {
    const auto i = static_cast<std::size_t>(b);
    ss_res += (g.density[i] - g.gaussian[i]) * (g.density[i] - g.gaussian[i]);
    ss_tot += (g.density[i] - mean_d) * (g.density[i] - mean_d);
  }
  g.r2 = 1.0 - ss_res / ss_tot;
  return g;
}

}  // namespace mc::haptics
