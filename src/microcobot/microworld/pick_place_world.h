#pragma once
/// @file
/// The microworld of a watchmaking pick-and-place: a rigid micro-part (a cube, e.g. a 300 um
/// brass part) on a substrate, held there by adhesion, and the slave PiezoGripper carried by
/// the XYZ stage.
///
/// At this scale surface forces dominate (thesis §1.1.1): a 300 um brass cube weighs 2.3 uN
/// while a capillary meniscus holds it to the substrate with ~70 uN and van der Waals
/// forces hold it to a finger with a few uN. Inertia is negligible (a 0.23 mg part reaches
/// force equilibrium in microseconds), so the world is quasi-static: at each step the part is
/// where the force balance puts it, and contacts switch by comparing pull-off and friction
/// capacities:
///  - lift-off:   2 mu_finger F_grip  >= F_pulloff_substrate + W    (else the fingers slip)
///  - drag:       2 mu_finger F_grip  >= mu_substrate (F_pulloff_substrate + W)
///  - release:    on the substrate, fingers open: the part stays on the substrate when
///                F_pulloff_substrate > 2 F_pulloff_finger, else it sticks to a finger;
///                opened in the air it sticks to a finger when 2 F_pulloff_finger > W
///                (release.h: the strategies that shake or roll it off a finger).
/// The gripper reference point is the middle of the finger tips; fingers close along x.
///
/// The part is a block part_side_m x part_side_m x part_height_m (a cube by default, a pin when
/// taller). With hole_side_m > 0 the target is a square hole of that side and hole_depth_m deep
/// (a pin-in-hole insertion with clearance hole_side_m - part_side_m): the part goes down into
/// it only when its footprint fits (|x - x_hole| and |y - y_hole| <= clearance / 2), else it
/// lands on the rim; once in, the hole's walls stop it sideways, up to what holds the part in the
/// fingers (beyond it the part slips between them).
///
/// Finger compliance (contact force by vision): the fingers are benders of stiffness
/// k_finger along their closing axis, so a lateral force F on them along it (a wall, the
/// substrate's drag) bends both tips together by F / (2 k_finger) (common mode; across that axis
/// they are as stiff as their width). Against a wall they bend before the part slips: the wall's
/// reaction along the closing axis is 2 k_finger times the push, not the wall's own stiffness. The
/// bend carries the part at the wall (it stays in the jaws); the drag's (at most mu (F_pulloff +
/// W) / (2 k) = 0.1 um) is drawn on the tips only.
///
/// Orientation: the part and the hole are squares turned by part_yaw_rad and
/// hole_yaw_rad about the vertical, and the fingers by the gripper's yaw (the rotary axis under
/// it, turning about the vertical through the tips). A square part turned by d against the
/// hole has a footprint s (|cos d| + |sin d|) wide along the hole's sides (d taken modulo 90 deg,
/// the square's symmetry), so it goes in only when |d| is small enough for the clearance:
/// 200 um in 220 um fits up to |d| = 6.06 deg, in 210 um up to 2.86 deg. Closing fingers square the
/// part against their flats (the parallel-jaw squeeze turns a polygon to a stable face pair:
/// Goldberg, "Orienting polygonal parts without sensors", Algorithmica 10, 1993): a grasped part's
/// yaw is the fingers' plus a multiple of 90 deg, and it turns with them. A part down in its hole
/// is held by the walls: it keeps its yaw, the fingers slip round it.
///
/// The fingers' vertical alignment (thesis §1.1.4, the 4-DOF PiezoGripper; bender_fingers.h): each
/// tip stands at its mount height (gripper.tip_misalignment_m, split about the reference) plus its
/// align bender's deflection, driven by the align drives given to step(). Tips at different heights
/// dz hold the part with the faces' overlap only, F_hold = 2 mu F_grip max(0, 1 - |dz| / h_face)
/// (holding_force_N, mu = finger_friction), in place of 2 mu F_grip everywhere the grip holds (the
/// lift-off, the drag, the hole's walls), and a lifted part turns between them by atan(dz / side)
/// (part_tilt_rad). Each tip below the substrate presses on it with its bender's stiffness
/// (read_tips): the gripper feels those forces while its reference point is above the substrate
/// (below it, the crash's stiff reaction). Level tips (the default) grip as the closing model alone.
///
/// A tilted seat (the substrate on the parallel positioner turned about a horizontal axis,
/// devices/carried_seat.h; the world is then written in the substrate's frame): a part held
/// upright by the fingers meets its hole's axis at the seat's tilt theta, and a rigid pin
/// tilted in a hole wedges at two-point contact once its lean spans the hole (Whitney,
/// "Quasi-static assembly of compliantly supported rigid parts", J. Dyn. Syst. Meas. Control
/// 104(1), 1982): a pin w wide across a side of the hole D goes in to the depth
/// l_max = (D - w cos theta) / sin theta and no further (the tilt taken across a side of the
/// hole, the worse case for a square pin). The part is placed only at the hole's bottom.

#include <cmath>

#include <Eigen/Dense>

#include <array>

#include "microcobot/core/params.h"
#include "microcobot/microworld/bender_fingers.h"
#include "microcobot/microworld/neighbours.h"
#include "microcobot/microworld/piezo_gripper.h"
#include "microcobot/microworld/surface_forces.h"

namespace mc::microworld {

struct PickPlaceParams {
  double part_side_m = 300e-6;         ///< cube side (the 300 um part of the main scenario)
  double part_height_m = 0.0;          ///< the part's height; 0: part_side_m (a cube)
  double hole_side_m = 0.0;            ///< side of the square hole at the target; 0: no hole
  double hole_depth_m = 0.0;           ///< its depth
  double part_density_kg_m3 = 8500.0;  ///< brass (watch parts)
  double gravity_m_s2 = 9.81;          ///< the part's weight per mass
  /// Substrate-part pull-off: capillary meniscus in ambient humidity, 4 pi gamma R cos(theta)
  /// with water (gamma 0.072 N/m, theta 60 deg) and an effective radius of a quarter of the side.
  double substrate_pulloff_N = capillary_sphere_plane_N(0.072, 75e-6, M_PI / 3.0);  // 33.9 uN
  /// Finger-part pull-off per finger: van der Waals of the finger's tip asperities,
  /// A R / (6 D^2) with A = 1e-19 J, D = 0.4 nm and R = 20 um (dry, coated fingers).
  double finger_pulloff_N = vdw_sphere_plane_N(1e-19, 20e-6, 0.4e-9);  // 2.08 uN
  /// Gap up to which the part-substrate meniscus still holds (its rupture distance, of the
  /// order of the liquid volume's cube root: ~1 um for a femtolitre meniscus).
  double meniscus_rupture_m = 1e-6;
  double finger_friction = 0.3;     ///< finger-part friction coefficient
  double substrate_friction = 0.3;  ///< part-substrate friction coefficient
  /// Sliding velocity below which the part-substrate friction is regularised (creep).
  double creep_velocity_m_s = 10e-6;
  double substrate_stiffness_N_m = 1e5;         ///< finger-tip crash into the substrate (penalty)
  Eigen::Vector3d part_start_m{0.0, 0.0, 0.0};  ///< part centre on the substrate (z ignored)
  Eigen::Vector3d target_m{2e-3, 0.0, 0.0};     ///< where the part must be placed (x, y)
  double part_yaw_rad = 0.0;  ///< the part's start orientation about the vertical (counter-clockwise)
  double hole_yaw_rad = 0.0;  ///< the hole's (the part must be turned to it, modulo 90 deg)
  PiezoGripperParams gripper;
  /// The platform's limits for this part (teleop/safety_limits.h). 1 mN of grip
  /// holds a 300 um brass part with a 27x margin (2 mu F >= pull-off + weight needs 60 uN) and
  /// stays well below what dents a watch part's finish.
  double grip_force_limit_N = 1e-3;
  /// Force on the gripper above which the stage holds: above the largest force of a normal
  /// pick-and-place (a held part pressed down slips in the fingers at 2 mu F_grip <= 0.6 mN).
  double contact_force_limit_N = 2e-3;
  /// Lowest finger-tip height above the substrate the platform lets any input command. A
  /// negative floor lets the tips into the substrate: only for tests of stiff contacts (the
  /// passivity tests), never on a platform with a customer's parts.
  double min_tip_height_m = 10e-6;
  /// Without a hole the target is a flat seat: a part resting within this of it is placed.
  double seat_tolerance_m = 10e-6;
  /// Release by rolling (release.h): the share of a finger's pull-off left once its flat contact
  /// has peeled onto its edge (line contact: a tenth of the face's), and the turn of the fingers
  /// against the held part that peels it (it lifts the far edge of a 40 um contact by 0.4 um, far
  /// beyond van der Waals' nanometre range, and far above the rotary axis' holding jitter).
  double roll_edge_fraction = 0.1;
  double roll_peel_angle_rad = 0.01;
  /// The substrate's tilt on what carries it (the parallel positioner's plate, or the bench): its
  /// surface turned by Ry(seat_tilt_y_rad) Rx(seat_tilt_x_rad) about the world's origin, a fixture
  /// that does not sit flat. The cell is not told it: it measures the seat by touch and levels it
  /// on the positioner (cell/seat_levelling.h). 0: the seat is flat on its carrier.
  double seat_tilt_x_rad = 0.0;
  double seat_tilt_y_rad = 0.0;
  /// The scene's other parts (neighbours.h): set by the cell from its batch (assembly_batch.h), not
  /// a file's key; the first neighbour_count count.
  static constexpr int kMaxNeighbours = 8;
  std::array<NeighbourPart, kMaxNeighbours> neighbours{};
  int neighbour_count = 0;

  template <class V>
  void visit(V& v) {
    v("part_side_m", part_side_m);
    v("part_height_m", part_height_m);
    v("hole_side_m", hole_side_m);
    v("hole_depth_m", hole_depth_m);
    v("part_density_kg_m3", part_density_kg_m3);
    v("gravity_m_s2", gravity_m_s2);
    v("substrate_pulloff_N", substrate_pulloff_N);
    v("finger_pulloff_N", finger_pulloff_N);
    v("meniscus_rupture_m", meniscus_rupture_m);
    v("finger_friction", finger_friction);
    v("substrate_friction", substrate_friction);
    v("creep_velocity_m_s", creep_velocity_m_s);
    v("substrate_stiffness_N_m", substrate_stiffness_N_m);
    v("part_start_x_m", part_start_m.x());
    v("part_start_y_m", part_start_m.y());
    v("target_x_m", target_m.x());
    v("target_y_m", target_m.y());
    v("part_yaw_rad", part_yaw_rad);
    v("hole_yaw_rad", hole_yaw_rad);
    v("gripper", gripper);
    v("grip_force_limit_N", grip_force_limit_N);
    v("contact_force_limit_N", contact_force_limit_N);
    v("min_tip_height_m", min_tip_height_m);
    v("seat_tolerance_m", seat_tolerance_m);
    v("roll_edge_fraction", roll_edge_fraction);
    v("roll_peel_angle_rad", roll_peel_angle_rad);
    v("seat_tilt_x_rad", seat_tilt_x_rad);
    v("seat_tilt_y_rad", seat_tilt_y_rad);
  }
  void validate() const;
  double part_weight_N() const;
  double part_mass_kg() const;
  double height_m() const { return part_height_m > 0.0 ? part_height_m : part_side_m; }
};

/// The pin-in-hole scene: a 200 um square brass pin, 600 um tall, into a 220 um hole 300 um
/// deep at the target (20 um of clearance, 10 um each side). `microcobot serve --scene
/// pin-in-hole`; scenes/pin-in-hole.yaml is the same scene as a file.
PickPlaceParams pin_in_hole_scene();

/// A flat part on a flat, dry seat (release.h): a 300 x 300 x 50 um brass plate
/// (a bridge's blank) whose edge faces cling to the fingers' flat tips by van der Waals over a true
/// contact of 2e-13 m^2 (1e-4 of the 40 x 50 um face: 16.6 uN per finger), while the ground seat
/// holds its face over 2.4e-13 m^2 (2.7e-6 of 300 x 300 um: 19.9 uN), no meniscus. Opened, the
/// fingers keep it (19.9 < 2 x 16.6 uN); shaking (37.8 uN of inertia) or rolling releases it.
PickPlaceParams flat_part_scene();

/// `a` modulo a square's symmetry (90 deg), in [-45, 45) deg.
double wrap_quarter_turn(double a) noexcept;

/// Where the part is held.
enum class PartPhase {
  kOnSubstrate,    ///< resting on the substrate (possibly squeezed by the fingers)
  kGrasped,        ///< lifted and carried by the grip
  kStuckToFinger,  ///< fingers open but adhesion keeps it on a finger
};

struct PickPlaceState {
  Eigen::Vector3d part_m = Eigen::Vector3d::Zero();  ///< part centre
  PartPhase phase = PartPhase::kOnSubstrate;
  double part_yaw_rad = 0.0;  ///< the part's orientation about the vertical
  /// Part centre - gripper point while held, in the fingers' frame (turned by the gripper's yaw).
  Eigen::Vector3d offset_m = Eigen::Vector3d::Zero();
  double yaw_offset_rad = 0.0;  ///< part yaw - gripper yaw while held
  Eigen::Vector3d last_gripper_m = Eigen::Vector3d::Zero();
  double last_gripper_yaw_rad = 0.0;
  PiezoGripperState gripper;
  /// The fingers' common-mode deflection [m] (world x, y; along their closing axis): a lateral force
  /// F on them (a wall, the substrate's drag) bends both tips by F / (2 k_finger). Where the
  /// microscope sees the tips: the gripper point plus this.
  Eigen::Vector2d finger_deflection_m = Eigen::Vector2d::Zero();
  /// Stuck to a finger: how far the fingers have turned against the part held on its seat, and
  /// whether that has peeled their flat contact onto its edge (release.h, roll).
  double stuck_turn_rad = 0.0;
  bool finger_contact_rolled = false;
  int neighbour_contacts = 0;  ///< steps in which a finger or the held part struck a neighbour
  bool crashed = false;        ///< a finger tip went into the substrate at some point
  /// The fingers' benders (only the align pair is stepped here, the grasp pair rests at 0 V: the
  /// closing is `gripper`'s) and their mounts (gripper.tip_misalignment_m).
  BenderFingersState fingers;
  /// The held part's tilt about the fingers' closing axis from the tips' misalignment (0 unless
  /// grasped).
  double part_tilt_rad = 0.0;
  /// The seat's tilt against the fingers' vertical at the last step (step()'s seat_tilt_rad).
  double seat_tilt_rad = 0.0;
};

/// What the world returns each step: the forces the slave feels (to be fed back, scaled, to
/// the operator) and contact flags.
struct PickPlaceOutput {
  double grip_force_N = 0.0;
  Eigen::Vector3d force_on_gripper_N = Eigen::Vector3d::Zero();  ///< reaction on the fingers
  double opening_m = 0.0;  ///< actual finger opening (blocked by the part when gripping)
  bool part_between_fingers = false;
  bool part_on_substrate = true;
  bool touching_neighbour = false;  ///< a finger or the held part strikes another part of the scene
  /// The tips in the gripper's frame against the substrate (bender_fingers.h): each one's height
  /// and vertical contact force.
  TipReading tips;
  double tip_misalignment_m = 0.0;  ///< finger 1's tip height minus finger 0's, off the substrate
  double holding_force_N = 0.0;     ///< the friction the grip holds the part with (F_hold)
};

/// The align drives for one step [V]: each finger's vertical bender (positive raises its tip).
using AlignDrives = std::array<double, 2>;

class PickPlaceWorld {
 public:
  explicit PickPlaceWorld(PickPlaceParams params);
  const PickPlaceParams& params() const { return p_; }

  PickPlaceState initial_state() const;
  /// Advances by dt with the gripper point at `gripper_m`, the fingers turned by `gripper_yaw_rad`
  /// (closing along that direction) and their opening commanded to `opening_command_m`. Never
  /// allocates.
  /// The align benders go toward `align_V` (level tips at 0 V unless mounted misaligned). The
  /// seat is tilted by `seat_tilt_rad` against the fingers' vertical (the file's comment: how deep
  /// a held part then goes into its hole).
  PickPlaceOutput step(PickPlaceState& s, const Eigen::Vector3d& gripper_m, double opening_command_m,
                       double dt_s, double gripper_yaw_rad = 0.0, const AlignDrives& align_V = {},
                       double seat_tilt_rad = 0.0) const noexcept;
  /// The fingers as bender_fingers.h sees them: the align benders and the face height of
  /// `gripper`, the tips' stiffness its finger_stiffness_N_m, the friction finger_friction.
  const BenderFingersParams& fingers() const noexcept { return fingers_; }
  /// Horizontal distance from the part centre to the target.
  double placement_error_m(const PickPlaceState& s) const;
  /// The part's orientation against the hole's, modulo the square's 90 deg, in [-45, 45) deg.
  double orientation_error_rad(const PickPlaceState& s) const noexcept;
  /// Height of the part's centre when it rests at (x, y) turned by `yaw_rad`: in the hole when its
  /// footprint fits the hole's clearance (held `tilt_rad` off the hole's axis: only as deep as the
  /// tilt lets it, hole_entry_depth_m), on the substrate (or the hole's rim) otherwise.
  double rest_z_m(double x, double y, double yaw_rad = 0.0, double tilt_rad = 0.0) const noexcept;
  /// How deep a part turned by `yaw_rad` and tilted by `tilt_rad` against the hole's axis goes into
  /// it: the hole's depth, or where its lean wedges it (the file's comment); 0 when it does not fit.
  double hole_entry_depth_m(double yaw_rad, double tilt_rad) const noexcept;
  /// Half the play the hole leaves a part turned by `yaw_rad` along each of its sides (negative:
  /// it does not fit at that angle).
  double hole_play_m(double yaw_rad) const noexcept;
  /// The part is down in the hole (its bottom below the substrate).
  bool inserted(const PickPlaceState& s) const noexcept;
  /// The part is where the target wants it and let go: down at the hole's bottom, or, on a flat
  /// seat, resting on the substrate within seat_tolerance_m of the target.
  bool placed(const PickPlaceState& s) const noexcept;

 private:
  bool between_fingers(const PickPlaceState& s, const Eigen::Vector3d& g, double yaw) const noexcept;
  Eigen::Vector2d rubbing_force(const Eigen::Vector2d& motion, double dt_s, double coulomb_N) const noexcept;
  /// Keeps a part that was in the hole (`in_hole`, before this step's motion) inside its walls;
  /// returns the wall's reaction on the fingers (turned by `yaw`) [N], at most `capacity_N` (what
  /// holds the part in them). Along their closing axis the fingers bend by reaction / (2 k_finger)
  /// first; `slip_m` (their frame) is how far the part slips in them.
  /// The neighbours' reaction on the fingers (at `opening`, turned by `yaw`) and on the held part.
  Eigen::Vector2d neighbour_reaction(const PickPlaceState& s, const Eigen::Vector3d& g, double yaw,
                                     double opening, bool& touching) const noexcept;
  Eigen::Vector2d confine_to_hole(Eigen::Vector3d& part, double part_yaw, double yaw, bool in_hole,
                                  double capacity_N, Eigen::Vector2d& slip_m) const noexcept;
  PickPlaceParams p_;
  BenderFingersParams fingers_;
  double weight_;
};

}  // namespace mc::microworld
