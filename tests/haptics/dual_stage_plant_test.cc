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

// Local extremum of |G_LF| in dB on a 1 Hz grid over [lo, hi]: the lowest (sign +1) or highest
// (sign -1) point, required to be a true local extremum (its neighbours on both sides are higher/lower).
struct Extremum {
  double f_Hz = 0.0;
  double dB = 0.0;
  bool local = false;
};
Extremum extremum(const DualStagePlant& plant, double lo, double hi, double sign) {
  Extremum e{lo, sign * 1e9, false};
  for (double f = lo; f <= hi; f += 1.0) {
    const double v = db(plant.frf(Channel::kPantograph, f));
    if (sign * v < sign * e.dB) e = {f, v, false};
  }
  const double left = db(plant.frf(Channel::kPantograph, e.f_Hz - 1.0));
  const double right = db(plant.frf(Channel::kPantograph, e.f_Hz + 1.0));
  e.local = e.f_Hz > lo && e.f_Hz < hi && sign * left > sign * e.dB && sign * right > sign * e.dB;
  return e;
}

// Fig. 3.10: "a first, nicely damped antiresonance slightly after 200 Hz accompanied by a damped
// resonance at 300 Hz. Another resonance-antiresonance pair around 800 Hz, with a sharp peak".
TEST(DualStagePlant, PantographChannelHasTheFig310AntiresonancesAndResonances) {
  const DualStagePlant plant{DualStagePlantParams{}};
  double lo = 1e9, hi = -1e9, ref = 0.0;
  int n = 0;
  for (double f = 40.0; f <= 120.0; f += 1.0, ++n) ref += std::abs(plant.frf(Channel::kPantograph, f));
  ref = 20.0 * std::log10(ref / n);
  for (double f = 40.0; f <= 200.0; f += 1.0) {
    const double v = db(plant.frf(Channel::kPantograph, f)) - ref;
    lo = std::min(lo, v), hi = std::max(hi, v);
  }
  EXPECT_LT(hi, 1.0);
  EXPECT_GT(lo, -1.0);
  // Damped antiresonance just above 200 Hz, then a damped resonance near 300 Hz.
  const Extremum anti = extremum(plant, 200.0, 260.0, +1.0);
  const Extremum res = extremum(plant, 260.0, 340.0, -1.0);
  EXPECT_TRUE(anti.local) << anti.f_Hz;
  EXPECT_TRUE(res.local) << res.f_Hz;
  EXPECT_GT(res.dB - anti.dB, 1.5);
  // Damped: the dip is shallow (a few dB below the band), not a notch.
  EXPECT_GT(anti.dB - ref, -6.0);
  // Near 800 Hz an antiresonance followed by a sharp resonance.
  const Extremum res8 = extremum(plant, 700.0, 900.0, -1.0);
  const Extremum anti8 = extremum(plant, 700.0, res8.f_Hz, +1.0);
  EXPECT_TRUE(res8.local) << res8.f_Hz;
  EXPECT_TRUE(anti8.local) << anti8.f_Hz;
  EXPECT_LT(anti8.f_Hz, res8.f_Hz);
  EXPECT_GT(res8.dB - anti8.dB, 15.0);
  EXPECT_GT(res8.dB - db(plant.frf(Channel::kPantograph, 0.92 * res8.f_Hz)), 8.0);
}

// Without the two linkage modes the plant is eq. 3.4 as printed: no antiresonance on the
// Pantograph path besides the magnet's, so no local minimum between 150 and 1250 Hz.
TEST(DualStagePlant, Eq34AsPrintedHasNoLinkageAntiresonance) {
  DualStagePlantParams p;
  p.m_p_kg = 0.0;
  p.m_d_kg = 0.0;
  const DualStagePlant plant{p};
  double prev = db(plant.frf(Channel::kPantograph, 150.0)), prev2 = prev;
  for (double f = 151.0; f <= 1250.0; f += 1.0) {
    const double v = db(plant.frf(Channel::kPantograph, f));
    EXPECT_FALSE(prev < prev2 && prev < v) << f - 1.0;
    prev2 = prev, prev = v;
  }
  // ... and the total mass is eq. 3.4's four masses.
  EXPECT_DOUBLE_EQ(plant.total_mass_kg(), p.m_h_kg + p.m_v_kg + p.m_1_kg + p.m_2_kg);
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
  p = {};
  p.k_p_N_per_m = 0.0;  // a linkage mode needs its spring
  EXPECT_THROW(DualStagePlant{p}, InvalidParams);
  p = {};
  p.b_d_Ns_per_m = -1.0;
  EXPECT_THROW(DualStagePlant{p}, InvalidParams);
  const DualStagePlant plant{DualStagePlantParams{}};
  DualStagePlantState s;
  EXPECT_THROW(plant.step(s, 1e12, 0.0), ComputationFailed);
}

}  // namespace
}  // namespace mc::haptics
