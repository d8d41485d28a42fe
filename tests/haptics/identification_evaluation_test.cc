#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "microcobot/core/error.h"
#include "microcobot/core/rng.h"
#include "microcobot/haptics/evaluation.h"
#include "microcobot/haptics/identification.h"

namespace mc::haptics {
namespace {

const IdentificationResult& identified() {
  static const IdentificationResult id = [] {
    const DualStagePlant plant{DualStagePlantParams{}};
    return identify(plant, IdentificationOptions{});
  }();
  return id;
}

TEST(Identification, FindsTheStaticGainTheModelAndThe200HzCutoff) {
  const DualStagePlant plant{DualStagePlantParams{}};
  const IdentificationResult& id = identified();
  EXPECT_NEAR(id.lf_gain * plant.total_mass_kg(), 1.0, 0.05);  // mass line 1/M
  EXPECT_GT(id.lf_flat_upper_Hz, 200.0);
  EXPECT_LT(id.lf_flat_upper_Hz, 230.0);
  EXPECT_LT(id.hf_valid_lower_Hz, 120.0);  // saturation spoils only the low band
  EXPECT_DOUBLE_EQ(id.cutoff_Hz, 200.0);
  // The identified (not the true) model follows the true channel within 0.3 dB on 150-1000 Hz.
  for (double f = 150.0; f <= 1000.0; f *= 1.05) {
    EXPECT_NEAR(
        20 * std::log10(std::abs(id.hf_model.response(f)) / std::abs(plant.frf(Channel::kHaptuator, f))), 0.0,
        0.3)
        << f;
  }
}

TEST(Identification, NoOverlapIsReported) {
  // With a 0.02 dB flatness demand neither channel is "uniform" over a common band.
  const DualStagePlant plant{DualStagePlantParams{}};
  IdentificationOptions o;
  o.flat_tol_dB = 0.02;
  o.prbs_bits = 14;
  o.nperseg = 1024;
  EXPECT_THROW(identify(plant, o), ComputationFailed);
}

TEST(Evaluation, CombinedResponseIsFlatAndThePantographAloneIsNot) {
  const DualStagePlant plant{DualStagePlantParams{}};
  const EvaluationResult ev = evaluate(plant, pipeline_from(identified()), EvaluationOptions{});
  ASSERT_EQ(ev.fc_Hz.size(), 14u);
  // Goal: within +-0.5 dB over 63-1250 Hz.
  for (double v : ev.combined_dB) EXPECT_LT(std::abs(v), 0.5);
  // Complementary channels: LF dominates below the cut-off, HF above.
  EXPECT_GT(ev.lf_dB.front(), ev.hf_dB.front() + 20.0);
  EXPECT_GT(ev.hf_dB.back(), ev.lf_dB.back() + 20.0);
  double dev = 0.0;
  for (std::size_t i = 0; i < ev.fc_Hz.size(); ++i)
    if (ev.fc_Hz[i] > 250.0) dev = std::max(dev, std::abs(ev.pantograph_dB[i]));
  EXPECT_GT(dev, 6.0);
}

// The high band leads the low band at the cut-off (Haptuator phase that eq. 3.6 cannot hold,
// Pantograph lag before its antiresonance): without the alignment delay the halves miss the
// goal at the cut-off; the delay chosen from the measured FRFs brings the sum back.
TEST(Evaluation, AlignmentDelayChosenFromTheMeasurementsFlattensTheCutoff) {
  const DualStagePlant plant{DualStagePlantParams{}};
  const IdentificationResult& id = identified();
  EXPECT_GT(id.hf_delay_s, 1.5e-4);
  EXPECT_LT(id.hf_delay_s, 1.0e-3);
  RenderPipelineParams unaligned = pipeline_from(id);
  unaligned.hf_delay_s = 0.0;
  const EvaluationResult raw = evaluate(plant, unaligned, EvaluationOptions{});
  const EvaluationResult aligned = evaluate(plant, pipeline_from(id), EvaluationOptions{});
  const std::size_t at_cutoff = 5;  // 199.5 Hz
  ASSERT_NEAR(raw.fc_Hz[at_cutoff], 199.5, 0.1);
  EXPECT_LT(raw.combined_dB[at_cutoff], -0.5);
  EXPECT_GT(aligned.combined_dB[at_cutoff], raw.combined_dB[at_cutoff] + 0.3);
  EXPECT_LT(aligned.flatness_dB, raw.flatness_dB);
}

TEST(Evaluation, AlignmentDelayNeedsMeasuredResponses) {
  IdentificationResult empty = identified();
  empty.hf = {};
  EXPECT_THROW(choose_hf_delay_s(empty, RenderPipelineParams{}), ComputationFailed);
}

TEST(GaussianStats, GaussianSamplesFitAndUniformOnesDoNot) {
  Rng rng(5);
  std::vector<double> gauss(20000), uniform(20000);
  for (double& v : gauss) v = 0.3 + 2.0 * rng.normal();
  for (double& v : uniform) v = rng.uniform();
  const GaussianStats g = gaussian_stats(gauss);
  EXPECT_NEAR(g.mean, 0.3, 0.05);
  EXPECT_NEAR(g.stddev, 2.0, 0.05);
  EXPECT_NEAR(g.kurtosis, 3.0, 0.15);  // Pearson's, 3 for a Gaussian
  EXPECT_GT(g.r2, 0.99);
  ASSERT_EQ(g.density.size(), 41u);
  // The histogram is a density: it integrates to ~1 over mean +- 4 std.
  double area = 0.0;
  for (double d : g.density) area += d * (g.bin_centre[1] - g.bin_centre[0]);
  EXPECT_NEAR(area, 1.0, 1e-3);
  const GaussianStats u = gaussian_stats(uniform);
  EXPECT_NEAR(u.kurtosis, 1.8, 0.05);  // 9/5 for a uniform distribution
  EXPECT_LT(u.r2, 0.9);
  EXPECT_THROW(gaussian_stats(std::vector<double>(50, 1.0)), ComputationFailed);
  EXPECT_THROW(gaussian_stats(std::vector<double>(500, 1.0)), ComputationFailed);  // zero variance
}

}  // namespace
}  // namespace mc::haptics
