#pragma once
/// @file
/// Evaluation of the dual-stage interface (thesis §3.5.1, Table 3.4, Fig. 3.13): sine-dwell
/// magnitude of the handle acceleration over K_sys times the force signal, at the 1/3-octave
/// centres, with the low channel alone, the high channel alone and both; plus the raw
/// Pantograph (gain-compensated, no crossover) for contrast. Also the replay of a recorded
/// force through the pipeline and the plant (§3.5.2).

#include <cstdint>
#include <span>
#include <vector>

#include "microcobot/haptics/dual_stage_plant.h"
#include "microcobot/haptics/render_pipeline.h"

namespace mc::haptics {

struct EvaluationOptions {
  double amplitude_N = 0.2;  ///< force signal amplitude of each dwell
  double noise_m_s2 = 0.05;  ///< accelerometer noise (std)
  double settle_s = 0.15;    ///< transient discarded before each measurement
  double measure_s = 0.2;    ///< measurement window (rounded to whole periods)
  std::uint64_t seed = 2;
};

struct EvaluationResult {
  std::vector<double> fc_Hz;
  std::vector<double> lf_dB;          ///< low channel alone (LP + C_LF -> Pantograph)
  std::vector<double> hf_dB;          ///< high channel alone (HP + C_HF -> Haptuator)
  std::vector<double> combined_dB;    ///< both
  std::vector<double> pantograph_dB;  ///< Pantograph alone with C_LF, no crossover
  double flatness_dB = 0.0;           ///< max - min of combined_dB
};

/// Which paths of the pipeline drive the plant.
enum class EvalMode { kLowOnly, kHighOnly, kBoth, kPantographOnly };

/// Sine-dwell gain |a_handle| / (K_sys |F|) at f (linear), with measurement noise, measured
/// by dsp::sine_dwell after `settle_s` over a whole number of periods.
double sine_dwell_gain(const DualStagePlant& plant, const RenderPipelineParams& rp, EvalMode mode,
                       double f_Hz, const EvaluationOptions& options, std::uint64_t seed);

/// Fig. 3.13 at the centres of Table 3.4.
EvaluationResult evaluate(const DualStagePlant& plant, const RenderPipelineParams& rp,
                          const EvaluationOptions& options);

/// Replays a force signal sampled at the loop rate (N) through the pipeline and the plant;
/// returns the accelerometer signal (m/s^2, with noise). Allocates the output only.
std::vector<double> replay(const DualStagePlant& plant, const RenderPipelineParams& rp,
                           std::span<const double> force_N, double noise_m_s2, std::uint64_t seed);

}  // namespace mc::haptics

namespace mc::haptics {

/// Distribution statistics of a signal (Fig. 3.15), from ident/stats: histogram over
/// mean +- 4 std as a density, the least-squares Gaussian fitted to it (ident::fit_gaussian)
/// and its R^2, and Pearson's kurtosis m4 / m2^2 (3 for a Gaussian).
struct GaussianStats {
  std::vector<double> bin_centre;
  std::vector<double> density;
  std::vector<double> gaussian;
  double mean = 0.0;
  double stddev = 0.0;
  double r2 = 0.0;
  double kurtosis = 0.0;
};
GaussianStats gaussian_stats(std::span<const double> x, int bins = 41);

}  // namespace mc::haptics
