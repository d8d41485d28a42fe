// Identification step 1 (thesis §2.5.2.1): round trip of the PE modes and of the two asperities
// from simulated step responses with the sensor effects of §2.5.1, and the bad-input contracts.
#include <cmath>

#include <gtest/gtest.h>

#include "ident_truth.h"
#include "microcobot/core/error.h"
#include "microcobot/stickslip/ident_friction_modes.h"
#include "microcobot/stickslip/ident_modal.h"
#include "microcobot/stickslip/ident_pe_modes.h"

namespace mc::stickslip {
// The file's own namespace: its helpers keep their names beside the other test files of the
// module in a unity build (MC_UNITY_TESTS).
namespace ident_modes_test {
namespace {

double freq(double k, double m) { return std::sqrt(k / m) / (2 * M_PI); }
double zeta(double d, double k, double m) { return d / (2 * std::sqrt(k * m)); }

MeasuredRecord pe_record(const StickSlipParams& truth, std::uint64_t seed) {
  StickSlipParams p = truth;
  p.slider.attached = false;
  const ActuatorModel m(p, 1e-6);
  const auto w = make_waveform(WaveKind::kStep, 90, 1, Direction::kForward, p.drive);
  SensorEffects s;
  s.seed = seed;
  return measure(m, w, 1e-3, 1e6, s, Measured::kPiezo, 1e-4);
}

TEST(IdentPeModes, RecoversTheModesOfAnotherAxis) {
  const StickSlipParams truth = test::ident_truth_params();
  const MeasuredRecord rec = pe_record(truth, 7);
  const PeModesResult r = identify_pe_modes(rec, StickSlipParams{}.pe);
  const auto& t = truth.pe;
  EXPECT_NEAR(r.a.frequency_Hz / freq(t.stiffness_a_N_m, t.mass_kg), 1.0, 0.01);
  EXPECT_NEAR(r.b.frequency_Hz / freq(t.stiffness_b_N_m, t.mass_kg), 1.0, 0.01);
  EXPECT_NEAR(r.a.damping_ratio / zeta(t.damping_a_N_s_m, t.stiffness_a_N_m, t.mass_kg), 1.0, 0.10);
  EXPECT_NEAR(r.b.damping_ratio / zeta(t.damping_b_N_s_m, t.stiffness_b_N_m, t.mass_kg), 1.0, 0.10);
  EXPECT_NEAR(r.gain_fraction_a, t.gain_fraction_a, 0.05);
  // The PSD sees both resonances near the truth (the initial guesses of the fit).
  ASSERT_EQ(r.psd_peaks_Hz.size(), 2u);
  EXPECT_NEAR(r.psd_peaks_Hz[0] / 55e3, 1.0, 0.1);
  EXPECT_NEAR(r.psd_peaks_Hz[1] / 104e3, 1.0, 0.1);
  // The residual is the sensor noise (1 nm RMS), not model error.
  EXPECT_LT(r.rms_m, 2.5e-9);
  EXPECT_NO_THROW(r.params.validate());
}

TEST(IdentFrictionModes, RecoversTheAsperitiesOfAnotherAxis) {
  const StickSlipParams truth = test::ident_truth_params();
  // The "real" axis is simulated with a 1 us step (the default 10 us step shifts the heavily
  // damped 520 Hz mode by ~1.4%: discretisation, not physics).
  const ActuatorModel m(truth, 1e-6);
  const auto w = make_waveform(WaveKind::kStep, 20, 1, Direction::kForward, truth.drive);
  SensorEffects s;
  s.seed = 11;
  const MeasuredRecord rec = measure(m, w, 0.03, 25e3, s, Measured::kSlider, 2e-3);
  // The PE as identified in step 1a (the PE's compliance loads the contact).
  StickSlipParams base;
  base.pe = identify_pe_modes(pe_record(truth, 5), base.pe).params;
  const FrictionModesResult r = identify_friction_modes(rec, base);
  const auto& f = truth.friction;
  const double ms = truth.slider.mass_kg;
  EXPECT_NEAR(r.a.frequency_Hz / freq(f.rho0_a_N_m, ms), 1.0, 0.01);
  EXPECT_NEAR(r.b.frequency_Hz / freq(f.rho0_b_N_m, ms), 1.0, 0.01);
  EXPECT_NEAR(r.a.damping_ratio / zeta(f.rho1_a_N_s_m, f.rho0_a_N_m, ms), 1.0, 0.10);
  EXPECT_NEAR(r.b.damping_ratio / zeta(f.rho1_b_N_s_m, f.rho0_b_N_m, ms), 1.0, 0.10);
  EXPECT_NEAR(r.mass_fraction_a, f.mass_fraction_a, 0.05);
  EXPECT_LT(r.rms_m, 2.5e-9);
}

MeasuredRecord small_step(std::size_t n, double step_V) {
  MeasuredRecord r;
  r.source = "x.csv";
  for (std::size_t i = 0; i < n; ++i) {
    r.t_s.push_back(static_cast<double>(i) * 1e-5);
    r.u_V.push_back(i > 10 ? step_V : 0.0);
    r.x_m.push_back(i > 10 ? step_V * 1e-8 : 0.0);
  }
  return r;
}

TEST(IdentRecord, BadInputGivesOneLineErrors) {
  CsvTable no_x({"t_s", "u_V"});
  for (int i = 0; i < 20; ++i) no_x.add_row(std::vector<double>{i * 1e-3, 1.0});
  try {
    record_from_table(no_x, "a.csv");
    FAIL();
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("x_m"), std::string::npos) << e.what();
  }
  CsvTable back({"t_s", "u_V", "x_m"});
  for (int i = 0; i < 20; ++i) back.add_row(std::vector<double>{i == 12 ? 0.0 : i * 1e-3, 1.0, 0.0});
  EXPECT_THROW(record_from_table(back, "b.csv"), InvalidInput);
  CsvTable few({"t_s", "u_V", "x_m"});
  for (int i = 0; i < 5; ++i) few.add_row(std::vector<double>{i * 1e-3, 1.0, 0.0});
  EXPECT_THROW(record_from_table(few, "c.csv"), InvalidInput);
  // A record that never steps.
  EXPECT_THROW(fit_step_input(small_step(400, 0.0)), InvalidInput);
  // Too short for the analysis.
  EXPECT_THROW(identify_pe_modes(small_step(100, 50.0), StickSlipParams{}.pe), InvalidInput);
}

TEST(IdentRecord, StepReconstructionIgnoresVoltageNoise) {
  const StickSlipParams truth = test::ident_truth_params();
  const MeasuredRecord rec = pe_record(truth, 3);
  const StepInput s = fit_step_input(rec);
  EXPECT_NEAR(s.u1_V - s.u0_V, 90.0, 0.2);
  EXPECT_NEAR(s.t_ramp_s, 90.0 / truth.drive.slew_rate_V_s, 3e-6);
  EXPECT_NEAR(s.t_start_s, 1e-4, 2e-6);
}

}  // namespace
}  // namespace ident_modes_test
}  // namespace mc::stickslip
