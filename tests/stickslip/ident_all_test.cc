// The identification round trip: a campaign simulated on an axis unlike the defaults, with the
// sensor effects of §2.5.1, identified by the three steps of §2.5.2; the identified axis
// reproduces held-out sawtooth runs. Also the directory contracts (bad input, skipped runs).
#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "ident_truth.h"
#include "microcobot/core/error.h"
#include "microcobot/core/params.h"
#include "microcobot/stickslip/ident_all.h"
#include "microcobot/stickslip/ident_synthetic.h"
#include "support/test_support.h"

namespace mc::stickslip {
namespace {

double freq(double k, double m) { return std::sqrt(k / m) / (2 * M_PI); }
double zeta(double d, double k, double m) { return d / (2 * std::sqrt(k * m)); }

CampaignPlan test_plan() {
  CampaignPlan plan;
  plan.amplitudes_V = {40, 60, 80, 100};  // 40 V below 500 Hz: scanning mode, never steps
  plan.frequencies_Hz = {100, 200, 500};
  return plan;
}

TEST(IdentAll, RoundTripRecoversAnotherAxis) {
  const StickSlipParams truth = test::ident_truth_params();
  mc::test::TempDir dir;
  write_campaign(dir.path(), truth, test_plan(), SensorEffects{});
  std::atomic<int> calls{0};
  const IdentifyAllResult r = identify_all(dir.path(), StickSlipParams{}, {},
                                           [&](const std::string&, std::size_t, std::size_t) { ++calls; });
  EXPECT_GT(calls.load(), 5);
  // Step 1: modes within 1%, damping within 10%.
  ASSERT_TRUE(r.pe.has_value());
  const auto& pe = truth.pe;
  EXPECT_NEAR(r.pe->a.frequency_Hz / freq(pe.stiffness_a_N_m, pe.mass_kg), 1.0, 0.01);
  EXPECT_NEAR(r.pe->b.frequency_Hz / freq(pe.stiffness_b_N_m, pe.mass_kg), 1.0, 0.01);
  EXPECT_NEAR(r.pe->a.damping_ratio / zeta(pe.damping_a_N_s_m, pe.stiffness_a_N_m, pe.mass_kg), 1.0, 0.1);
  EXPECT_NEAR(r.pe->b.damping_ratio / zeta(pe.damping_b_N_s_m, pe.stiffness_b_N_m, pe.mass_kg), 1.0, 0.1);
  const auto& f = truth.friction;
  const double ms = truth.slider.mass_kg;
  EXPECT_NEAR(r.friction.a.frequency_Hz / freq(f.rho0_a_N_m, ms), 1.0, 0.01);
  EXPECT_NEAR(r.friction.b.frequency_Hz / freq(f.rho0_b_N_m, ms), 1.0, 0.01);
  EXPECT_NEAR(r.friction.a.damping_ratio / zeta(f.rho1_a_N_s_m, f.rho0_a_N_m, ms), 1.0, 0.1);
  EXPECT_NEAR(r.friction.b.damping_ratio / zeta(f.rho1_b_N_s_m, f.rho0_b_N_m, ms), 1.0, 0.1);
  // Step 2: PI loop within 2% of the stroke.
  EXPECT_LT(r.hysteresis.rms_fraction, 0.02);
  // Step 3: the 40 V runs at 100 and 200 Hz never step: reported and skipped, their cells
  // extrapolated (below every fitted cell of their column), none interpolated.
  std::size_t skipped = 0;
  for (const auto& run : r.breakaway.runs) {
    if (run.amplitude_V == 40 && run.frequency_Hz < 300) {
      EXPECT_FALSE(run.ok) << run.name;
      EXPECT_NE(run.skipped.find("never steps"), std::string::npos) << run.skipped;
      ++skipped;
    } else {
      EXPECT_TRUE(run.ok) << run.name << ": " << run.skipped;
      EXPECT_NEAR(run.v_simulated_m_s / run.v_measured_m_s, 1.0, 0.01) << run.name;
    }
  }
  EXPECT_EQ(skipped, 4u);
  EXPECT_EQ(r.breakaway.skipped, 4u);
  EXPECT_TRUE(r.breakaway.filled.empty());
  EXPECT_EQ(r.breakaway.extrapolated.size(), 4u);
  // Held-out runs (amplitudes and a frequency, 300 Hz, not in the campaign): the identified axis
  // moves as the truth does, within 5%, in both directions.
  const ActuatorModel mt(truth), mi(r.params);
  for (double a : {70.0, 90.0}) {
    for (double fr : {100.0, 200.0, 300.0, 500.0}) {
      for (Direction d : {Direction::kForward, Direction::kBackward}) {
        const auto w = make_waveform(WaveKind::kSawtooth, a, fr, d, truth.drive);
        const int periods = std::max(5, static_cast<int>(std::ceil(0.005 * fr)));
        // The true axis's own surface (closed form), not an interpolation of its table.
        const double vt = simulated_mean_velocity(mt, w, test::ident_truth_zba(a, fr, d), periods);
        const double vi = simulated_mean_velocity(mi, w, r.params.breakaway.lookup(a, fr, d), periods);
        EXPECT_NEAR(vi / vt, 1.0, 0.05) << a << " V " << fr << " Hz " << to_string(d);
        EXPECT_GT(vt * (d == Direction::kForward ? 1 : -1), 0.0);
        std::printf("held-out %g V %g Hz %s: v_identified / v_true - 1 = %+.2f%%\n", a, fr,
                    to_string(d).c_str(), 100.0 * (vi / vt - 1.0));
      }
    }
  }
  // The parameter file is what `stickslip simulate --params` reads.
  const auto back = params_from_yaml_text<StickSlipParams>(params_to_yaml(r.params));
  EXPECT_EQ(back.breakaway.forward_m, r.params.breakaway.forward_m);
  EXPECT_DOUBLE_EQ(back.friction.rho0_a_N_m, r.params.friction.rho0_a_N_m);
  EXPECT_EQ(back.hysteresis.weights, r.params.hysteresis.weights);
}

/// Steady step per period of `m` at a sawtooth drive: over periods 1..n after the power-up one.
double steady_step(const ActuatorModel& m, double amplitude, double frequency, Direction d, int n) {
  const auto w = make_waveform(WaveKind::kSawtooth, amplitude, frequency, d, m.params().drive);
  const Trajectory tr = simulate(m, w, (n + 1) / frequency);
  auto at = [&](int k) { return tr.x2_m[static_cast<std::size_t>(std::llround(k / frequency / m.dt_s()))]; };
  return (at(n + 1) - at(1)) / n;
}

TEST(IdentAll, NearThresholdDrivesRelyOnExtrapolatedNotCopiedCells) {
  // The default axis's full campaign (`identify synth --grid full`, realistic noise:
  // 0.3 nm, 0.5 V). The backward runs below ~45 V never step at 50-100 Hz; were their cells to
  // take the nearest stepping cell's z_ba (50 V: too high by the slope x 10 V), the 45 V
  // 150 Hz backward drive, just above the threshold, would step 17 % short of the truth. So those
  // cells are extrapolated along the stepping cells' line in amplitude and reported as such.
  const StickSlipParams truth;
  CampaignPlan plan;
  plan.amplitudes_V = {10, 20, 30, 40, 50, 60, 70, 80, 90, 100};
  plan.frequencies_Hz = {50, 100, 500, 1000, 2000};
  SensorEffects sensor;
  sensor.position_noise_rms_m = 0.3e-9;
  sensor.voltage_noise_rms_V = 0.5;
  mc::test::TempDir dir;
  write_campaign(dir.path(), truth, plan, sensor);
  const IdentifyAllResult r = identify_all(dir.path(), StickSlipParams{});
  bool backward_40V_100Hz = false;
  for (const auto& c : r.breakaway.extrapolated) backward_40V_100Hz |= c == "backward 40 V 100 Hz";
  EXPECT_TRUE(backward_40V_100Hz);
  const double want = steady_step(ActuatorModel(truth), 45, 150, Direction::kBackward, 14);
  const double got = steady_step(ActuatorModel(r.params), 45, 150, Direction::kBackward, 14);
  std::printf("45 V 150 Hz backward: %.2f nm per period identified, %.2f nm true (%+.1f %%)\n", got * 1e9,
              want * 1e9, 100 * (got / want - 1));
  EXPECT_LT(want, -20e-9);  // it does step
  EXPECT_NEAR(got / want, 1.0, 0.10);
}

TEST(IdentAll, ThreadsDoNotChangeTheResult) {
  const StickSlipParams truth = test::ident_truth_params();
  CampaignPlan plan;
  plan.amplitudes_V = {60, 100};
  plan.frequencies_Hz = {200};
  const ActuatorModel m(truth);
  std::vector<SawtoothRun> runs;
  for (double a : plan.amplitudes_V) {
    for (Direction d : {Direction::kForward, Direction::kBackward}) {
      SawtoothRun run;
      run.name = sawtooth_file_name(a, 200, d);
      run.amplitude_V = a;
      run.frequency_Hz = 200;
      run.direction = d;
      run.rec = measure_sawtooth(m, a, 200, d, plan, SensorEffects{});
      runs.push_back(run);
    }
  }
  BreakawayOptions one, two;
  one.threads = 1;
  two.threads = 2;
  const auto r1 = identify_breakaway(runs, m, one);
  const auto r2 = identify_breakaway(runs, m, two);
  ASSERT_EQ(r1.runs.size(), r2.runs.size());
  for (std::size_t i = 0; i < r1.runs.size(); ++i) {
    ASSERT_TRUE(r1.runs[i].ok) << r1.runs[i].skipped;
    EXPECT_DOUBLE_EQ(r1.runs[i].z_ba_m, r2.runs[i].z_ba_m);
    // Identified on the true model itself: z_ba comes back (velocity is steep in z_ba).
    EXPECT_NEAR(r1.runs[i].z_ba_m / truth.breakaway.lookup(runs[i].amplitude_V, 200, runs[i].direction), 1.0,
                0.01);
  }
}

TEST(IdentAll, RecordsWithoutASawtoothRunAreRefusedBeforeAnyComputation) {
  const IdentificationRecords none;  // empty step and sine records too: refused first for the runs
  try {
    identify_all(none, StickSlipParams{});
    FAIL();
  } catch (const InvalidInput& e) {
    EXPECT_STREQ(e.what(), "sawtooth: no run (step 3 needs at least one)");
  }
}

TEST(IdentAll, SynthTakesTheSensorNoiseAndHysteresisReportsItsDecision) {
  // `identify synth --voltage-noise V --position-noise M`: RMS values in volts and metres, the
  // same for every record; `identify hysteresis` estimates the voltage noise and says how it
  // took the sine record (from rest, by the two fits' residuals).
  mc::test::TempDir dir;
  auto r = mc::test::run_cli({"identify", "synth", "--out", (dir / "c").string(), "--voltage-noise", "0.5",
                              "--position-noise", "3e-10", "--seed", "7", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const MeasuredRecord sine = read_record(dir / "c" / "sine.csv");
  double s2 = 0.0;  // second differences: 6 sigma^2 for white noise
  for (std::size_t i = 1; i + 1 < sine.size(); ++i) {
    const double d2 = sine.u_V[i + 1] - 2 * sine.u_V[i] + sine.u_V[i - 1];
    s2 += d2 * d2;
  }
  EXPECT_NEAR(std::sqrt(s2 / 6.0 / static_cast<double>(sine.size() - 2)), 0.5, 0.03);
  r = mc::test::run_cli({"identify", "hysteresis", "--in", (dir / "c" / "sine.csv").string(), "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(j["from_rest"].get<bool>());
  EXPECT_LT(j["rms_from_rest_m"].get<double>(), j["rms_steady_loop_m"].get<double>());
  EXPECT_NEAR(j["voltage_noise_V"].get<double>(), 0.5, 0.05);
  // Out of range: a usage error naming the flag (exit 2).
  r = mc::test::run_cli({"identify", "synth", "--out", (dir / "d").string(), "--voltage-noise", "-1"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--voltage-noise"), std::string::npos) << r.err;
}

TEST(IdentAll, BadDirectoriesGiveOneLineErrors) {
  mc::test::TempDir dir;
  EXPECT_THROW(identify_all(dir.path() / "nope", StickSlipParams{}), InvalidInput);
  EXPECT_THROW(identify_all(dir.path(), StickSlipParams{}), InvalidInput);  // no step.csv
  EXPECT_THROW(read_sawtooth_runs(dir.path()), InvalidInput);               // no runs
  mc::test::write_text(dir / "sawtooth_60V_fast_forward.csv", "t_s,u_V,x_m\n0,0,0\n");
  try {
    read_sawtooth_runs(dir.path());
    FAIL();
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("sawtooth_<amplitude>V"), std::string::npos) << e.what();
  }
  double a = 0, fr = 0;
  Direction d{};
  EXPECT_TRUE(parse_sawtooth_file_name("sawtooth_62.5V_500Hz_backward.csv", a, fr, d));
  EXPECT_DOUBLE_EQ(a, 62.5);
  EXPECT_DOUBLE_EQ(fr, 500);
  EXPECT_EQ(d, Direction::kBackward);
  for (const char* bad : {"sawtooth_62.V_500Hz_forward.csv", "sawtooth_0V_500Hz_forward.csv",
                          "sawtooth_60V_500Hz_forward.csv.bak", "sawtooth_60V_500Hz_sideways.csv",
                          "sawtooth_-60V_500Hz_forward.csv", "sawtooth_60V500Hz_forward.csv"}) {
    EXPECT_FALSE(parse_sawtooth_file_name(bad, a, fr, d)) << bad;
  }
  EXPECT_DOUBLE_EQ(a, 62.5);  // a rejected name leaves the outputs untouched
  EXPECT_EQ(sawtooth_file_name(60, 500, Direction::kForward), "sawtooth_60V_500Hz_forward.csv");
}

}  // namespace
}  // namespace mc::stickslip
