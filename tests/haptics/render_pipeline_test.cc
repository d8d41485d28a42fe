#include "microcobot/haptics/render_pipeline.h"

#include <cmath>
#include <complex>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "microcobot/core/error.h"
#include "support/counting_allocator.h"

namespace mc::haptics {
// The file's own namespace: its helpers keep their names beside the other test files of the
// module in a unity build (MC_UNITY_TESTS).
namespace render_pipeline_test {
namespace {

double db(std::complex<double> z) { return 20.0 * std::log10(std::abs(z)); }

// Digital C_HF followed by the DAC's zero-order hold (sinc droop) equals eq. 3.8.
TEST(RenderPipeline, DigitalCompensatorFollowsEq38) {
  const RenderPipeline rp{RenderPipelineParams{}};
  for (double f = 63.0; f <= 1250.0; f *= 1.05) {
    const double x = std::numbers::pi * f / rp.params().fs_Hz;
    const double zoh = std::sin(x) / x;
    EXPECT_NEAR(db(rp.c_hf_response(f) * zoh) - db(rp.c_hf_analog(f)), 0.0, 0.05) << f;
  }
}

TEST(RenderPipeline, CompensatedHaptuatorModelIsFlatAtKsys) {
  const RenderPipelineParams p;
  const RenderPipeline rp{p};
  for (double f = 100.0; f <= 1250.0; f *= 1.05) {
    const double x = std::numbers::pi * f / p.fs_Hz;
    const double g = std::abs(rp.c_hf_response(f) * std::sin(x) / x * p.hf_model().response(f));
    EXPECT_NEAR(20 * std::log10(g / p.k_sys_m_s2_per_N), 0.0, 0.05) << f;
  }
}

TEST(RenderPipeline, ThesisFmaxOf1kHzCosts3dBAt1kHz) {
  RenderPipelineParams p;
  p.f_max_Hz = 1000.0;
  const RenderPipeline rp{p};
  const double g = std::abs(rp.c_hf_analog(1000.0) * p.hf_model().response(1000.0));
  EXPECT_NEAR(20 * std::log10(g / p.k_sys_m_s2_per_N), -3.0, 0.05);
}

TEST(RenderPipeline, CrossoverSumsToUnityMagnitudeAndSplitsAtCutoff) {
  const RenderPipeline rp{RenderPipelineParams{}};
  for (double f = 10.0; f <= 4000.0; f *= 1.1) {
    EXPECT_NEAR(std::abs(rp.lowpass_response(f) + rp.highpass_response(f)), 1.0, 1e-6) << f;
  }
  EXPECT_NEAR(db(rp.lowpass_response(200.0)), -6.02, 0.05);
  EXPECT_NEAR(db(rp.highpass_response(200.0)), -6.02, 0.05);
}

TEST(RenderPipeline, SteadyForceGoesToThePantographOnly) {
  RenderPipelineParams p;
  p.lf_gain_m_s2_per_N = 2.0;  // C_LF = K_sys / G_LF = 2
  RenderPipeline rp{p};
  RenderOutput out;
  for (int k = 0; k < 20000; ++k) out = rp.tick(0.5);
  EXPECT_NEAR(out.f_m_N, 1.0, 1e-6);
  EXPECT_NEAR(out.u_V, 0.0, 1e-6);
}

TEST(RenderPipeline, OutputsAreLimited) {
  RenderPipelineParams p;
  p.max_force_N = 0.5;
  p.max_voltage_V = 1.0;
  RenderPipeline rp{p};
  double fmax = 0, umax = 0;
  for (int k = 0; k < 5000; ++k) {
    const RenderOutput o = rp.tick(k % 2 ? 100.0 : -100.0);
    fmax = std::max(fmax, std::abs(o.f_m_N));
    umax = std::max(umax, std::abs(o.u_V));
  }
  EXPECT_LE(fmax, 0.5);
  EXPECT_LE(umax, 1.0);
  EXPECT_DOUBLE_EQ(umax, 1.0);
}

// The alignment delay shifts the high band by whole samples and leaves the low band alone.
TEST(RenderPipeline, HighBandDelayShiftsOnlyTheHaptuatorCommand) {
  RenderPipelineParams p;
  p.hf_delay_s = 0.0;
  RenderPipeline plain{p};
  p.hf_delay_s = 7.0e-4;  // 7 samples at 10 kHz
  RenderPipeline delayed{p};
  std::vector<RenderOutput> a, b;
  for (int k = 0; k < 400; ++k) {
    const double force = std::sin(0.07 * k) + (k == 3 ? 1.0 : 0.0);
    a.push_back(plain.tick(force));
    b.push_back(delayed.tick(force));
  }
  for (int k = 0; k < 400; ++k) {
    EXPECT_EQ(b[k].f_m_N, a[k].f_m_N) << k;
    EXPECT_EQ(b[k].u_V, k < 7 ? 0.0 : a[k - 7].u_V) << k;
  }
  // ... and reset() empties the delay line.
  delayed.reset();
  plain.reset();
  for (int k = 0; k < 7; ++k) EXPECT_EQ(delayed.tick(1.0).u_V, 0.0);
  EXPECT_NE(plain.tick(1.0).u_V, 0.0);
  // The compensator's response carries the delay's phase, not its magnitude.
  const double f = 500.0;
  EXPECT_NEAR(std::abs(delayed.c_hf_response(f)), std::abs(plain.c_hf_response(f)), 1e-12);
  EXPECT_NEAR(std::arg(delayed.c_hf_response(f) / plain.c_hf_response(f)),
              std::remainder(-2.0 * std::numbers::pi * f * 7.0e-4, 2.0 * std::numbers::pi), 1e-9);
}

TEST(RenderPipeline, TickDoesNotAllocate) {
  RenderPipeline rp{RenderPipelineParams{}};
  test::AllocationGuard guard;
  double acc = 0;
  for (int k = 0; k < 10000; ++k) acc += rp.tick(std::sin(0.01 * k)).u_V;
  EXPECT_EQ(guard.allocations(), 0u);
  EXPECT_TRUE(std::isfinite(acc));
}

TEST(RenderPipeline, RejectsBadParameters) {
  RenderPipelineParams p;
  p.cutoff_Hz = 6000.0;
  EXPECT_THROW(RenderPipeline{p}, InvalidParams);
  p = {};
  p.hf_num = {1.0};
  EXPECT_THROW(RenderPipeline{p}, InvalidParams);
  p = {};
  p.f_max_Hz = 100.0;
  EXPECT_THROW(RenderPipeline{p}, InvalidParams);
  p = {};
  p.hf_delay_s = -1e-4;
  EXPECT_THROW(RenderPipeline{p}, InvalidParams);
  p.hf_delay_s = (RenderPipelineParams::kMaxDelaySamples + 1) / p.fs_Hz;
  EXPECT_THROW(RenderPipeline{p}, InvalidParams);
  p.hf_delay_s = RenderPipelineParams::kMaxDelaySamples / p.fs_Hz;
  EXPECT_NO_THROW(RenderPipeline{p});
}

}  // namespace
}  // namespace render_pipeline_test
}  // namespace mc::haptics
