#include "microcobot/microworld/tweezers_scenario.h"

#include <cmath>
#include <numbers>

#include <fmt/format.h>
#include <Eigen/Dense>

#include "microcobot/core/error.h"
#include "microcobot/dsp/welch.h"

namespace mc::microworld {

TweezersScenario parse_scenario(const std::string& text) {
  if (text == "brownian") return TweezersScenario::kBrownian;
  if (text == "contact") return TweezersScenario::kContact;
  throw UsageError("--scenario must be brownian or contact (got '" + text + "')");
}

TweezersRecord simulate_tweezers(const OpticalTrapParams& params, TweezersScenario scenario,
                                 const TweezersOptions& o) {
  require_positive(o.duration_s, "duration_s");
  require_positive(o.record_rate_Hz, "record_rate_Hz");
  OpticalTrap trap(params);
  // The record must resolve the bead's corner frequency, or the PSD read from it (and the corner
  // fitted to it) is aliased: 1e-3 N/m at the 10 kHz haptic rate fitted a corner 7 % low.
  require(
      trap.corner_frequency_Hz() < 0.5 * o.record_rate_Hz, "trap.trap_stiffness_N_per_m",
      fmt::format(
          "too stiff for record_rate_Hz = {:g} Hz: the corner frequency k / (2 pi gamma) = {:.3g} Hz "
          "must lie below the record's Nyquist frequency; the largest value this rate allows is {:.3g}",
          o.record_rate_Hz, trap.corner_frequency_Hz(), std::numbers::pi * trap.drag() * o.record_rate_Hz),
      params.trap_stiffness_N_per_m);
  const double dt = params.dt_s;
  const auto every = static_cast<long>(std::llround(1.0 / (o.record_rate_Hz * dt)));
  require(every >= 1, "record_rate_Hz", "must not exceed 1/dt_s", o.record_rate_Hz);
  require_budget(o.duration_s / dt, kMaxSimulatedSteps, "trap.dt_s",
                 "simulated steps (duration / trap.dt_s)");
  require_budget(o.duration_s * o.record_rate_Hz, kMaxRecordedSamples, "record_rate_Hz",
                 "recorded samples (duration x record_rate_Hz)");
  const auto steps = static_cast<long>(std::llround(o.duration_s / dt));
  Rng rng(o.seed);
  OpticalTrapState s;
  const double touch = params.bead_radius_m + params.obstacle_radius_m;
  const bool contact = scenario == TweezersScenario::kContact;
  if (contact) trap.set_obstacle(Eigen::Vector2d(0.0, touch + o.initial_gap_m));
  TweezersRecord rec;
  double t_contact = -1.0;
  double y_turn = 0.0;
  for (long k = 0; k < steps; ++k) {
    const double t = static_cast<double>(k) * dt;
    if (contact) {
      // The operator approaches at constant speed, feels the contact, and retracts.
      double y;
      if (t_contact < 0.0 || t < t_contact + o.retract_after_s) {
        y = o.approach_speed_m_s * t;
        y_turn = y;
      } else {
        y = std::max(0.0, y_turn - o.approach_speed_m_s * (t - t_contact - o.retract_after_s));
      }
      s.trap_m = Eigen::Vector2d(0.0, y);
      if (t_contact < 0.0 && trap.contact_force(s.bead_m).norm() > 0.0) t_contact = t;
    }
    trap.step(s, rng);
    if (k % every == 0) {
      const double f = params.trap_stiffness_N_per_m * (s.bead_m(1) - s.trap_m(1));
      rec.t_s.push_back(t);
      rec.bead_y_m.push_back(s.bead_m(1));
      rec.trap_y_m.push_back(s.trap_m(1));
      rec.force_y_N.push_back(f);
      rec.hand_force_N.push_back(o.force_scale * f);
    }
  }
  rec.contact_time_s = t_contact;
  return rec;
}

double fit_corner_frequency(const std::vector<double>& x, double fs) {
  dsp::WelchOptions w;
  w.fs_Hz = fs;
  w.nperseg = x.size() >= 16384 ? 4096 : 1024;
  const dsp::Spectrum psd = dsp::welch(x, w);
  const double t = 1.0 / fs;
  // 1/S = c0 + c1 cos(w T): weighted linear least squares (weights S, so that each bin's
  // relative error counts the same), DC and Nyquist bins excluded.
  Eigen::MatrixXd a(static_cast<Eigen::Index>(psd.f_Hz.size()), 2);
  Eigen::VectorXd b(a.rows());
  Eigen::Index n = 0;
  for (std::size_t i = 1; i + 1 < psd.f_Hz.size(); ++i) {
    const double sv = psd.value[i];
    if (!(sv > 0.0)) continue;
    a(n, 0) = sv;
    a(n, 1) = sv * std::cos(2.0 * std::numbers::pi * psd.f_Hz[i] * t);
    b(n) = 1.0;
    ++n;
  }
  if (n < 10) throw ComputationFailed("corner fit: too few PSD bins");
  const Eigen::Vector2d c = a.topRows(n).colPivHouseholderQr().solve(b.head(n));
  // c0 = (1 + a^2)/A, c1 = -2a/A  =>  a^2 + 2 (c0/c1) a + 1 = 0, root in (0, 1).
  if (!(c(1) < 0.0)) throw ComputationFailed("corner fit: PSD is not a Lorentzian decay");
  const double r = c(0) / c(1);
  const double disc = r * r - 1.0;
  if (disc <= 0.0) throw ComputationFailed("corner fit: no real decay factor");
  const double decay = -r - std::sqrt(disc);
  if (!(decay > 0.0 && decay < 1.0)) throw ComputationFailed("corner fit: decay out of (0, 1)");
  return -std::log(decay) / (2.0 * std::numbers::pi * t);
}

}  // namespace mc::microworld
