#pragma once
/// @file
/// The scripted operator of the main scenario: a watchmaker doing a pick-and-place through the
/// platform. It looks through the microscope (the true positions of the finger tips and of the
/// part, at the operator rate), moves the haptic handle, presses the deadman and the clutch,
/// turns the Z thumb wheel and pinches the TéléTweez, as a person would:
///
///   approach  bring the open gripper over the part (XY), then down to the grasp height;
///   grasp     pinch the TéléTweez, closing further until the grip is felt (the rendered
///             finger force), then hold the pinch;
///   lift      raise the part off the substrate (the grip must beat its adhesion);
///   transport move it to the target at the transport speed, clutching (indexing) whenever
///             the hand nears the edge of the Pantograph's workspace;
///   place     slow down near the target until the part is within the microscope's
///             resolution, set it down, open the tweezers (adhesion to the substrate keeps
///             the part in place), and retract.
///
/// Heights are the finger tips' above the part's bottom: with a hole at the target, the part is
/// grasped higher by the hole's depth, so that the tips stay above the substrate once it is in.
/// Each phase has a time limit; an operator who cannot finish a phase gives up (gave_up(),
/// give_up_reason()). Done or given up, the operator lets go of the deadman and the controls.
/// act() is real-time safe (it runs as a loop task).

#include <string_view>

#include "microcobot/platform/platform.h"
#include "microcobot/runtime/fixed_rate_loop.h"

namespace mc::cell {

struct PickPlaceOperatorParams {
  double transport_speed_m_s = 100e-6;  ///< slave speed while transporting
  double approach_speed_m_s = 100e-6;   ///< slave speed of the other XY moves
  double fine_speed_m_s = 10e-6;        ///< slave speed within fine_distance_m of a goal
  double fine_distance_m = 20e-6;       ///< within this of a goal the operator slows to fine_speed_m_s
  double visual_gain_1_s = 4.0;         ///< how fast the operator corrects a seen error
  double resolution_m = 1e-6;           ///< what the operator can see through the microscope
  double jog_speed_m_s = 200e-6;        ///< Z thumb wheel speed
  double grasp_z_m = 100e-6;            ///< finger-tip height for grasping (part is 300 um tall)
  double carry_z_m = 400e-6;            ///< finger-tip height while transporting
  double set_down_press_m = 5e-6;       ///< how far below the grasp height to set down
  double retract_z_m = 600e-6;          ///< finger-tip height after the release (clear of the part)
  double pinch_m = 5e-3;                ///< the fingers close the TéléTweez levers by this much ...
  double pinch_s = 0.5;                 ///< ... in this time (and open them as fast)
  double max_pinch_m = 10e-3;           ///< and never further (the levers' travel)
  double felt_grip_N = 0.05;            ///< finger force that tells the part is held
  double hand_limit_m = 35e-3;          ///< clutch when the hand gets this far from the centre
  double hand_return_speed_m_s = 0.2;   ///< hand speed while clutched
  double phase_timeout_s = 30.0;        ///< give up a phase after this long

  template <class V>
  void visit(V& v) {
    v("transport_speed_m_s", transport_speed_m_s);
    v("approach_speed_m_s", approach_speed_m_s);
    v("fine_speed_m_s", fine_speed_m_s);
    v("fine_distance_m", fine_distance_m);
    v("visual_gain_1_s", visual_gain_1_s);
    v("resolution_m", resolution_m);
    v("jog_speed_m_s", jog_speed_m_s);
    v("grasp_z_m", grasp_z_m);
    v("carry_z_m", carry_z_m);
    v("set_down_press_m", set_down_press_m);
    v("retract_z_m", retract_z_m);
    v("pinch_m", pinch_m);
    v("pinch_s", pinch_s);
    v("max_pinch_m", max_pinch_m);
    v("felt_grip_N", felt_grip_N);
    v("hand_limit_m", hand_limit_m);
    v("hand_return_speed_m_s", hand_return_speed_m_s);
    v("phase_timeout_s", phase_timeout_s);
  }
  void validate() const;
};

class PickPlaceOperator {
 public:
  enum class Phase {
    kApproach,
    kDescend,
    kPinch,
    kLift,
    kTransport,
    kSetDown,
    kRelease,
    kRetract,
    kDone,
    kGaveUp
  };
  static std::string_view name(Phase p);

  PickPlaceOperator(platform::Platform& platform, const PickPlaceOperatorParams& params);
  /// One operator tick (the platform's operator task). Real-time safe.
  void act(const runtime::TickInfo& tick) noexcept;

  Phase phase() const { return phase_; }
  bool done() const { return phase_ == Phase::kDone; }
  bool gave_up() const { return phase_ == Phase::kGaveUp; }
  /// The phase the operator gave up in (meaningful when gave_up()).
  Phase failed_phase() const { return failed_phase_; }
  /// Why an operator gives up in `phase`, in a person's words.
  static std::string_view give_up_reason(Phase phase);
  /// Time each phase started [s] (NaN if not reached), indexed by Phase.
  double phase_start_s(Phase p) const { return started_[static_cast<int>(p)]; }
  int clutches() const { return clutches_; }

 private:
  void enter(Phase p, double t) noexcept;
  /// Moves the hand so that the slave's point `seen` goes to `goal` (XY) at most at `speed`;
  /// clutches near the workspace edge. Returns true once within the resolution.
  bool steer(const Eigen::Vector2d& seen, const Eigen::Vector2d& goal, double speed, double dt) noexcept;
  double jog_to(double z_seen, double z_goal) const noexcept;
  /// Lets go of the deadman, the clutch and the jog wheel (done or given up).
  void let_go() noexcept;

  platform::Platform& platform_;
  const devices::SimulatedDevices& sim_;  ///< the operator acts on the simulated masters' hands
  PickPlaceOperatorParams p_;
  double motion_scale_;
  double lift_m_ = 0.0;  ///< the hole's depth: grasp and carry heights are raised by it
  Phase phase_ = Phase::kApproach;
  Phase failed_phase_ = Phase::kApproach;
  double phase_t0_ = 0.0;
  double started_[10];
  devices::OperatorHand hand_;
  bool clutching_ = false;
  Eigen::Vector2d clutch_aim_ = Eigen::Vector2d::Zero();
  int clutches_ = 0;
  double pinch_ = 0.0;  ///< present aim of the fingers [m]
  double settled_s_ = 0.0;
};

}  // namespace mc::cell
