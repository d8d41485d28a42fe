#pragma once
/// @file
/// Trajectory tracking within one step (the "trajectory tracking" that thesis §2.7 and
/// §2.8 name as what the model makes possible): one continuous scanning loop whose sawtooth is
/// phased by the reference itself.
///
///  - Scanning is the slow ramp of every period: the slider sticks to the PE (thesis §2.2.2,
///    Fig. 2.2a), so the voltage that puts it on the reference is the exact inverse of the
///    Prandtl-Ishlinskii hysteresis (eq. 2.5) applied to the wanted PE extension
///    y = y_anchor + (r - r_anchor) + catch-up + integral. The ramp is therefore never linear: it
///    follows the reference's position, velocity and acceleration continuously (sub-step
///    resolution while stepping).
///  - The abrupt edge (Fig. 2.2b, 2.3) is a "flyback": when the ramp reaches the end of the PE's
///    range in the direction of motion, the voltage returns to the other end at the amplifier's
///    slew limit, the slider slips and keeps its place but for a backslip b. The period of the
///    resulting sawtooth is set by the reference velocity: f = |v| / s(A, f, direction) from the
///    model's step map (the step map's inverse at the operating point), and it is this operating
///    point (A, f, direction) that the model's break-away strain z_ba sees (thesis §2.7: the
///    generator passes its configuration on).
///  - Feedforward of the backslip: before an edge the ramp leads the reference by a fraction of
///    the predicted backslip b = g H(A) - s(A, f, direction) (the step map's reach minus its step,
///    direction dependent through z_ba), after the edge it catches up along a smooth (raised
///    cosine) profile, so the error is split around zero instead of a one-sided jump and the
///    slider's 600 Hz contact mode is not rung by a velocity step. The feedback (integral on the
///    measured error minus the error this plan expects) corrects only the residual; a running
///    estimate of the backslip (per direction) is updated from each edge's measured outcome.
///  - Step-scan blending: stepping is nothing but scanning with edges, so there is no mode switch.
///    Around zero velocity and at the end of a move no edge is needed while the PE has range left;
///    when one is, it is the same edge. The final position is held by the same scanning loop.
/// update() and next_drive() never allocate; the model and the step map are fixed at construction.

#include <array>
#include <cstdint>

#include "microcobot/motion/backslip_estimate.h"
#include "microcobot/motion/catch_up.h"
#include "microcobot/motion/damping_band_pass.h"
#include "microcobot/motion/reference.h"
#include "microcobot/motion/step_map.h"
#include "microcobot/stickslip/drive_segment.h"
#include "microcobot/stickslip/prandtl_ishlinskii.h"

namespace mc::motion {

/// The gains (sprint_*, unload_V, edge_ready_V, lead_*, catchup_s, settle_s, ki_1_s, kp, backslip_gain,
/// damp_*, low_V, powerup_V) were chosen by scripts/tune_tracking.py on the tuning set of
/// `microcobot control validate --set tuning` only and are judged on its validation set
/// (docs/parameters.md, docs/benchmarks.md).
struct TrackingParams {
  double control_rate_Hz = 10000.0;  ///< rate of update()
  /// Voltage range the ramp uses; the edge spans it (the sawtooth amplitude A = high - low). A
  /// narrower edge rings the contact less (200 um/s trapezoid RMS 118 nm over 7.5-100 V, 81-85 nm
  /// over 30-100 V) but advances less per edge, so a fast or accelerating reference is followed
  /// over the wider sprint range below.
  double low_V = 31.62;
  double high_V = 100.0;
  /// The range's bottom while sprinting: the reference faster than sprint_velocity_m_s, or the
  /// axis behind it by more than sprint_lag_m (back to low_V once within half of it) [V].
  double sprint_low_V = 7.5;
  /// [m/s]: above the envelope's 800 um/s, so the sprint starts on the lag trigger: with the edge
  /// transients damped (damp_gain) that trigger can be as low as 0.42 um, so that the
  /// fast, strongly accelerating moves sprint early (docs/benchmarks.md).
  double sprint_velocity_m_s = 1191.0e-6;
  double sprint_lag_m = 422.8e-9;  ///< [m]
  /// Anticipation: the velocity trigger looks at the reference's speed this far ahead,
  /// |v| + |a| h while the reference speeds up (a v > 0), so that a strongly accelerating move
  /// sprints before the narrow edges fall behind rather than once the lag says they have. 0: off [s].
  double sprint_horizon_s = 0.0;
  /// An edge starts when the wanted ramp would pass this close to the end of the range [V].
  double guard_V = 0.5;
  /// ...and only when the drive is already within this much of that end: the ramp uses its range
  /// before an edge (an axis that fell behind catches up instead of stalling) [V].
  double edge_ready_V = 5.861;
  /// Unloading: right after the edge the voltage turns back by this much at the slew limit, which
  /// releases the contact's strain (|z| ~ z_ss after the slip) before it pulls the slider back;
  /// without it the slider recoils by ~1 um after a full-range edge (model, 100 V) [V]. For the
  /// low_V..high_V edge; a sprint edge unloads in proportion to its amplitude.
  double unload_V = 49.16;
  /// A shaped edge: the edge and its unloading in two halves, the second starting this long
  /// after the first, so that the halves' recoils cancel on the contact mode whose half period
  /// this is (a zero-vibration shaper; 305 us for the 1.64 kHz mode). Each half slips, so the
  /// edge's backslip is larger (docs/concepts/control.md, "The edge's dip"). 0: one edge [s].
  double edge_split_s = 0.0;
  /// Backslip of an unloaded edge assumed before the first edge is measured [m].
  double backslip_m = 0.0;
  /// At rest, an edge only when the wanted PE extension lies this far beyond the range [m].
  double edge_margin_m = 20e-9;
  /// Fraction of the predicted backslip the ramp leads by at the edge (0: none, 0.5: split).
  double lead_fraction = 0.9603;
  /// A further lead for the edge's transient dip (the slider slides back ~0.5 um while the edge and
  /// the unloading run, then returns) [m].
  double lead_m = 923.8e-9;
  /// The lead builds up over this last part of the PE's range before the edge [m].
  /// ...judged on the plan (anchor + reference travel + catch-up), not on the wanted extension
  /// with its feedback (false: on the wanted extension, for comparison; docs/benchmarks.md).
  bool lead_on_plan = true;
  double lead_window_m = 238.8e-9;
  /// After an edge: the catch-up of the remaining error takes this long (raised cosine) [s].
  double catchup_s = 0.6018e-3;
  /// After an edge: the integral is frozen while the slip rings [s].
  double settle_s = 0.5285e-3;
  double ki_1_s = 872.2;  ///< integral gain on the residual error [1/s]
  /// Proportional correction of the residual (fraction per tick). Negative on purpose: while the
  /// slider sticks, the edges leave it ringing on the contact at ~1.8 kHz (5-6 ticks a period),
  /// and the loop's delay (the sample, then the ramp's first-order hold: ~1.5 ticks) is close to
  /// a quarter of that period, so -|kp| e acts on the ringing as velocity feedback, i.e. damping;
  /// a positive gain is anti-damping and rings it (docs/errata.md; on the model, 200 um/s
  /// trapezoid with a 0-100 V edge: RMS 159 nm at 0, 128 nm at -0.3, 220 nm at +0.1). Beyond
  /// |kp| ~ 0.45 the loop rings (100 um/s: max 262 nm at -0.4, 721 nm at -0.5); damp_gain adds
  /// damping at the contact mode only.
  double kp = -0.2794;
  double backslip_gain = 0.402;  ///< update rate of the backslip estimate per edge (0: model only)
  /// Resonant damping of the contact's stiff mode: the edges leave the slider ringing
  /// on asperity b at sqrt(rho0_b / M_s) = 1.64 kHz (thesis Table 2.8, docs/concepts/stick-slip.md "two
  /// asperities"), with a damping ratio of rho1_b / (2 sqrt(rho0_b c_b M_s)) ~ 0.04 only. The
  /// measured position is band-passed around damp_Hz (RBJ biquad, peak gain 1, quality damp_q) and
  /// damp_gain times it, delayed by damp_lag_ticks (-1..1, linear between ticks, < 0 extrapolates: the
  /// phase), is added to the wanted PE extension; with the loop's ~1.5-tick delay (about a quarter period) a
  /// positive gain moves the PE against the ringing's velocity, i.e. damps it, like kp's negative
  /// gain but without acting below or above the mode (200 um/s trapezoid, steady part: error
  /// peak-to-peak 554 nm without, 401 nm at gain 0.4, phase 0, lead on the plan). 0: off.
  double damp_gain = 0.4837;
  double damp_Hz = 1640.0;      ///< [Hz]
  double damp_q = 1.317;        ///< quality factor of the band-pass
  double damp_lag_ticks = 0.0;  ///< [ticks]
  /// Power-up ramp-in: the amplifier starts at 0 V, the bottom of the range, so a
  /// backward move's first edge would come at once, with no lead to split its dip (626 nm at
  /// 200 um/s). Instead the controller's first act after a reset below low_V is one edge that
  /// lifts the drive to powerup_V (mid-range: both directions then have ramp left to lead their
  /// first edge), overshooting by powerup_unload_V and turning back at the slew limit like every
  /// edge's unloading; the ramp then holds the position for powerup_settle_s, after which ready()
  /// reports true and a move may start. 0 V: off (the first edge spans the amplitude from 0 V).
  double powerup_V = 59.73;
  double powerup_unload_V = 30.0;  ///< [V]
  /// Ready once the ramp-in's edge (and any edge the hold takes after it: the fast rise drags the
  /// slider forward by up to ~1 um, which the hold catches up) is this long past and the filtered
  /// error is within powerup_ready_m; a move that starts before carries the rest.
  double powerup_settle_s = 6e-3;  ///< [s]
  double powerup_ready_m = 10e-9;  ///< [m]
  /// In position: |filtered error| below this with the reference at rest [m] (reported only).
  double in_position_m = 3e-9;
  double filter_s = 1e-3;  ///< time constant of the in-position filter [s]

  template <class V>
  void visit(V& v) {
    v("control_rate_Hz", control_rate_Hz);
    v("low_V", low_V);
    v("high_V", high_V);
    v("sprint_low_V", sprint_low_V);
    v("sprint_velocity_m_s", sprint_velocity_m_s);
    v("sprint_lag_m", sprint_lag_m);
    v("sprint_horizon_s", sprint_horizon_s);
    v("guard_V", guard_V);
    v("edge_ready_V", edge_ready_V);
    v("unload_V", unload_V);
    v("edge_split_s", edge_split_s);
    v("backslip_m", backslip_m);
    v("edge_margin_m", edge_margin_m);
    v("lead_fraction", lead_fraction);
    v("lead_m", lead_m);
    v("lead_window_m", lead_window_m);
    v("lead_on_plan", lead_on_plan);
    v("catchup_s", catchup_s);
    v("settle_s", settle_s);
    v("ki_1_s", ki_1_s);
    v("kp", kp);
    v("backslip_gain", backslip_gain);
    v("damp_gain", damp_gain);
    v("damp_Hz", damp_Hz);
    v("damp_q", damp_q);
    v("damp_lag_ticks", damp_lag_ticks);
    v("powerup_V", powerup_V);
    v("powerup_unload_V", powerup_unload_V);
    v("powerup_settle_s", powerup_settle_s);
    v("powerup_ready_m", powerup_ready_m);
    v("in_position_m", in_position_m);
    v("filter_s", filter_s);
  }
  void validate() const;
};

/// The sawtooth operating point that the model's z_ba(A, f, direction) sees (thesis §2.7).
struct OperatingPoint {
  double amplitude_V = 0.0;
  double frequency_Hz = 1000.0;
  stickslip::Direction direction = stickslip::Direction::kForward;
};

class TrackingController {
 public:
  /// `model` gives the PE gain, the hysteresis and the drive limits; `map` the step lengths (it
  /// must outlive the controller). Allocates (the hysteresis observer) here only.
  TrackingController(const TrackingParams& p, const stickslip::StickSlipParams& model, const StepMap& map);

  /// Starts from the measured position `x_m` with the drive at `u_V` (the PE's present voltage).
  void reset(double x_m, double u_V = 0.0) noexcept;
  /// The reference for the next update() (position, velocity, acceleration). Never allocates.
  void set_reference(const ReferenceSample& r) noexcept { ref_ = r; }
  /// One control tick on the measured position. Never allocates.
  void update(double measured_position_m) noexcept;
  /// The drive over the actuator step `dt_s`: the ramp (linear between ticks) or the edge at the
  /// slew limit, with a corner where the edge ends inside the step. Never allocates.
  stickslip::DriveSegment next_drive(double dt_s) noexcept;
  /// 0 V at once; the axis stays stopped until reset().
  void emergency_stop() noexcept;

  const OperatingPoint& operating_point() const noexcept { return op_; }
  double voltage_V() const noexcept { return u_; }
  /// Edges (steps) since construction, and of them those taken forward.
  std::int64_t edges() const noexcept { return edges_; }
  bool in_edge() const noexcept { return edge_; }
  /// Edges span the sprint range (sprint_low_V..high_V).
  bool sprinting() const noexcept { return sprint_; }
  bool stopped() const noexcept { return stopped_; }
  /// False from a reset below low_V until the power-up ramp-in has settled (see powerup_V): a
  /// reference should rest until then. Always true with powerup_V = 0.
  bool ready() const noexcept { return !powerup_.under_way; }
  /// |filtered error| < in_position_m with the reference at rest.
  bool in_position() const noexcept { return in_position_; }
  /// Present backslip estimate [m] per direction (model prediction refined by the edges).
  double backslip_m(stickslip::Direction d) const noexcept {
    return backslip_.of(d == stickslip::Direction::kForward);
  }
  /// Model prediction of the backslip of an edge of the full range at `frequency_Hz`:
  /// g H(A) - s(A, f, direction) from the step map [m].
  double predicted_backslip_m(double frequency_Hz, stickslip::Direction d) const noexcept;
  /// The PE's static displacement g H(U) from the present hysteresis state at voltage U [m].
  double pe_displacement_m(double u_V) const noexcept;
  /// U that makes g H(U) = `y_m` from the present hysteresis state (exact PI inverse) [V].
  double inverse_V(double y_m) const noexcept;
  const TrackingParams& params() const noexcept { return p_; }

 private:
  void start_edge(double x, bool forward) noexcept;
  void start_ramp_in(double x) noexcept;
  /// The legs of an edge from the present voltage to `target_V`, turning back by `unload_V`, in
  /// two halves `split_s` apart when split_s > 0.
  void plan_edge(double target_V, double unload_V, double split_s) noexcept;
  void anchor_after_edge() noexcept;
  double flyback_frequency_Hz(double v_m_s, double amplitude_V, stickslip::Direction d) const noexcept;

  // Fixed at construction.
  const TrackingParams p_;
  const StepMap& map_;
  const stickslip::PiParams pi_;
  const double g_, slew_, min_V_, dt_c_;

  // State.
  stickslip::PiState obs_;
  OperatingPoint op_;
  ReferenceSample ref_;
  double u_ = 0.0, u_cmd_ = 0.0, u_prev_cmd_ = 0.0;
  double y_anchor_ = 0.0, r_anchor_ = 0.0, integ_ = 0.0;
  CatchUp catch_up_;  ///< the plan's offset after an edge
  double since_edge_s_ = 1.0;
  BackslipEstimate backslip_;  ///< per direction, refined by each edge's outcome
  double x_filt_ = 0.0;
  /// The edge under way, as legs run one after the other: each to its voltage at the slew limit,
  /// or held for hold_s (> 0). An edge, its unloading, and with edge_split_s the same in halves.
  struct EdgeLeg {
    double to_V = 0.0, hold_s = 0.0;
  };
  std::array<EdgeLeg, 5> legs_{};
  int leg_ = 0, leg_count_ = 0;
  /// The ramp's lowest voltage: low_V, or below it after power-up until the ramp rises through low_V
  /// or a forward edge lands there.
  double floor_V_ = 0.0;
  bool edge_ = false, pending_anchor_ = false;
  bool stopped_ = false, in_position_ = false, have_x_ = false, sprint_ = false;
  /// The power-up (see powerup_V): under way until ready(); its ramp-in edge started, and running
  /// with its catch-up; the time settled since.
  struct PowerUp {
    bool under_way = false, ramp_in = false, ramp_in_started = false;
    double settled_s = 0.0;
  } powerup_;
  std::int64_t edges_ = 0;
  DampingBandPass band_pass_;  ///< resonant damping: the measured position's band-pass
};

}  // namespace mc::motion
