#pragma once
/// @file
/// Levelling the seat the part rides on, before the cell inserts into it (the thesis's assembly,
/// §2.3, Fig. 2.4: the part on the 6-DOF parallel positioner). A fixture seldom sits flat on its
/// plate (microworld::PickPlaceParams::seat_tilt_x_rad), and a pin the fingers hold upright wedges
/// in a bore whose axis leans by theta once l sin(theta) + w cos(theta) = D at a depth l short of
/// the bottom (Whitney 1982; microworld/pick_place_world.h): 1.2 deg for a 100 um pin with 3 um of
/// clearance in a 300 um bore.
///
/// The seat is measured by touch, with the part the fingers hold (over the bore, before the
/// insertion: the tips themselves may not come within the platform's floor of the seat): its bottom
/// comes down force-guarded at three points round the bore, probe_radius_m from it, and at the
/// first again; the plane through the three touches is the seat's (the part's offset in the fingers
/// is the same at each, so the plane's slope is the seat's), once the part's slip in the fingers is
/// taken out: each touch pushes it up by a fraction of a micrometre, which the first point's second
/// touch measures in all and which is shared out over the touches as a linear drift, as a CMM's
/// closing measurement is. The positioner then turns its plate about its centre by the
/// smallest rotation that takes the plane's normal n to the vertical,
///
///   R_c = the rotation about n x e_z by acos(n . e_z),   T_plate' = (R_c R_plate, d_plate),
///
/// which leaves every point of the seat at the height of its centre: the seat's drawing puts its
/// surface through the plate's centre at z = 0, and what the cell does not know is its tilt
/// (docs/errata.md). The bore moves by its distance from the centre times 1 - cos(theta) (0.3 um
/// for 1 deg at 2 mm), well within the insertion's search. A new round of touches checks the
/// result; the seat is level once a round measures a tilt within tolerance_rad (max_rounds rounds
/// at most, each but the last levelling).
/// The part then goes back where it was taken from, over the bore, and the insertion goes on.
///
/// Each round also gives the platform the seat's pose on the plate as measured (seat_on_plate();
/// platform::Platform::set_seat_on_plate), so that the tips' floor and the refusals of the moves
/// take the seat where it is, not where a flat mount would put it.
///
/// Like the task, a pure object: each tick it reads the slave's sensors (TaskSensors) and returns
/// the console input the platform follows (its limits apply: the floor, the contact limit).
/// When a round's touches are in and the seat is not level it waits for the plate's move: the cell
/// plans it off the loop from level_goal() (motion::check_move), starts it
/// (Platform::start_pose_move) and says when it ended (moved()). Never allocates; noexcept.
///
///   rise      up to the travel height (where the part was taken from); after a round's third
///             touch, the fit
///   travel    over the next touch point
///   descend   down at approach_speed_m_s to search_from_m over where the part's bottom meets the
///             nominal surface (the round's first touch; the others: lift_m over that touch), then at
///             probe_speed_m_s until the contact force passes contact_threshold_N (a touch during
///             the fast part: back up by lift_m and again), then back up by retouch_m and down
///             at touch_speed_m_s to the touch that is measured; beyond max_travel_m: failed
///   move      the plate levels (the cell's move), the tool holding
///   return    back where the part was taken from

#include <array>
#include <limits>
#include <string>

#include <Eigen/Dense>

#include "microcobot/cell/assembly_task.h"
#include "microcobot/motion/pose.h"
#include "microcobot/teleop/teleoperation.h"

namespace mc::cell {

struct SeatLevellingParams {
  /// "auto": when the part rides on a parallel positioner; "on" (refused without one), "off".
  std::string mode = "auto";
  /// The touches round the bore, on the diagonals at 45, 135 and 225 deg: off the bore (a part's
  /// bottom partly over its edge still touches the surface) and, on a 700 um grid
  /// (assembly_batch.h), clear of the neighbours' parts.
  double probe_radius_m = 350e-6;
  double probe_speed_m_s = 20e-6;  ///< the descent that finds the touch
  /// The touch that measures, from retouch_m over the one found: slow, for the stick-slip Z's
  /// steps to stay well under the press the threshold takes (measured at 50 um/s, seats were
  /// left 0.5 mrad off: docs/parameters.md).
  double touch_speed_m_s = 2e-6;
  double retouch_m = 3e-6;
  double approach_speed_m_s = 200e-6;  ///< the descent down to search_from_m
  double travel_speed_m_s = 500e-6;    ///< between the touch points
  /// The fast descent's end over the nominal contact, for a round's first touch: a 2 deg tilt
  /// raises a seat 70 um at 2 mm from its centre; a touch above it is taken again slowly.
  double search_from_m = 100e-6;
  double max_travel_m = 400e-6;  ///< the slow descent's longest
  /// A touch: half the insertion's contact_threshold_N, for the press to stay under what the
  /// grip holds (a part pressed harder slips up in the fingers: the drift the fourth touch measures).
  double contact_threshold_N = 30e-6;
  /// The next touches' slow descent starts this over the first: a 4 deg seat differs by 49 um
  /// between touches 0.7 mm apart.
  double lift_m = 50e-6;
  /// A round measuring less is level: 0.03 deg, a fortieth of the wedge angle of the batch's
  /// tightest fit (1.2 deg, header) and twice the touches' own scatter over 0.5 mm.
  double tolerance_rad = 0.5e-3;
  int max_rounds = 3;  ///< rounds of touches at most (each but the last levels)

  template <class V>
  void visit(V& v) {
    v("mode", mode);
    v("probe_radius_m", probe_radius_m);
    v("probe_speed_m_s", probe_speed_m_s);
    v("touch_speed_m_s", touch_speed_m_s);
    v("retouch_m", retouch_m);
    v("approach_speed_m_s", approach_speed_m_s);
    v("travel_speed_m_s", travel_speed_m_s);
    v("search_from_m", search_from_m);
    v("max_travel_m", max_travel_m);
    v("contact_threshold_N", contact_threshold_N);
    v("lift_m", lift_m);
    v("tolerance_rad", tolerance_rad);
    v("max_rounds", max_rounds);
  }
  /// Throws mc::InvalidParams naming the field (level_seat.*).
  void validate() const;
};

class SeatLevelling {
 public:
  enum class Phase { kRise, kTravel, kDescend, kBackOff, kMove, kReturn, kDone, kFailed };

  /// `bore_xy_m`: the bore's drawn position (world); `contact_z_m`: the tool's height at which the
  /// held part's bottom meets the nominal surface (the task's grasp height). It starts from the
  /// tool's position at the first tick, where it returns. Throws mc::InvalidParams.
  SeatLevelling(const SeatLevellingParams& params, const Eigen::Vector2d& bore_xy_m, double contact_z_m);

  /// One tick: the console input to hand the platform (deadman held; holding while the plate moves).
  const teleop::ConsoleInput& tick(const TaskSensors& s, double dt_s) noexcept;

  /// The round's touches are in and the seat is not level: the plate must move (kMove).
  bool wants_move() const noexcept { return phase_ == Phase::kMove && !move_started_; }
  /// The plate's pose that levels the seat, from the pose `plate` it held during the touches.
  motion::PlatformTransform level_goal(const motion::PlatformTransform& plate) const noexcept;
  /// The seat's pose on the plate as the last round measured it, the plate at `plate` meanwhile
  /// (its heading is the plate's, which touches cannot see).
  motion::PlatformTransform seat_on_plate(const motion::PlatformTransform& plate) const noexcept;
  /// The cell started the move (`started`), or could not (`why`, a static string: failed).
  void move_started(bool started, const char* why = "") noexcept;
  /// The move ended: at its goal (`arrived`), or stopped short (failed).
  void moved(bool arrived) noexcept;

  Phase phase() const noexcept { return phase_; }
  bool finished() const noexcept { return phase_ == Phase::kDone || phase_ == Phase::kFailed; }
  const char* failure() const noexcept { return failure_; }
  /// The seat's tilt as the first round and the last round measured it [rad].
  double tilt_before_rad() const noexcept { return tilt_before_; }
  double tilt_rad() const noexcept { return tilt_; }
  int rounds() const noexcept { return rounds_; }
  /// The seat's normal as the last round measured it (world frame, upwards).
  const Eigen::Vector3d& normal() const noexcept { return normal_; }
  /// The tool's height at which the held part's bottom met the seat, over the bore, as the last
  /// round measured it (the drift taken out; NaN before a round): the insertion's reference
  /// (AssemblyTask::set_surface_contact_m).
  double contact_height_m() const noexcept { return contact_height_; }
  /// Where the touches are taken (world x, y): i in 0..3 (3: the first again).
  Eigen::Vector2d touch_point(int i) const noexcept;

 private:
  /// The descent's three speeds: down to search_from_m, finding the touch, measuring it.
  enum class Descent { kFast, kSlow, kFine };
  void fail(const char* why) noexcept;
  /// Up by `by_m` from the touch, then down again at the speed of `then`.
  void back_off(const TaskSensors& s, double by_m, Descent then) noexcept;
  /// Heads for `goal` at `speed`: true once the tool is within kThere_m of it.
  bool head_for(const Eigen::Vector3d& goal, double speed, const TaskSensors& s) noexcept;
  /// The plane through the round's touches: its normal and tilt; the plate's move, the return, or
  /// a failure.
  void fit() noexcept;

  SeatLevellingParams p_;
  Eigen::Vector2d bore_;
  double contact_z_;
  Eigen::Vector3d start_ = Eigen::Vector3d::Zero();  // where the tool was at the first tick
  Eigen::Vector3d hold_ = Eigen::Vector3d::Zero();   // where it holds while the plate moves
  bool started_ = false;
  Phase phase_ = Phase::kRise;
  int point_ = 0, rounds_ = 0;
  Descent descent_ = Descent::kFast;
  bool released_ = false;      // the contact seen under the threshold since the descent began
  bool move_started_ = false;  // the cell started the level move
  double fast_end_z_ = 0.0, slow_from_z_ = 0.0, back_to_z_ = 0.0;
  static constexpr int kTouches = 4;  // three points, the first touched again
  std::array<Eigen::Vector3d, kTouches> touches_{};
  Eigen::Vector3d normal_ = Eigen::Vector3d::UnitZ();
  double tilt_ = 0.0, tilt_before_ = 0.0;
  double contact_height_ = std::numeric_limits<double>::quiet_NaN();
  const char* failure_ = "";
  teleop::ConsoleInput out_;
};

}  // namespace mc::cell
