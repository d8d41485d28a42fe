#include "microcobot/haptics/dual_stage_plant.h"

#include <cmath>
#include <complex>
#include <numbers>

#include <gtest/gtest.h>

#include "microcobot/core/error.h"
#include "support/counting_allocator.h"

namespace mc::haptics {
namespace {

double db(std::complex<double> z) { return 20.0 * std::log10(std::abs(z)); }

std::complex<double> eq36(double f) {
  const std::complex<double> s(0.0, 2.0 * std::numbers::pi * f);
  return (250.0 * s + 6.406e5) / (s * s + 2135.0 * s + 4.559e6);
}

TEST(DualStagePlant, PantographChannelIsFlatTo200HzThenLeavesTheBand) {
  const DualStagePlant plant{DualStagePlantParams{}};
  const double ref = db(plant.frf(Channel::kPantograph, 80.0));
  // Mass line: 1/M_total above the finger mode.
  EXPECT_NEAR(std::abs(plant.frf(Channel::kPantograph, 80.0)) * plant.total_mass_kg(), 1.0, 0.1);
  for (double f = 40.0; f <= 200.0; f *= 1.02) {
    EXPECT_LT(std::abs(db(plant.frf(Channel::kPantograph, f)) - ref), 1.0) << f;
  }
  // Just above 200 Hz it is no longer flat, and well above it deviates by > 6 dB.
  EXPECT_GT(std::abs(db(plant.frf(Channel::kPantograph, 230.0)) - ref), 1.0);
  double worst = 0.0;
  for (double f = 250.0; f <= 1250.0; f *= 1.02)
    worst = std::max(worst, std::abs(db(plant.frf(Channel::kPantograph, f)) - ref));
  EXPECT_GT(worst, 6.0);
}

TEST(DualStagePlant, PantographChannelHasASharpResonanceNear800Hz) {
  const DualStagePlant plant{DualStagePlantParams{}};
  double fpk = 0.0, pk = -1e9;
  for (double f = 600.0; f <= 1000.0; f += 1.0) {
    const double v = db(plant.frf(Channel::kPantograph, f));
    if (v > pk) pk = v, fpk = f;
  }
  EXPECT_NEAR(fpk, 800.0, 40.0);
  // Sharp: at +-8 % of the peak frequency the response is already > 8 dB lower.
  EXPECT_GT(pk - db(plant.frf(Channel::kPantograph, 0.92 * fpk)), 8.0);
  EXPECT_GT(pk - db(plant.frf(Channel::kPantograph, 1.08 * fpk)), 8.0);
}

TEST(DualStagePlant, HaptuatorChannelMatchesEq36On100To1000Hz) {
  const DualStagePlant plant{DualStagePlantParams{}};
  for (double f = 100.0; f <= 1000.0; f *= 1.02) {
    EXPECT_LT(std::abs(db(plant.frf(Channel::kHaptuator, f)) - db(eq36(f))), 1.0) << f;
  }
  // ... and it cannot render static forces: far below its band it vanishes.
  EXPECT_LT(db(plant.frf(Channel::kHaptuator, 5.0)) - db(eq36(5.0)), -20.0);
}

// Steady-state sine response of step() equals the analytic FRF (stops open).
TEST(DualStagePlant, StepMatchesFrequencyResponse) {
  const DualStagePlant plant{DualStagePlantParams{}};
  for (const auto& [channel, f, amp] :
       {std::tuple{Channel::kPantograph, 150.0, 0.5}, std::tuple{Channel::kHaptuator, 400.0, 2.0}}) {
    DualStagePlantState s;
    const double dt = plant.params().dt_s;
    const int settle = 4000, n = 2000;  // n * dt = 0.2 s: an integer number of periods
    std::complex<double> acc = 0.0;
    for (int k = 0; k < settle + n; ++k) {
      // ZOH input held over [k dt, (k+1) dt): compare against the output at t = (k+1) dt.
      const double u = amp * std::sin(2 * std::numbers::pi * f * k * dt);
      plant.step(s, channel == Channel::kPantograph ? u : 0.0, channel == Channel::kHaptuator ? u : 0.0);
      if (k >= settle) {
        acc += s.accel_m_s2 * std::exp(std::complex<double>(0, -2 * std::numbers::pi * f * (k + 1) * dt));
      }
    }
    const double measured = 2.0 * std::abs(acc) / n / amp;
    // The ZOH adds a sinc(f dt) droop and half a sample of delay; at <= 400 Hz it is < 0.3 %.
    const double expected = std::abs(plant.frf(channel, f));
    EXPECT_NEAR(measured / expected, 1.0, 0.01) << f;
  }
}

TEST(DualStagePlant, StrokeSaturationSpoilsTheLowBandOnly) {
  const DualStagePlant plant{DualStagePlantParams{}};
  auto gain = [&](double f, double amp, double* travel) {
    DualStagePlantState s;
    const double dt = plant.params().dt_s;
    const int n = static_cast<int>(std::round(20.0 / f / dt));  // 20 periods
    std::complex<double> acc = 0.0;
    *travel = 0.0;
    for (int k = 0; k < 2 * n; ++k) {
      plant.step(s, 0.0, amp * std::sin(2 * std::numbers::pi * f * k * dt));
      *travel = std::max(*travel, std::abs(DualStagePlant::magnet_travel(s)));
      if (k >= n)
        acc += s.accel_m_s2 * std::exp(std::complex<double>(0, -2 * std::numbers::pi * f * (k + 1) * dt));
    }
    return 2.0 * std::abs(acc) / n / amp;
  };
  double travel = 0.0;
  const double amp = 15.0;
  // 40 Hz: the magnet hits its stops and the response departs from the linear model.
  const double g40 = gain(40.0, amp, &travel);
  EXPECT_GT(travel, plant.params().stroke_m);
  EXPECT_GT(std::abs(db(g40) - db(plant.frf(Channel::kHaptuator, 40.0))), 1.0);
  // 400 Hz: same drive, free travel, linear.
  const double g400 = gain(400.0, amp, &travel);
  EXPECT_LT(travel, plant.params().stroke_m);
  EXPECT_NEAR(g400 / std::abs(plant.frf(Channel::kHaptuator, 400.0)), 1.0, 0.01);
}

TEST(DualStagePlant, StepDoesNotAllocate) {
  const DualStagePlant plant{DualStagePlantParams{}};
  DualStagePlantState s;
  test::AllocationGuard guard;
  for (int k = 0; k < 1000; ++k) plant.step(s, 0.1 * std::sin(k * 0.01), 1.0);
  EXPECT_EQ(guard.allocations(), 0u);
}

TEST(DualStagePlant, RejectsInvalidParamsAndDivergence) {
  DualStagePlantParams p;
  p.m_h_kg = 0.0;
  EXPECT_THROW(DualStagePlant{p}, InvalidParams);
  p = {};
  p.stop_k_N_per_m = 1e12;
  EXPECT_THROW(DualStagePlant{p}, InvalidParams);
  const DualStagePlant plant{DualStagePlantParams{}};
  DualStagePlantState s;
  EXPECT_THROW(plant.step(s, 1e12, 0.0), ComputationFailed);
}

}  // namespace
}  // namespace mc::haptics
