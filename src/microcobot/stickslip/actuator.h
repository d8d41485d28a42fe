#pragma once
/// @file
/// One stick-slip positioning axis: PE (eq. 2.1-2.7) + PI hysteresis (Fig. 2.6) + two-asperity
/// elasto-plastic friction (eq. 2.9-2.21) + slider (eq. 2.8), and its fixed-step integrator.
///
/// Integrator (docs/concepts/stick-slip.md): each step of length h (split into integrator.substeps sub-steps
/// while the contact is active: abrupt drive edge or a strain near z_ba; and cut at the drive's
/// corners, DriveSegment)
///  1. H(U) by the PI operators (rate independent, exact) at each corner and at the step's end,
///     linear in time between them;
///  2. the PE's two modes by exact discretisation with a first-order hold on g H(U) and a
///     zero-order hold on the friction reaction (which is < 1e-8 of the modal forces);
///  3. each slider part by velocity Verlet, its strain z by advance_strain() along the relative
///     path increment (exact in the elastic phase, so the stick phase has no drift); the velocity
///     takes the step's impulse of F = rho0 z + (rho1 dz/dx + rho2)(x1' - x2') (eq. 2.10-2.11):
///     rho0 z by the trapezoid of its ends, the damping with the PE's mean velocity over the step
///     against the trapezoid of x2' (implicit);
///  4. the end stops as inelastic contacts (position clamped, inward velocity removed).
///
/// One ActuatorModel (immutable: params + precomputed matrices) drives any number of
/// ActuatorStates; step() never allocates, locks, throws or does I/O.

#include <array>
#include <functional>
#include <vector>

#include "microcobot/stickslip/drive.h"
#include "microcobot/stickslip/drive_segment.h"
#include "microcobot/stickslip/piezo_element.h"
#include "microcobot/stickslip/stickslip_params.h"

namespace mc::stickslip {

/// The state of one axis. Plain copyable data.
struct ActuatorState {
  double t_s = 0.0;
  double u_V = 0.0;   ///< last drive voltage
  double uh_m = 0.0;  ///< g H(U): hysteretic static PE displacement [m]
  PiState pi;
  double x1a_m = 0.0, v1a_m_s = 0.0, x1b_m = 0.0, v1b_m_s = 0.0;  ///< PE modes (eq. 2.1-2.3)
  std::array<double, 2> x2_m{};                                   ///< slider part positions (asperity a, b)
  std::array<double, 2> v2_m_s{};                                 ///< slider part velocities
  std::array<double, 2> a2_m_s2{};                                ///< slider part accelerations (Verlet)
  std::array<double, 2> z_m{};  ///< elastic strain of asperity a, b (eq. 2.9)
  std::array<double, 2> f_N{};  ///< friction force of asperity a, b per unit share (eq. 2.20-2.21)
  double friction_N = 0.0;      ///< F_f on the slider (reaction -F_f on the PE)
  double z_ba_m = 1e-6;         ///< current break-away strain (operating point)
  bool diverged = false;        ///< set when a state became NaN/Inf

  double x1_m() const { return x1a_m + x1b_m; }  ///< PE displacement (eq. 2.3)
};

class ActuatorModel {
 public:
  /// Validates `params` and precomputes the discretisation for params.integrator.dt_s (or `dt_s`).
  explicit ActuatorModel(StickSlipParams params);
  ActuatorModel(StickSlipParams params, double dt_s);

  const StickSlipParams& params() const { return p_; }
  double dt_s() const { return dt_; }

  /// A state at rest at U = 0, slider at slider.initial_position_m.
  ActuatorState initial_state() const;
  /// Sets the break-away strain from the table at the drive's operating point (thesis §2.7: the
  /// sawtooth generator passes its configuration to the model). Real-time safe.
  void set_operating_point(ActuatorState& s, double amplitude_V, double frequency_Hz,
                           Direction direction) const noexcept;
  /// Advances `s` by dt_s() along the drive's path over the step: linear from s.u_V through the
  /// segment's corners to its end voltage (each clamped to the amplifier range). Never
  /// allocates; NaN/Inf sets s.diverged.
  void step(ActuatorState& s, const DriveSegment& drive) const noexcept;
  /// A step whose drive is linear from s.u_V to `u_V` (a sample stream played by a DAC through
  /// its reconstruction filter).
  void step(ActuatorState& s, double u_V) const noexcept;
  /// Slider position x2 [m]: the mass-weighted mean of its two parts (docs/concepts/stick-slip.md).
  double slider_position(const ActuatorState& s) const noexcept;
  double slider_velocity(const ActuatorState& s) const noexcept;
  /// True when a step at the state's own voltage would leave it as it is, to within a picometre:
  /// the PE modes at their static equilibrium and still, the slider's parts still. A drive held
  /// constant brings the model there within milliseconds (the PE's ringing and the contact's
  /// oscillation are damped); a simulated axis then skips its integration (a parked axis).
  bool at_rest(const ActuatorState& s) const noexcept;
  /// Mass fraction of slider part a and b.
  std::array<double, 2> mass_fractions() const { return c_; }

 private:
  StickSlipParams p_;
  double dt_;
  /// What a step of length h needs, precomputed at construction.
  struct StepConstants {
    double h = 0.0;
    double inv_h = 0.0;
    ModeDiscretization ma, mb;     ///< exact PE mode matrices for h
    std::array<double, 2> rho0{};  ///< rho0 pre-warped for Verlet at h (docs/concepts/stick-slip.md)
  };
  /// The constants of a step of length h (the grid's, and a sub-step split at a corner).
  StepConstants constants(double h) const noexcept;
  /// One integration sub-step (PE exact, contact by Verlet + path-integrated strain).
  void substep(ActuatorState& s, double uh_m, const StepConstants& k) const noexcept;

  StepConstants full_, sub_;
  int substeps_ = 1;
  std::array<double, 2> c_{}, rho0_{}, rho1_{};
  std::array<double, 2> inv_m_{};       ///< 1 / (c_i M_s), the part masses' reciprocals
  double ka_ = 0.0, kb_ = 0.0;          ///< K_pa phi, K_pb (1 - phi): force per metre of g H(U)
  double inv_ratio_ = 1.0;              ///< 1 / (z_ba / z_ss)
  double inv_wa_ = 0.0, inv_wb_ = 0.0;  ///< 1 / omega of the PE modes
  double inv_ka_ = 0.0, inv_kb_ = 0.0;  ///< 1 / K_pa, 1 / K_pb
  double ringing_sq_ = 0.0;             ///< integrator.substep_ringing_m squared
  double lo_ = 0.0, hi_ = 0.0;
};

/// step(params-model, state, input, ...) in the free-function form used by the platform loop.
inline void step(const ActuatorModel& m, ActuatorState& s, const DriveSegment& drive) noexcept {
  m.step(s, drive);
}

/// A sampled run.
struct Trajectory {
  std::vector<double> t_s, u_V, x1_m, x2_m;
};

/// Runs `wave` for `duration_s` from the model's initial state (or `state`), recording every
/// `record_every` steps. The model follows the exact waveform (Waveform::segment: its corners
/// wherever they fall in time). Sets the operating point from the waveform. Throws
/// mc::ComputationFailed on divergence (never returns NaN).
Trajectory simulate(const ActuatorModel& m, const Waveform& wave, double duration_s, int record_every = 1,
                    ActuatorState* state = nullptr);

/// The streaming form of simulate(): steps `state` through `wave` for `duration_s` (operating
/// point set from the waveform) and hands the first state and every `record_every`-th after it
/// to `on_sample`, for callers that keep only what they need (the CLI without --out keeps no
/// 32 MB record of a 10 s run). Throws mc::ComputationFailed on divergence, `state` then
/// unspecified.
void simulate_each(const ActuatorModel& m, const Waveform& wave, double duration_s, int record_every,
                   ActuatorState& state, const std::function<void(const ActuatorState&)>& on_sample);

}  // namespace mc::stickslip
