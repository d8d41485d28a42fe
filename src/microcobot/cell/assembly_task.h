#pragma once
/// @file
/// The automatic pick-and-insert of one pin: a sequence of
/// steps with behaviour-tree semantics, run by the robot while the operator supervises, pauses,
/// confirms, takes over and hands back (the supervisor: task_supervisor.h; the camera's looks:
/// task_looks.h; the insertion's search: insertion_search.h). Like a ros2_control controller it is a pure
/// object: each tick it reads the slave's sensors (TaskSensors: measured tip position, contact and grip
/// forces, opening) and returns the console input the platform follows (teleop::ConsoleInput:
/// a straight move to a goal at a speed, a gripper opening, the deadman), so that the platform's
/// own limits (teleop/safety_limits.h: grip, contact, floor) apply to it as to any operator.
///
///   approach   over the pin's nominal slot, the finger tips clear of its top (turning the fingers
///              to the pin's nominal orientation on the way, at that height, when align is automatic)
///   align      the fingers' flats square with the pin's faces: the rotary axis to the pin's nominal
///              yaw, modulo 90 deg, nearest to where it is (motion/rotary_axis.h); the squeeze of
///              the grasp takes out the pin's error in its slot
///   descend    to the grasp height: the tips `grip_above_m` above a full bore's depth
///   grasp      close until the grip force reaches `grip_force_N` (the closing fingers centre
///              the pin along x; its slot error along y stays unknown)
///   lift       the pin's bottom `clearance_height_m` above the substrate
///   transport  over the bore (turning the pin towards its bore's orientation on the way, when
///              rotate is automatic)
///   rotate     the pin's faces square with the bore's: the rotary axis to the bore's yaw modulo
///              90 deg (the pin turns with the fingers about the tips' centre, over the bore)
///   insert     a flat part onto a flat seat (AssemblyGoal::flat_seat): down at insert_speed_m_s
///              until the contact force exceeds contact_threshold_N, which is the seat: placed.
///              A pin into its bore: force-guarded: down at `insert_speed_m_s` until the contact force
///              exceeds `contact_threshold_N`. Reached near the bore's depth: inserted. Reached at the
///              surface: jammed on the rim; up by `search_retreat_m`, over to the next point of
///              the search along the fingers' y, the pin's unknown direction in them (0, +s, -s,
///              +2s, ... with s = search_step_factor x the bore's
///              radial clearance; a pin fits when |dy| <= clearance), down again; beyond
///              `search_range_m`: failed
///   release    open the fingers (the substrate's adhesion keeps the pin in its bore), then the
///              goal's release strategy (microworld/release.h): shake, the gripper's burst for
///              shake_s; roll, the fingers turned by roll_rad with the part on its seat
///   retract    up clear of the pin
///   verify     the stage still, the cell's vision looks at the pin: down in its bore (its centre
///              within verify_tolerance_m of the inserted height, and within the bore's clearance
///              of its axis), or the task fails: a pin that stuck to a finger and came up with
///              it is not a success the task reports. Without vision (TaskSensors::part_m not
///              finite, e.g. the live console) the insertion's contact at the bore's depth stands
///
/// Looks (set_looks(true): the cell has a camera, cell_camera.h): the task holds while the camera
/// looks (status awaiting look), and see() hands it what was seen:
///   slot    before the approach moves: the pin's position and yaw in its slot replace the slot's
///           nominal ones (the grasp then centres the pin along the fingers' y too);
///   bore    before the transport moves (a pin's bore, not a flat seat): the bore's position seen
///           replaces its drawing's (the plate's errors: AssemblyBatchParams::bore_error_m);
///   held    at the insertion's start: the pin's offset along the fingers' y, seen over the bore;
///           the descent aims the pin, not the tool point, at the bore's axis (the search goes on
///           around that point if it still jams);
///   align   instead of held, with the visual servo (set_looks(true, true)): at the insertion's
///           start the pin and its bore seen from one camera pose, the error between them; the tool
///           moves by minus that error (at the carrying height) and the task looks again, until
///           the servo says converged or align_max_looks looks were taken (the last error is
///           still corrected); the descent then aims there (the search goes on around that point
///           if it still jams);
///   placed  in verify, the stage still: the camera's sighting is the verify's evidence (a pin not
///           seen down in its bore fails the task).
/// A look that finds nothing leaves the task as without a camera (nominal slot, search from the
/// tool point); in verify it fails the task.
///
/// Status: running; paused (pause(): the deadman is let go, so the coupling stops the stage's
/// target at the next tick and the stage holds; resume() goes on from where the stage is);
/// awaiting confirmation (a step whose autonomy is kConfirm waits before it starts, holding);
/// operator (take_over(), or a step whose autonomy is kManual: the task sends nothing and the
/// operator's master drives; hand_back() resumes the current step, re-planned from where the
/// stage is, or the next one when the operator says the step is done); assisted (a move whose
/// autonomy is kAssisted: the operator drives it under shared control, fixtures() guiding the
/// tool to the step's goal, a guide at its x, y and a height stop at its z
/// (teleop/virtual_fixtures.h), and the task goes on by itself once the tool has been within
/// position_tolerance_m of the goal for settle_s; hand_back() and skip() as for the operator);
/// succeeded; failed (a step's
/// timeout, a jam beyond the search). skip() leaves the current step for the next one, from where
/// the stage is (the operator judged it done or needless: e.g. a pin already in the fingers).
/// Every goal is a move from the coupling's current target at a bounded speed, so resuming,
/// handing back and skipping never jump. Never allocates; noexcept.

#include <array>
#include <cmath>
#include <limits>
#include <string_view>

#include <Eigen/Dense>

#include "microcobot/cell/insertion_search.h"
#include "microcobot/cell/task_looks.h"
#include "microcobot/cell/task_steps.h"
#include "microcobot/cell/task_supervisor.h"
#include "microcobot/microworld/release.h"
#include "microcobot/teleop/teleoperation.h"

namespace mc::cell {

struct AssemblyTaskParams {
  double travel_speed_m_s = 500e-6;      ///< XY moves at a safe height
  double z_speed_m_s = 200e-6;           ///< vertical moves
  double insert_speed_m_s = 20e-6;       ///< the force-guarded descent and the search's moves
  double clearance_height_m = 150e-6;    ///< tips above a pin's top, a carried pin above the plate
  double grip_above_m = 100e-6;          ///< grasp: tips this far above a full bore's depth
  double grip_force_N = 0.3e-3;          ///< grasp force (the platform's limit: world.grip_force_limit_N)
  double close_rate_m_s = 200e-6;        ///< the fingers' closing speed while grasping
  double contact_threshold_N = 60e-6;    ///< a contact force above this stops a descent
  double search_retreat_m = 20e-6;       ///< lift before moving to the next search point
  double search_step_factor = 1.5;       ///< search step / the bore's radial clearance (< 2)
  double search_range_m = 25e-6;         ///< the search's extent along y, either side
  double position_tolerance_m = 0.5e-6;  ///< a goal is reached within this ...
  double settle_s = 0.05;                ///< ... for this long
  double step_timeout_s = 20.0;          ///< a step that takes longer fails the task
  /// verify: the pin's centre seen within this of its inserted height (a pin on the rim sits
  /// 300 um higher, one stuck to a finger higher still; the vision is within 0.1 um)
  double verify_tolerance_m = 20e-6;
  /// align, rotate: the rotary axis' speed, and the yaw a turn ends within (0.5 mrad costs a
  /// 300 um pin 0.08 um of its play, whose least is 3 um).
  double rotate_speed_rad_s = 0.16;
  double yaw_tolerance_rad = 0.5e-3;
  /// release: how long the gripper's burst shakes the opened fingers (release.h, shake), and how
  /// far the fingers turn to roll their contact off the part (three times the world's 0.01 rad
  /// peel angle).
  double shake_s = 0.05;
  double roll_rad = 0.03;
  /// The visual servo's looks before an insertion at most (set_looks(true, true)): one converges
  /// unless the stage's moves are off (each look corrects what the last move missed).
  int align_max_looks = 5;

  template <class V>
  void visit(V& v) {
    v("travel_speed_m_s", travel_speed_m_s);
    v("z_speed_m_s", z_speed_m_s);
    v("insert_speed_m_s", insert_speed_m_s);
    v("clearance_height_m", clearance_height_m);
    v("grip_above_m", grip_above_m);
    v("grip_force_N", grip_force_N);
    v("close_rate_m_s", close_rate_m_s);
    v("contact_threshold_N", contact_threshold_N);
    v("search_retreat_m", search_retreat_m);
    v("search_step_factor", search_step_factor);
    v("search_range_m", search_range_m);
    v("position_tolerance_m", position_tolerance_m);
    v("settle_s", settle_s);
    v("step_timeout_s", step_timeout_s);
    v("verify_tolerance_m", verify_tolerance_m);
    v("rotate_speed_rad_s", rotate_speed_rad_s);
    v("yaw_tolerance_rad", yaw_tolerance_rad);
    v("shake_s", shake_s);
    v("roll_rad", roll_rad);
    v("align_max_looks", align_max_looks);
  }
  void validate() const;
};

/// What the cell is told about one insertion (assembly_batch.h's AssemblyJob), world frame.
struct AssemblyGoal {
  Eigen::Vector2d part_m{0, 0};    ///< the pin's nominal position
  Eigen::Vector2d target_m{0, 0};  ///< the bore
  double part_height_m = 600e-6;
  double hole_depth_m = 300e-6;  ///< the bore's depth (0 on a flat seat)
  /// The bore's radial clearance; on a flat seat, how far from its centre the part may rest.
  double clearance_m = 10e-6;
  bool flat_seat = false;  ///< the target is a flat seat, not a bore (a flat part is placed on it)
  /// How the fingers let go of the part (microworld/release.h; assembly_batch.h chooses per part).
  microworld::ReleaseStrategy release = microworld::ReleaseStrategy::kOpen;
  double open_m = 600e-6;       ///< the gripper fully open
  double part_yaw_rad = 0.0;    ///< the pin's nominal orientation in its slot (a square: modulo 90 deg)
  double target_yaw_rad = 0.0;  ///< the bore's orientation
  /// The rotary axis' travel (platform::Platform::yaw_min_rad, yaw_max_rad).
  double yaw_min_rad = -1.0, yaw_max_rad = 1.0;
  /// The forbidden regions round the scene's other parts (teleop/virtual_fixtures.h, keep-out;
  /// task_io.h's assembly_goal), in force with the shared control of an assisted step.
  std::array<teleop::FixtureSet::KeepOut, teleop::FixtureSet::kMaxKeepOuts> keep_outs{};
  int keep_out_count = 0;
  /// The tallest of the scene's other parts (0: none): the tips travel clear of its top and a
  /// carried part's bottom above it (safe and carrying heights).
  double tallest_neighbour_m = 0.0;
};

/// The fingers' yaw that squares them with a square turned by `square_yaw_rad` (modulo 90 deg):
/// the one nearest `from_rad` within [min_rad, max_rad] (the nearest to the travel when none is).
double square_yaw_goal(double square_yaw_rad, double from_rad, double min_rad, double max_rad) noexcept;

/// The slave's sensors at one tick, world frame.
struct TaskSensors {
  Eigen::Vector3d tip_m = Eigen::Vector3d::Zero();      ///< measured finger-tip position
  double yaw_rad = 0.0;                                 ///< measured fingers' yaw (the rotary axis)
  Eigen::Vector3d contact_N = Eigen::Vector3d::Zero();  ///< force on the gripper
  double grip_N = 0.0;
  double opening_m = 0.0;
  /// The gripper opening the coupling commands now (the operator's, while they drive); not finite:
  /// unknown. The task takes it over when it drives again, so that a hand-back never opens or
  /// closes the fingers by itself (a pin grasped by the operator stays grasped).
  double gripper_command_m = std::numeric_limits<double>::quiet_NaN();
  /// The part's centre as the cell's vision sees it; not finite: no vision (the verify step then
  /// takes the insertion's contact as its evidence).
  Eigen::Vector3d part_m = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
};

class AssemblyTask {
 public:
  using Step = TaskStep;
  static constexpr int kStepCount = kTaskStepCount;
  using Status = TaskStatus;
  using Look = TaskLook;
  using Sighting = TaskSighting;
  using Autonomy = StepAutonomy;
  /// The steps that may be assisted: the moves to a position (approach, descend, lift, transport,
  /// retract: a guide at the goal's x, y, along the path from where the step began for approach and
  /// transport, and a height stop at its z; done once the tool is there), the turns (align, rotate:
  /// the guide and the height stop hold the tool where it is to turn while the operator turns the
  /// dial into a yaw stop at the square's yaw nearest where the turn began; done once the fingers
  /// are within yaw_tolerance_rad of it),
  /// the grasp (the guide and stop hold the tool over the pin while the operator closes; done once
  /// the grip reaches grip_force_N), the insertion (the guide on the bore's axis and the funnel round
  /// its rim; judged at the first contact above contact_threshold_N: the pin half down in the
  /// bore, the release; on the rim, the robot's search goes on from there, status running) and the release
  /// (the guide holds; done once the fingers are open).
  static bool assistable(Step s) noexcept { return step_assistable(s); }

  /// The finger tips' height while grasping: grip_above_m over a full bore (the pin's bottom sits
  /// at the bore's depth below them), half a flat part's thickness on a flat seat.
  static double grasp_height_m(const AssemblyTaskParams& p, const AssemblyGoal& goal) noexcept;
  /// Throws mc::InvalidParams (parameters, goal).
  AssemblyTask(const AssemblyTaskParams& params, const AssemblyGoal& goal);
  /// The goal as the task now knows it (its looks replace the slot's and the bore's drawn places).
  const AssemblyGoal& goal() const noexcept { return goal_; }

  /// One tick of `dt_s`: the console input to hand the platform (drives() says whether to).
  const teleop::ConsoleInput& tick(const TaskSensors& s, double dt_s) noexcept;
  /// False while the operator drives (taken over, a manual or assisted step) and once finished.
  bool drives() const noexcept { return !operator_drives() && !finished(); }
  /// The operator's master drives the stage (taken over, a manual or an assisted step).
  bool operator_drives() const noexcept { return supervisor_.operator_drives(); }
  /// The shared control the current step wants on the coupling (world frame; level 0: none):
  /// while assisted, a guide at the step's goal x, y and a height stop at its z, at level 1.
  const teleop::FixtureSet& fixtures() const noexcept { return fixtures_; }
  bool finished() const noexcept { return supervisor_.finished(); }

  /// The cell has a camera: the task asks for its looks (header), the insertion aligned by the
  /// visual servo with `servo` (align looks) or by one held look. Before the first tick.
  void set_looks(bool on, bool servo = false) noexcept { looks_.enable(on, servo); }
  /// Align looks taken for the present insertion, and the aim they set (the tool's offset from the
  /// bore as seen).
  int align_looks() const noexcept { return looks_.align_looks(); }
  Eigen::Vector2d align_aim_m() const noexcept { return search_.aim_m(); }
  /// The look the task awaits (kNone unless the status is kAwaitingLook).
  Look look_wanted() const noexcept {
    return status() == Status::kAwaitingLook ? looks_.awaited() : Look::kNone;
  }
  /// What the awaited look saw; the task runs on from the next tick (nothing awaited: ignored).
  void see(const Sighting& sighting) noexcept;
  /// The pin's offset along the fingers' y seen over the bore (NaN: none).
  double held_offset_m() const noexcept { return search_.held_offset_m(); }
  static std::string_view name(Look l) noexcept;

  void pause() noexcept { supervisor_.pause(); }
  void resume() noexcept { supervisor_.resume(); }
  void confirm() noexcept { supervisor_.confirm(); }
  void take_over() noexcept { supervisor_.take_over(); }
  /// The operator hands back: the current step again from where the stage is, or, with
  /// `step_done`, the next one.
  void hand_back(bool step_done = false) noexcept;
  /// The next step, from where the stage is, whatever the task's status (finished: nothing). A
  /// paused task stays paused in the next step (resume() goes on); a task the operator drives
  /// hands back into it. The next step's autonomy applies as on any entry (confirm: it waits).
  void skip() noexcept;
  /// A step's level counts from its next entry, and for the current step at once while it has
  /// not run a tick (so that a task file's level for the first step applies).
  void set_autonomy(Step step, Autonomy a) noexcept;

  Step step() const noexcept { return step_; }
  Status status() const noexcept { return supervisor_.status(); }
  /// Why the task failed ("" otherwise); a static string.
  std::string_view failure() const noexcept { return supervisor_.failure(); }
  int search_tries() const noexcept { return search_.tries(); }
  /// The tool's height at which the held part's bottom meets the seat over the target, as
  /// measured (the seat's levelling touches, seat_levelling.h): the insertion's heights count from
  /// it instead of the grasp height (a part grasped off a tilted tray sits higher or lower in the
  /// fingers than drawn). Ignored when not finite.
  void set_surface_contact_m(double z_m) noexcept {
    if (std::isfinite(z_m)) rim_z_ = surface_z_ = z_m;
  }
  /// Tip height at which the inserting descent met its stop (NaN before).
  double insert_contact_z_m() const noexcept { return search_.contact_z_m(); }
  static std::string_view name(Step s) noexcept;
  static std::string_view name(Status s) noexcept;
  static std::string_view name(Autonomy a) noexcept;
  Autonomy autonomy(Step step) const noexcept { return supervisor_.autonomy(step); }

 private:
  enum class Release { kOpen, kStrategy };
  void enter(Step s) noexcept;
  void fail(const char* why) noexcept { supervisor_.fail(why); }
  /// The goal of a move step (assistable()) from the tip at `tip`.
  Eigen::Vector3d move_goal(Step s, const Eigen::Vector3d& tip) const noexcept;
  /// An assisted step's tick: its fixtures; the next step once the goal has been held.
  void assisted_tick(const TaskSensors& s, double dt) noexcept;
  /// Heads for `goal` at `speed`; true once the tip has been within tolerance for settle_s.
  bool move_to(const Eigen::Vector3d& goal, double speed, const TaskSensors& s, double dt) noexcept;
  /// Turns the fingers towards `yaw` (the rotary axis' goal from this tick on).
  void turn_to(double yaw) noexcept;
  /// The fingers' yaw squaring them with the pin (align) and the pin with its bore (rotate).
  double align_yaw(double from) const noexcept;
  double rotate_yaw(double from) const noexcept;
  /// The insertion's point: the bore's axis, the servo's aim and the search's offset.
  Eigen::Vector2d search_xy() const noexcept { return search_.point(goal_.target_m); }
  /// The look the current step needs before it moves (kNone: none, or no camera).
  Look look_before_moving() const noexcept;
  void insert_tick(const TaskSensors& s, double dt) noexcept;
  void release_tick(const TaskSensors& s, double dt) noexcept;
  void verify_tick(const TaskSensors& s, double dt) noexcept;

  AssemblyTaskParams p_;
  AssemblyGoal goal_;
  TaskSupervisor supervisor_;
  TaskLooks looks_;
  InsertionSearch search_;
  teleop::ConsoleInput out_;
  teleop::FixtureSet fixtures_;
  Step step_ = Step::kApproach;
  double step_s_ = 0.0, settled_s_ = 0.0;
  double grasp_z_ = 0.0, safe_z_ = 0.0, carry_z_ = 0.0;
  double rim_z_ = 0.0;      // tool-point height at which the held pin's bottom meets the surface
  double surface_z_ = 0.0;  // ... over the target, as the insertion counts it (set_surface_contact_m)
  double opening_command_ = 0.0;
  Release release_ = Release::kOpen;
  double release_s_ = 0.0;                                 // time in the release's strategy
  Eigen::Vector2d assist_from_ = Eigen::Vector2d::Zero();  // where an assisted move's path starts
  bool assist_from_known_ = false;
  double yaw_goal_ = std::numeric_limits<double>::quiet_NaN();    // the rotary axis' (NaN: none yet)
  double assist_yaw_ = std::numeric_limits<double>::quiet_NaN();  // an assisted turn's yaw stop
  double last_yaw_ = 0.0;                                         // the fingers' yaw at the last tick
  Eigen::Vector3d last_tip_ = Eigen::Vector3d::Zero();            // ... and the tip's position
};

}  // namespace mc::cell
