// Identification step 2 (thesis §2.5.2.2): the PI hysteresis of another axis from a simulated
// sine response with sensor effects, its inverse, and the bad-input contracts.
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "ident_truth.h"
#include "microcobot/core/error.h"
#include "microcobot/stickslip/ident_hysteresis.h"

namespace mc::stickslip {
namespace {

MeasuredRecord sine_record(const ActuatorModel& m, double amplitude, double periods, std::uint64_t seed) {
  const auto w = make_waveform(WaveKind::kSine, amplitude, 50, Direction::kForward, m.params().drive);
  SensorEffects s;
  s.seed = seed;
  return measure(m, w, periods / 50.0, 25e3, s);
}

TEST(IdentHysteresis, RecoversTheLoopOfAnotherAxisWithinTwoPercentOfTheStroke) {
  const StickSlipParams truth = test::ident_truth_params();
  const ActuatorModel m(truth);
  const MeasuredRecord rec = sine_record(m, 40, 2, 21);
  // Step 1's dynamics (here the truth's PE and asperities) keep the slider's lag out of the PI.
  const HysteresisResult r = identify_hysteresis(rec, 35, &truth);
  ASSERT_EQ(r.pi.size(), 35u);
  // Non-uniform partition: the gaps between thresholds grow.
  for (std::size_t i = 2; i < r.pi.size(); ++i) {
    EXPECT_GT(r.pi.thresholds_V[i] - r.pi.thresholds_V[i - 1],
              r.pi.thresholds_V[i - 1] - r.pi.thresholds_V[i - 2]);
  }
  for (double w : r.pi.weights) EXPECT_GE(w, 0.0);
  EXPECT_LT(r.rms_fraction, 0.02);
  // The identified static model reproduces the truth's loop amplitude g H(40 V).
  const double truth_top = truth.pe.static_gain_m_V * pi_loading_curve(truth.hysteresis, 40.0);
  EXPECT_NEAR(r.static_gain_m_V * pi_loading_curve(r.pi, 40.0) / truth_top, 1.0, 0.03);
  // Simulating the axis with the identified PI and g (all else the truth's) reproduces the measured
  // loop: RMS error below 2% of the stroke on the second period.
  StickSlipParams id = truth;
  id.hysteresis = r.pi;
  id.pe.static_gain_m_V = r.static_gain_m_V;
  const ActuatorModel mi(id);
  SensorEffects clean{0.0, 0.0, 0.0, 1};
  const auto w = make_waveform(WaveKind::kSine, 40, 50, Direction::kForward, id.drive);
  const MeasuredRecord sim = measure(mi, w, 2 / 50.0, 25e3, clean);
  double ss = 0.0, lo = 1e9, hi = -1e9;
  std::size_t n = 0;
  for (std::size_t i = rec.size() / 2; i < rec.size(); ++i, ++n) {
    ss += (sim.x_m[i] - rec.x_m[i]) * (sim.x_m[i] - rec.x_m[i]);
    lo = std::min(lo, rec.x_m[i]);
    hi = std::max(hi, rec.x_m[i]);
  }
  EXPECT_LT(std::sqrt(ss / static_cast<double>(n)) / (hi - lo), 0.02);
  // The inverse is exact: H^-1(H(U)) = U.
  EXPECT_LT(r.inverse_max_error_V, 1e-9);
  EXPECT_NO_THROW(r.inverse.validate());
}

TEST(IdentHysteresis, BadInputIsRejected) {
  const ActuatorModel m(test::ident_truth_params());
  const MeasuredRecord half = sine_record(m, 40, 0.6, 1);  // never returns to the minimum
  EXPECT_THROW(identify_hysteresis(half, 35), InvalidInput);
  MeasuredRecord flat = sine_record(m, 40, 2, 1);
  std::fill(flat.u_V.begin(), flat.u_V.end(), 10.0);
  EXPECT_THROW(identify_hysteresis(flat, 35), InvalidInput);
  EXPECT_THROW(identify_hysteresis(sine_record(m, 40, 2, 1), 0), UsageError);
}

}  // namespace
}  // namespace mc::stickslip
