#pragma once
/// @file
/// A person's hand as a motor system, for the simulated operator of the
/// manual and assisted cycles: seeded, with the limits the human-factors literature measures.
///
///  - **Reaction time.** A correction starts `reaction_time_s` after the person has seen the
///    result of the last movement (visual feedback loop ~200 ms: Card, Moran and Newell, The
///    Psychology of Human-Computer Interaction, 1983, perceptual + cognitive + motor cycles;
///    Welford, Reaction Times, 1980), plus the display's delay when the scene is shown late: under
///    delay a person moves and then waits to see (Ferrell, IEEE T-HFE 6(1), 1965).
///  - **Sub-movements.** Each movement is a minimum-jerk profile (Flash and Hogan, J. Neurosci.
///    5(7), 1985) x(t) = x0 + (x1 - x0)(10 s^3 - 15 s^4 + 6 s^5), s = t / T, whose duration
///    follows Fitts' law in its Shannon form (MacKenzie, Human-Computer Interaction 7, 1992)
///        T = a + b log2(D / W + 1)
///    for an amplitude D and the tolerance W the person aims at, and whose end misses the aim by
///    a normal error of standard deviation `endpoint_sd_fraction` x D per axis (signal-dependent
///    noise: Meyer et al., Psychological Review 95(3), 1988; Harris and Wolpert, Nature 394,
///    1998). A miss beyond W calls for a corrective sub-movement, smaller, after the reaction
///    time: the primary movement and its corrections together give Fitts' law's total time.
///  - **Tremor.** Physiological tremor is added to the hand's position: white noise through a
///    band-pass of 8-12 Hz (Butterworth, 4th order each side), scaled to `tremor_rms_m` per axis
///    (~100 um RMS at the hand: Elble and Koller, Tremor, 1990; Riviere, Rader and Thakor, IEEE
///    T-BME 45(5), 1998, measured 50-100 um in microsurgery).
///
/// Reach and Tremor are pure objects stepped at the operator rate; neither allocates after
/// construction (real-time safe).

#include <cstdint>
#include <limits>

#include <Eigen/Core>

#include "microcobot/core/rng.h"
#include "microcobot/dsp/sos.h"

namespace mc::cell {

struct PersonParams {
  double reaction_time_s = 0.2;        ///< from seeing a result to the next correction
  double display_delay_s = 0.0;        ///< the scene shown late by this (a remote microscope)
  double fitts_a_s = 0.1;              ///< Fitts' intercept
  double fitts_b_s_per_bit = 0.12;     ///< Fitts' slope (pointing with a stylus or handle)
  double endpoint_sd_fraction = 0.05;  ///< endpoint error SD / amplitude, per axis
  double tremor_rms_m = 100e-6;        ///< hand tremor, per axis
  double tremor_low_Hz = 8.0;          ///< the tremor's band: physiological tremor, 8 to 12 Hz
  double tremor_high_Hz = 12.0;        ///< (its upper edge)
  double vision_sd_m = 1.0e-6;         ///< what the person makes out through the microscope (SD)
  double feel_contact_N = 60e-6;       ///< a contact force the person notices (seen or felt)
  double stage_pace_m_s = 0.5e-3;      ///< the stage speed the person has learned not to outrun

  template <class V>
  void visit(V& v) {
    v("reaction_time_s", reaction_time_s);
    v("display_delay_s", display_delay_s);
    v("fitts_a_s", fitts_a_s);
    v("fitts_b_s_per_bit", fitts_b_s_per_bit);
    v("endpoint_sd_fraction", endpoint_sd_fraction);
    v("tremor_rms_m", tremor_rms_m);
    v("tremor_low_Hz", tremor_low_Hz);
    v("tremor_high_Hz", tremor_high_Hz);
    v("vision_sd_m", vision_sd_m);
    v("feel_contact_N", feel_contact_N);
    v("stage_pace_m_s", stage_pace_m_s);
  }
  /// Throws mc::InvalidParams naming the field.
  void validate() const;
  /// Fitts' movement time for amplitude `d` and tolerance `w` (same units).
  double movement_time_s(double d, double w) const noexcept;
};

/// One person's aimed movements of a point in the plane (a hand, a joystick's target, a jog
/// wheel's height): minimum-jerk sub-movements with endpoint noise, and the reaction time
/// between seeing a movement's end and the next.
class Reach {
 public:
  Reach(const PersonParams& params, Rng& rng) : p_(params), rng_(rng) {}

  /// Starts from `at`, still (a new phase, a clutch released).
  void reset(const Eigen::Vector2d& at, double t_s) noexcept;
  /// Aims to close the error the person sees, `error` (from the point to its goal, in the
  /// point's units), within `tolerance`: once the last movement has ended and the person has
  /// reacted (ready()), an error beyond the tolerance starts a sub-movement of that amplitude
  /// from where the last one ended, missing by the endpoint noise, no faster than `max_speed`
  /// at its peak (1.875 D / T for a minimum-jerk profile). Returns true when the person, ready,
  /// sees the error within the tolerance.
  /// `width`, when given, is the target's width the person plans the movement for (Fitts' W)
  /// where it differs from the tolerance they check (a guided target is caught from further).
  bool aim(const Eigen::Vector2d& error, double tolerance, double t_s,
           double max_speed = std::numeric_limits<double>::infinity(), double width = 0.0) noexcept;
  /// The person has seen the last movement end and may act again.
  bool ready(double t_s) const noexcept {
    return t_s >= t0_ + duration_ + p_.display_delay_s + p_.reaction_time_s;
  }
  /// Aims with no noise and no reaction (a clutch's way back, a move the person does not
  /// watch); the movement's end is `goal` exactly.
  void move(const Eigen::Vector2d& goal, double duration_s, double t_s) noexcept;
  /// The point at time `t_s` (the minimum-jerk profile of the current sub-movement).
  Eigen::Vector2d position(double t_s) const noexcept;
  Eigen::Vector2d velocity(double t_s) const noexcept;
  bool moving(double t_s) const noexcept { return t_s < t0_ + duration_; }
  /// Where the current movement will end.
  const Eigen::Vector2d& end() const noexcept { return x1_; }
  int submovements() const noexcept { return count_; }

 private:
  PersonParams p_;
  Rng& rng_;
  Eigen::Vector2d x0_ = Eigen::Vector2d::Zero(), x1_ = Eigen::Vector2d::Zero();
  double t0_ = 0.0, duration_ = 0.0;
  int count_ = 0;
};

/// Physiological tremor in the plane: two band-passed white noises of the configured RMS.
class Tremor {
 public:
  /// Designs the band-pass at `rate_Hz` (allocates). Throws mc::InvalidParams.
  Tremor(const PersonParams& params, double rate_Hz, std::uint64_t seed);
  /// The next sample [m]. Never allocates.
  Eigen::Vector2d next() noexcept;

 private:
  Rng rng_;
  dsp::SosFilter x_, y_;
  double gain_ = 0.0;  // white-noise SD giving tremor_rms_m at the output
};

}  // namespace mc::cell
