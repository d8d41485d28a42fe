#pragma once
/// @file
/// Iterative learning control (ILC) for a reference that is run again and again (the assembly
/// cell's repeated transports): a feedforward learned from trial to trial and added to the
/// tracking controller's reference position (tracking_controller.h).
///
/// The update is the classic first-order ILC law (Bristow, Tharayil & Alleyne, "A survey of
/// iterative learning control", IEEE Control Systems Magazine 26(3):96-114, 2006, eq. (4) and
/// §"Convergence"; Arimoto, Kawamura & Miyazaki, J. Robotic Systems 1(2), 1984, for the origin):
///
///   u_{j+1}(i) = (1 - alpha) Q[ u_j(i) - gamma e_j(i + lambda) ]
///
/// with u_j the correction of trial j at tick i (metres, added to the reference's position),
/// e_j(i) = x_j(i) - r(i) the measured error one tick after tick i (the position the drive of
/// tick i produced), gamma the learning gain, lambda the lead in ticks (the loop's delay from the
/// plan to the measured position, so that L = -gamma z^lambda inverts the delay), Q a zero-phase
/// low-pass (a first-order filter run forward then backward over the finished trial: ILC may be
/// non-causal in i because a trial's whole error is known before the next trial) and alpha a
/// forgetting factor that bounds what noise and non-repeating errors can build up.
///
/// Monotonic convergence (Bristow et al. 2006, the sufficient condition in the frequency domain for
/// the l2 norm of the error of a long trial): with P the closed loop from the correction to the
/// error (e_j = P u_j + d, d the error without learning),
///
///   sup_w | Q(e^{jwT}) | (1 - alpha) | 1 - gamma e^{jw lambda T} P(e^{jwT}) | < 1.
///
/// While the slider sticks to the PE the tracking controller puts the slider on its plan with a
/// pure delay of d ~ 1.5 ticks (P ~ e^{-jw d T}), so the condition reads
/// |1 - gamma e^{jw (lambda - d) T}| < 1 / |Q|, i.e. 0 < gamma < 2 cos(w (lambda - d) T) wherever Q
/// passes; Q's cutoff keeps the mismatched phase w |lambda - d| T well under 90 deg (1 kHz,
/// |lambda - d| = 0.5 tick: 18 deg). The edges (the slip and its recoil) are not on this P: their
/// error repeats only as far as their timing does, which Q and alpha keep from accumulating.
///
/// Indexed by time along the reference (the tick since the reference's clock started), not by
/// position: the reference is the same function of time on every trial, a time index covers rests
/// and reversals (a position index would merge a sine's outward and return passes and the moments
/// before and after a rest), and the controller's delay, which L inverts, is a delay in time.
///
/// Real time: the buffers are allocated at construction; begin_trial(), feedforward(), record()
/// and learn() never allocate. The correction belongs to one reference and one axis: a trial with
/// another identity (reference_identity(), combined with the axis' own) starts from zero.

#include <cstdint>
#include <vector>

namespace mc::motion {

/// The learning law's parameters. Chosen on the tuning set's 1-D cases only (seed 15:
/// `microcobot control learn --set tuning --references 30`, a grid of gamma 0.3-1, Q 5-200 Hz,
/// alpha 0-0.05 at lambda 2; docs/parameters.md) and judged on the validation set (seed 31).
struct LearningParams {
  double control_rate_Hz = 10000.0;  ///< rate of feedforward()/record() [Hz]
  double learning_gain = 0.6;        ///< gamma: fraction of the error corrected per trial
  /// lambda: the error that tick i's correction acts on comes this many ticks later (the loop's
  /// delay, sample then the ramp's hold: ~1.5 ticks) [ticks].
  int lead_ticks = 2;
  /// Q's corner: first-order low-pass run forward and backward (zero phase) [Hz]; 0: no filter
  /// (Q = 1). Low, because only the slow part of the error repeats from trial to trial: the edges'
  /// dips come at ticks that differ between trials (docs/concepts/control.md).
  double q_cutoff_Hz = 20.0;
  double forgetting = 0.05;        ///< alpha in [0, 1): the correction kept is (1 - alpha)
  double max_correction_m = 2e-6;  ///< |u| is clamped to this [m]

  template <class V>
  void visit(V& v) {
    v("control_rate_Hz", control_rate_Hz);
    v("learning_gain", learning_gain);
    v("lead_ticks", lead_ticks);
    v("q_cutoff_Hz", q_cutoff_Hz);
    v("forgetting", forgetting);
    v("max_correction_m", max_correction_m);
  }
  void validate() const;
};

/// FNV-1a over a reference's samples (positions quantised to 1 pm): the identity of a reference,
/// so that a correction is never applied to another one. Never allocates.
class ReferenceHash {
 public:
  void add(double x_m) noexcept;
  /// Mixes in another identity (e.g. the axis').
  void add_id(std::uint64_t id) noexcept;
  std::uint64_t value() const noexcept { return h_; }

 private:
  std::uint64_t h_ = 1469598103934665603ULL;
};

class IterativeLearning {
 public:
  /// Room for references of up to `max_ticks` control ticks; allocates here only.
  IterativeLearning(const LearningParams& p, long max_ticks);

  /// Forgets the correction (the user's reset; also on a new reference).
  void reset() noexcept;
  /// Starts a trial of the reference (and axis) with identity `id`: a new identity forgets the
  /// correction learned on the previous one. Never allocates.
  void begin_trial(std::uint64_t id) noexcept;
  /// The correction for tick `i` of the reference [m] (0 beyond what was learned). Never allocates.
  double feedforward(long i) const noexcept {
    return i >= 0 && i < learned_ticks_ ? u_[static_cast<std::size_t>(i)] : 0.0;
  }
  /// The error e(i) = x - r measured after tick `i`'s drive [m]; ticks beyond max_ticks are
  /// dropped (counted). Never allocates.
  void record(long i, double error_m) noexcept;
  /// End of the trial: u <- (1 - alpha) Q[u - gamma e(. + lambda)] over the ticks recorded. Never
  /// allocates.
  void learn() noexcept;

  const LearningParams& params() const noexcept { return p_; }
  long max_ticks() const noexcept { return static_cast<long>(u_.size()); }
  /// Trials learned from since the last reset.
  int trials() const noexcept { return trials_; }
  std::uint64_t identity() const noexcept { return id_; }
  bool has_identity() const noexcept { return has_id_; }
  /// Errors dropped since the trial began (the trial outran max_ticks).
  long dropped() const noexcept { return dropped_; }
  /// The present correction over the ticks learned.
  const std::vector<double>& correction() const noexcept { return u_; }
  long learned_ticks() const noexcept { return learned_ticks_; }
  /// The errors recorded in the present (or last) trial, over recorded_ticks().
  const std::vector<double>& errors() const noexcept { return e_; }
  long recorded_ticks() const noexcept { return recorded_ticks_; }

 private:
  const LearningParams p_;
  const double q_pole_;  ///< first-order low-pass: y += (1 - q_pole) (x - y); 0: Q = 1

  std::vector<double> u_, e_;  ///< the correction, this trial's errors
  long learned_ticks_ = 0, recorded_ticks_ = 0, dropped_ = 0;
  int trials_ = 0;
  std::uint64_t id_ = 0;
  bool has_id_ = false;
};

}  // namespace mc::motion
