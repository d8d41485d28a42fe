#pragma once
/// @file
/// The 6-DOF parallel stick-slip positioner under pose control (thesis: T. Lu, "Design and
/// Realization of a Desktop Micro-manipulation Cobotic Platform", PhD thesis, Université Pierre et
/// Marie Curie, 2016, §2.3, Fig. 2.4; structure: parallel_geometry.h; equations:
/// docs/concepts/parallel-positioner.md, "Pose control").
///
/// Each of the six leg coordinates q_k is one SLC-1720 stick-slip axis of the project's model: one
/// ActuatorModel (immutable, shared), six ActuatorStates, six sensors (independent noise streams:
/// seed + k) and six trajectory-tracking controllers (tracking_controller.h). The slider position
/// of axis k is q_k (0 at home, mid-stroke), so the platform steps, slips and drifts as its legs do.
///
/// Control is in the legs' space: a move's reference pose T(s(t)) (pose_trajectory.h) gives
/// q_ref = IK(T) and its derivatives each tick, and each leg tracks its own q_ref; all legs follow
/// the same s(t). The measured pose is FK of the six sensors' readings (Newton from the previous
/// measured pose), every tick; the true pose FK of the six true slider positions (from the last
/// true pose), computed when asked (true_pose()): the simulation's truth, which no control needs,
/// so a loop that reads it at its telemetry rate pays one FK there instead of one a tick. Both are
/// what the platform does, not what it was told.
///
/// A coupling streams poses instead (follow()): the reference pursues the latest target within the
/// move limits and the workspace, tick by tick.
///
/// Modes of a leg: tracking (moving or holding its reference), or stepping open loop
/// (step_leg(): a sawtooth of N periods at full amplitude, recovery), after which it holds where
/// it landed. stop() holds every leg where it is. A diverged model or a failed FK stops every
/// axis at 0 V (fault()); so does emergency_stop() (halted()), the platform's safe state, until
/// rearm(). tick() never allocates.

#include <array>
#include <cstdint>
#include <memory>
#include <string>

#include "microcobot/motion/parallel_kinematics.h"
#include "microcobot/motion/pose_trajectory.h"
#include "microcobot/motion/position_sensor.h"
#include "microcobot/motion/sawtooth_generator.h"
#include "microcobot/motion/step_map.h"
#include "microcobot/motion/tracking_controller.h"
#include "microcobot/stickslip/actuator.h"

namespace mc::motion {

inline constexpr int kParallelAxes = 2 * kParallelLegs;
/// How far short of a stroke's end a followed reference stops: the tracking's error (under a
/// micrometre) and the sensor's noise keep the leg's reading inside the stroke, which the forward
/// kinematics requires (a reading beyond it faults the stage).
inline constexpr double kFollowStrokeMargin_m = 10e-6;
/// A followed target is reached within this (m, rad): rounding, not a tolerance of the control.
inline constexpr double kFollowArrival = 1e-12;

struct ParallelStageParams {
  ParallelGeometryParams geometry;
  TrackingParams tracking;
  PositionSensorParams sensor;
  PoseMoveLimits move;

  template <class V>
  void visit(V& v) {
    v("geometry", geometry);
    v("tracking", tracking);
    v("sensor", sensor);
    v("move", move);
  }
  void validate() const {
    geometry.validate();
    tracking.validate();
    sensor.validate();
    move.validate();
  }
};

/// The two positioners of a leg's carriage.
enum class LegPositioner { kRadial = 0, kTangential = 1 };
LegPositioner parse_leg_positioner(const std::string& name);  ///< "radial" | "tangential", else UsageError

struct LegAxisStatus {
  double position_m = 0.0;   ///< true slider position (simulation)
  double measured_m = 0.0;   ///< last sensor reading
  double reference_m = 0.0;  ///< the tracker's reference
  double voltage_V = 0.0;
  bool stepping = false;  ///< open-loop stepping (step_leg)
};

class ParallelStage {
 public:
  /// `model` and `map` must outlive the stage. The model's stroke must cover the geometry's.
  ParallelStage(const stickslip::ActuatorModel& model, const StepMap& map, const ParallelStageParams& p = {});

  /// Places the platform at rest at `T` (simulation set-up): each slider at IK(T), the trackers
  /// powering up to hold there. Throws PoseUnreachable for a pose out of the workspace.
  void place(const PlatformTransform& T);
  /// Starts a straight move in pose space from the pose the legs hold to `goal`, under the
  /// params' limits; it runs once every tracker is ready (powered up). Refused before anything
  /// moves (mc::InvalidInput with a one-line reason: check_move) when the goal or a pose along
  /// the line is unreachable, singular, beyond a stroke or joint limit or not finite, when a leg
  /// is stepping open loop, or after a fault. Returns the check (samples, peak leg speed).
  MoveCheck move_to(const PlatformTransform& goal);
  /// The same with other limits for this move.
  MoveCheck move_to(const PlatformTransform& goal, const PoseMoveLimits& limits);
  /// The real-time half of move_to(), for a loop whose moves are planned on another thread: starts
  /// `checked`, a trajectory that check_move() passed, whose start is the pose the legs hold
  /// (reference_pose() while no move runs). False, and nothing changes, while a move runs or a leg
  /// steps, after a fault or an emergency stop, or when the trajectory starts elsewhere than the held pose
  /// (by more than 1 nm or 1 nrad in any entry of R or d). Never allocates (the trajectory's storage is made
  /// by the constructor), never throws.
  bool start_move(const PoseTrajectory& checked) noexcept;
  /// Follows `target`, a pose streamed by a coupling (the console's jog, a master's position): the
  /// reference pose goes toward it, its translation and its rotation (about the platform's origin,
  /// in {H}) each along the shortest way at most at `limits`' speeds and accelerations, braking to
  /// stop on it; the legs track IK of that reference and their speeds stay within
  /// max_leg_speed_m_s. It never leaves the workspace: a step to a pose that is not reachable
  /// (reach_of: a stroke, a joint limit, a singularity; a leg within kFollowStrokeMargin_m of its
  /// stroke's end) is not taken and the reference stops where it is, follow_blocked() until a step
  /// is reachable again. A new target replaces the last at
  /// any time. Refused (false, nothing changes) while a move runs or a leg steps, after a fault or
  /// an emergency stop, or for a target or limits that are not finite. stop() ends it: every leg
  /// holds where it is measured. Never allocates.
  bool follow(const PlatformTransform& target, const PoseMoveLimits& limits) noexcept;
  bool follow(const PlatformTransform& target) noexcept { return follow(target, p_.move); }
  bool following() const noexcept { return following_; }
  bool follow_blocked() const noexcept { return follow_blocked_; }
  /// Open-loop stepping of one positioner (recovery): `steps` sawtooth periods at the full
  /// amplitude and `frequency_Hz`, forward for steps > 0; the leg then holds where it landed. Any
  /// move is stopped first (the other legs hold where they are).
  void step_leg(int leg, LegPositioner positioner, int steps, double frequency_Hz);
  /// step_leg()'s checks of its arguments: throws mc::InvalidParams.
  static void check_step_leg(int leg, int steps, double frequency_Hz);
  /// Ends any move: every tracking leg holds where it is measured now; a stepping leg finishes
  /// its period (U back at 0 V, no abrupt edge) and holds. Holding already (no move, no leg
  /// stepping), nothing changes: the held pose stays exact. Never allocates.
  void stop() noexcept;
  /// Every leg to 0 V at once (its tracker stopped, any stepping halted), no move: the safe state
  /// a platform's fault or e-stop asks for. The physics runs on (tick()) and the poses are still
  /// measured. Idempotent, never allocates; held until rearm().
  void emergency_stop() noexcept;
  /// After emergency_stop() (or at power-up): every tracker restarts where its sensor reads and the
  /// legs hold there, the reference pose FK of those readings (before the first tick: the pose
  /// place() gave, exactly). Throws mc::InvalidInput after a
  /// fault (a diverged model, legs where no pose of the positioner is): that stays latched.
  void rearm();
  /// One control period (1 / tracking.control_rate_Hz). Never allocates.
  void tick() noexcept;

  /// A move under way, or a followed reference still moving.
  bool moving() const noexcept { return moving_ || (following_ && !follow_still_); }
  /// Every leg tracking, no move under way or target followed, and every tracker in position.
  bool at_rest() const noexcept;
  bool fault() const noexcept { return fault_; }
  /// Stopped at 0 V by emergency_stop() (or a fault) until rearm().
  bool halted() const noexcept { return halted_ || fault_; }
  double time_s() const noexcept { return t_; }
  double tick_s() const noexcept { return static_cast<double>(ratio_) * model_.dt_s(); }
  /// Time into the present (or last) move [s]; 0 until every tracker is ready.
  double move_time_s() const noexcept { return t_move_; }

  const PlatformTransform& measured_pose() const noexcept { return measured_T_; }
  /// FK of the true slider positions, from the last true pose (computed on the first call after a
  /// tick; the last one where they fit no pose). Never allocates unless that FK fails.
  const PlatformTransform& true_pose() const noexcept;
  /// The pose the legs are told to be at (the move's T(s(t)), or the held pose).
  const PlatformTransform& reference_pose() const noexcept { return ref_T_; }
  /// The present (or last) move; only valid after a move_to().
  const PoseTrajectory& trajectory() const noexcept { return *traj_; }
  bool has_trajectory() const noexcept { return traj_ != nullptr; }
  LegAxisStatus status(int axis) const noexcept;
  const ParallelKinematics& kinematics() const noexcept { return kin_; }
  const ParallelStageParams& params() const noexcept { return p_; }

 private:
  struct LegAxis {
    stickslip::ActuatorState state;
    PositionSensor sensor;
    std::unique_ptr<TrackingController> ctrl;
    SawtoothGenerator gen;
    double measured = 0.0;
    double hold = 0.0;                  ///< the reference while holding
    std::int64_t periods_at_start = 0;  ///< the generator's periods when step_leg() started
    int steps_left = 0;                 ///< periods to run (0: end with the present one)
    bool stepping = false;
  };
  void hold_here(LegAxis& ax) noexcept;
  /// One tick of follow(): the reference one step toward the target (the legs' in ref_).
  void advance_follow() noexcept;
  void update_poses() noexcept;
  void safe_stop() noexcept;

  const stickslip::ActuatorModel& model_;
  ParallelStageParams p_;
  ParallelKinematics kin_;
  std::array<LegAxis, kParallelAxes> axes_;
  std::unique_ptr<PoseTrajectory> traj_;
  std::unique_ptr<PoseTrajectory> spare_;  ///< start_move()'s storage until traj_ exists
  LegReference ref_;
  PlatformTransform measured_T_, ref_T_;
  mutable PlatformTransform true_T_;
  mutable bool true_stale_ = false;  ///< the sliders moved since true_T_ was computed
  int ratio_ = 1;
  double t_ = 0.0, t_move_ = 0.0;
  bool moving_ = false, fault_ = false, halted_ = false;
  // follow(): the target, its limits, the reference's velocity (translation [m/s], rotation in
  // {H} [rad/s]).
  PlatformTransform follow_target_;
  PoseMoveLimits follow_limits_;
  Eigen::Vector3d follow_v_ = Eigen::Vector3d::Zero(), follow_w_ = Eigen::Vector3d::Zero();
  bool following_ = false, follow_blocked_ = false, follow_still_ = true;
};

}  // namespace mc::motion
