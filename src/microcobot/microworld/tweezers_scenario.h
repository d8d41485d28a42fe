#pragma once
/// @file
/// Recorded optical-tweezers scenarios (thesis §3.5.2, Fig. 3.14-3.16): the trapped probe
/// bead under Brownian motion alone, or driven by the operator into a large bead stuck on the
/// dish. The measured force k (x - x_trap) (linear spring model, Fig. 3.3) is recorded at the
/// haptic loop rate and scaled to the hand by a fixed factor.

#include <cstdint>
#include <string>
#include <vector>

#include "microcobot/microworld/optical_trap.h"

namespace mc::microworld {

enum class TweezersScenario { kBrownian, kContact };
/// Parses "brownian" or "contact"; throws UsageError otherwise.
TweezersScenario parse_scenario(const std::string& text);

struct TweezersOptions {
  double duration_s = 2.0;
  double record_rate_Hz = 1.0e4;  ///< the haptic loop rate
  /// Force scaling micro -> hand: 1 pN at the bead is 0.2 N at the hand (2e11). Brownian
  /// forces (~0.2 pN rms at 10 pN/um) become ~0.04 N, a contact (~5 pN) ~1 N.
  double force_scale = 2.0e11;
  double approach_speed_m_s = 4.0e-6;  ///< probe speed towards the stuck bead (contact)
  double initial_gap_m = 2.0e-6;       ///< surface gap at t = 0 (contact)
  double retract_after_s = 0.15;       ///< operator reaction after contact, then retracts
  std::uint64_t seed = 3;
};

struct TweezersRecord {
  std::vector<double> t_s;
  std::vector<double> bead_y_m;  ///< probe bead, along the approach axis
  std::vector<double> trap_y_m;
  std::vector<double> force_y_N;     ///< measured force k (y - y_trap)
  std::vector<double> hand_force_N;  ///< scaled to the hand
  double contact_time_s = -1.0;      ///< first contact (contact scenario), else -1
};

/// Simulates the scenario and records it.
TweezersRecord simulate_tweezers(const OpticalTrapParams& trap, TweezersScenario scenario,
                                 const TweezersOptions& options);

/// Corner frequency of the bead's position PSD: Welch PSD of the recorded positions, fitted by
/// the sampled Lorentzian S(f) = A / (1 + a^2 - 2 a cos(2 pi f T)) (exact for an OU process
/// sampled at T), f_c = -ln(a) / (2 pi T). Throws ComputationFailed if the fit is not a decay.
double fit_corner_frequency(const std::vector<double>& x, double fs_Hz);

}  // namespace mc::microworld
