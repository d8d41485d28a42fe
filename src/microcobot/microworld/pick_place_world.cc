#include "microcobot/microworld/pick_place_world.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include <fmt/format.h>

#include "microcobot/microworld/release.h"

namespace mc::microworld {
namespace {

// A planar vector turned by `a` (counter-clockwise).
Eigen::Vector2d turned(const Eigen::Vector2d& v, double a) noexcept {
  const double c = std::cos(a), s = std::sin(a);
  return {c * v.x() - s * v.y(), s * v.x() + c * v.y()};
}

}  // namespace

double wrap_quarter_turn(double a) noexcept {
  const double q = 0.5 * M_PI;
  return a - q * std::floor(a / q + 0.5);
}

void PickPlaceParams::validate() const {
  require_positive(part_side_m, "part_side_m");
  require_positive(part_density_kg_m3, "part_density_kg_m3");
  require_non_negative(gravity_m_s2, "gravity_m_s2");
  require_non_negative(substrate_pulloff_N, "substrate_pulloff_N");
  require_non_negative(finger_pulloff_N, "finger_pulloff_N");
  require_non_negative(meniscus_rupture_m, "meniscus_rupture_m");
  require_positive(creep_velocity_m_s, "creep_velocity_m_s");
  require_in_range(finger_friction, 0.0, 2.0, "finger_friction");
  require_in_range(substrate_friction, 0.0, 2.0, "substrate_friction");
  require_positive(substrate_stiffness_N_m, "substrate_stiffness_N_m");
  require_non_negative(part_height_m, "part_height_m");
  require_non_negative(hole_side_m, "hole_side_m");
  require_non_negative(hole_depth_m, "hole_depth_m");
  require(std::isfinite(part_yaw_rad) && std::abs(part_yaw_rad) <= 2 * M_PI, "part_yaw_rad",
          "must be within [-2 pi, 2 pi] rad", part_yaw_rad);
  require(std::isfinite(hole_yaw_rad) && std::abs(hole_yaw_rad) <= 2 * M_PI, "hole_yaw_rad",
          "must be within [-2 pi, 2 pi] rad", hole_yaw_rad);
  if (hole_side_m > 0.0) {
    require(hole_side_m > part_side_m, "hole_side_m",
            "must exceed part_side_m (the clearance must be positive)", hole_side_m);
    require(hole_depth_m > 0.0 && hole_depth_m < height_m(), "hole_depth_m",
            "must be within (0, the part's height): the fingers must hold the part above the substrate",
            hole_depth_m);
  }
  require(std::isfinite(grip_force_limit_N) && grip_force_limit_N > 0 && grip_force_limit_N <= 1.0,
          "grip_force_limit_N", "must be within (0, 1] N", grip_force_limit_N);
  require(std::isfinite(contact_force_limit_N) && contact_force_limit_N > 0 && contact_force_limit_N <= 10.0,
          "contact_force_limit_N", "must be within (0, 10] N", contact_force_limit_N);
  require(std::isfinite(min_tip_height_m) && min_tip_height_m >= -1e-3 && min_tip_height_m < 1e-3,
          "min_tip_height_m", "must be within [-1 mm, 1 mm)", min_tip_height_m);
  require(std::isfinite(seat_tolerance_m) && seat_tolerance_m > 0.0 && seat_tolerance_m <= 1e-3,
          "seat_tolerance_m", "must be within (0, 1 mm]", seat_tolerance_m);
  require(std::isfinite(roll_edge_fraction) && roll_edge_fraction >= 0.0 && roll_edge_fraction <= 1.0,
          "roll_edge_fraction", "must be within [0, 1]", roll_edge_fraction);
  require(std::isfinite(roll_peel_angle_rad) && roll_peel_angle_rad > 0.0 && roll_peel_angle_rad <= 0.5,
          "roll_peel_angle_rad", "must be within (0, 0.5] rad", roll_peel_angle_rad);
  for (const auto& [tilt, name] :
       {std::pair{seat_tilt_x_rad, "seat_tilt_x_rad"}, {seat_tilt_y_rad, "seat_tilt_y_rad"}})
    require(std::isfinite(tilt) && std::abs(tilt) <= 0.1, name, "must be within [-0.1, 0.1] rad (5.7 deg)",
            tilt);
  require(neighbour_count >= 0 && neighbour_count <= kMaxNeighbours, "neighbour_count",
          fmt::format("must be within [0, {}]", kMaxNeighbours), neighbour_count);
  for (int i = 0; i < neighbour_count; ++i) {
    const NeighbourPart& n = neighbours[static_cast<std::size_t>(i)];
    require(n.xy_m.allFinite() && std::isfinite(n.yaw_rad) && std::isfinite(n.side_m) && n.side_m > 0.0 &&
                std::isfinite(n.top_z_m) && n.top_z_m > 0.0,
            fmt::format("neighbours[{}]", i), "must have a finite place, a positive side and top", i);
  }
  gripper.validate();
  require(gripper.max_opening_m > part_side_m, "gripper.max_opening_m", "must exceed part_side_m",
          gripper.max_opening_m);
  // A part the fingers cannot hold at their force limit (friction on both sides plus adhesion) can
  // never be lifted: refused before a session that could only time out (gravity 1e308 did).
  const double hold_N = 2.0 * (finger_friction * grip_force_limit_N + finger_pulloff_N);
  require(
      part_weight_N() <= hold_N, "gravity_m_s2",
      fmt::format("makes the part weigh {:.3g} N (part_density_kg_m3 x volume x gravity_m_s2), more than the "
                  "fingers hold at grip_force_limit_N, 2 (finger_friction x grip_force_limit_N + "
                  "finger_pulloff_N) = {:.3g} N",
                  part_weight_N(), hold_N),
      gravity_m_s2);
}

double PickPlaceParams::part_weight_N() const { return part_mass_kg() * gravity_m_s2; }

double PickPlaceParams::part_mass_kg() const {
  return part_density_kg_m3 * part_side_m * part_side_m * height_m();
}

PickPlaceParams pin_in_hole_scene() {
  PickPlaceParams p;
  p.part_side_m = 200e-6;
  p.part_height_m = 600e-6;
  p.hole_side_m = 220e-6;
  p.hole_depth_m = 300e-6;
  return p;
}

PickPlaceParams flat_part_scene() {
  PickPlaceParams p;
  p.part_side_m = 300e-6;
  p.part_height_m = 50e-6;
  p.finger_pulloff_N = vdw_plane_plane_N(1e-19, 2e-13, 0.4e-9);       // 16.6 uN
  p.substrate_pulloff_N = vdw_plane_plane_N(1e-19, 2.4e-13, 0.4e-9);  // 19.9 uN
  return p;
}

PickPlaceWorld::PickPlaceWorld(PickPlaceParams params) : p_(std::move(params)) {
  p_.validate();
  weight_ = p_.part_weight_N();
  // One set of figures for both models: the closing model's stiffness and friction are the tips'.
  fingers_.align = p_.gripper.align;
  fingers_.contact_stiffness_N_m = p_.gripper.finger_stiffness_N_m;
  fingers_.tip_face_height_m = p_.gripper.tip_face_height_m;
  fingers_.friction_coefficient = p_.finger_friction;
}

PickPlaceState PickPlaceWorld::initial_state() const {
  PickPlaceState s;
  s.part_yaw_rad = p_.part_yaw_rad;
  s.part_m = {p_.part_start_m.x(), p_.part_start_m.y(),
              rest_z_m(p_.part_start_m.x(), p_.part_start_m.y(), p_.part_yaw_rad)};
  s.gripper.free_opening_m = p_.gripper.max_opening_m;
  s.last_gripper_m = {p_.part_start_m.x(), p_.part_start_m.y(), 10 * p_.part_side_m};
  const double m = p_.gripper.tip_misalignment_m;
  s.fingers.mount_z_m = {-0.5 * m, 0.5 * m};
  return s;
}

double PickPlaceWorld::placement_error_m(const PickPlaceState& s) const {
  return std::hypot(s.part_m.x() - p_.target_m.x(), s.part_m.y() - p_.target_m.y());
}

double PickPlaceWorld::orientation_error_rad(const PickPlaceState& s) const noexcept {
  return wrap_quarter_turn(s.part_yaw_rad - p_.hole_yaw_rad);
}

double PickPlaceWorld::hole_play_m(double yaw_rad) const noexcept {
  // The turned square's extent along the hole's sides: s (|cos d| + |sin d|) / 2.
  const double d = wrap_quarter_turn(yaw_rad - p_.hole_yaw_rad);
  return 0.5 * (p_.hole_side_m - p_.part_side_m * (std::abs(std::cos(d)) + std::abs(std::sin(d))));
}

double PickPlaceWorld::hole_entry_depth_m(double yaw_rad, double tilt_rad) const noexcept {
  if (p_.hole_side_m <= 0.0 || hole_play_m(yaw_rad) + 1e-12 <= 0.0) return 0.0;
  const double theta = std::abs(tilt_rad);
  if (theta < 1e-12) return p_.hole_depth_m;
  // Wedged at two-point contact: the pin's width w cos(theta) plus its lean l sin(theta) span D.
  const double w = p_.hole_side_m - 2.0 * hole_play_m(yaw_rad);  // the footprint across a side
  const double l_max = (p_.hole_side_m - w * std::cos(theta)) / std::sin(theta);
  return std::clamp(l_max, 0.0, p_.hole_depth_m);
}

double PickPlaceWorld::rest_z_m(double x, double y, double yaw_rad, double tilt_rad) const noexcept {
  const double half_height = 0.5 * p_.height_m();
  if (p_.hole_side_m <= 0.0) return half_height;
  const double play = hole_play_m(yaw_rad) + 1e-12;
  const Eigen::Vector2d d = turned({x - p_.target_m.x(), y - p_.target_m.y()}, -p_.hole_yaw_rad);
  const bool fits = play > 0.0 && std::abs(d.x()) <= play && std::abs(d.y()) <= play;
  return fits ? half_height - hole_entry_depth_m(yaw_rad, tilt_rad) : half_height;
}

bool PickPlaceWorld::inserted(const PickPlaceState& s) const noexcept {
  return p_.hole_side_m > 0.0 && s.part_m.z() < 0.5 * p_.height_m() - 1e-9;
}

bool PickPlaceWorld::placed(const PickPlaceState& s) const noexcept {
  if (s.phase != PartPhase::kOnSubstrate) return false;
  if (p_.hole_side_m > 0.0) return s.part_m.z() <= 0.5 * p_.height_m() - p_.hole_depth_m + 1e-9;
  return std::abs(s.part_m.z() - 0.5 * p_.height_m()) < 1e-9 && placement_error_m(s) <= p_.seat_tolerance_m;
}

Eigen::Vector2d PickPlaceWorld::confine_to_hole(Eigen::Vector3d& part, double part_yaw, double yaw,
                                                bool in_hole, double capacity_N,
                                                Eigen::Vector2d& slip_m) const noexcept {
  slip_m.setZero();
  if (!in_hole) return Eigen::Vector2d::Zero();
  const double play = std::max(hole_play_m(part_yaw), 0.0);
  // In the hole's frame (its sides along the axes).
  const Eigen::Vector2d d = turned(part.head<2>() - p_.target_m.head<2>(), -p_.hole_yaw_rad);
  Eigen::Vector2d inside = d;
  for (int i = 0; i < 2; ++i) inside[i] = std::clamp(d[i], -play, play);
  part.head<2>() = p_.target_m.head<2>() + turned(inside, p_.hole_yaw_rad);
  // What the wall moves the part by against the fingers, in their frame (x: their closing axis).
  const Eigen::Vector2d push = turned(turned(inside - d, p_.hole_yaw_rad), -yaw);
  // Along their closing axis both fingers bend together (2 k_finger) before the part slips in them;
  // across it they are as stiff as their width (the wall's stiffness stands for it). The fingers
  // feel at most what holds the part (friction of the grip, or the adhesion to a finger): beyond
  // it the part slips between them, by what the bend does not take.
  const double k2 = 2.0 * p_.gripper.finger_stiffness_N_m;
  Eigen::Vector2d reaction(k2 * push.x(), p_.substrate_stiffness_N_m * push.y());
  const double n = reaction.norm();
  if (n > capacity_N) reaction *= capacity_N / n;
  slip_m = {push.x() - reaction.x() / k2, push.y()};
  return turned(reaction, yaw);
}

Eigen::Vector2d PickPlaceWorld::neighbour_reaction(const PickPlaceState& s, const Eigen::Vector3d& g,
                                                   double yaw, double opening,
                                                   bool& touching) const noexcept {
  Eigen::Vector2d f = Eigen::Vector2d::Zero();
  touching = false;
  const auto& gp = p_.gripper;
  const double held_bottom = s.part_m.z() - 0.5 * p_.height_m();
  const bool held = s.phase != PartPhase::kOnSubstrate;
  for (int i = 0; i < p_.neighbour_count; ++i) {
    const NeighbourPart& n = p_.neighbours[static_cast<std::size_t>(i)];
    const Footprint square{n.xy_m, {0.5 * n.side_m, 0.5 * n.side_m}, n.yaw_rad};
    Eigen::Vector2d out;
    const auto strike = [&](const Footprint& body) {
      const double depth = overlap(square, body, out);
      if (depth <= 0.0) return;
      f += p_.substrate_stiffness_N_m * depth * out;
      touching = true;
    };
    if (g.z() < n.top_z_m) {
      for (double side : {-1.0, 1.0}) {  // each finger, from its inner face outward
        const double x = side * (0.5 * opening + 0.5 * gp.finger_thickness_m);
        strike({g.head<2>() + turned({x, 0.0}, yaw),
                {0.5 * gp.finger_thickness_m, 0.5 * gp.finger_width_m},
                yaw});
      }
    }
    if (held && held_bottom < n.top_z_m)
      strike({s.part_m.head<2>(), {0.5 * p_.part_side_m, 0.5 * p_.part_side_m}, s.part_yaw_rad});
  }
  return f;
}

bool PickPlaceWorld::between_fingers(const PickPlaceState& s, const Eigen::Vector3d& g,
                                     double yaw) const noexcept {
  const double half = 0.5 * p_.part_side_m, half_height = 0.5 * p_.height_m();
  const double opening = std::max(s.gripper.free_opening_m, p_.part_side_m);
  const Eigen::Vector2d d = turned((s.part_m - g).head<2>(), -yaw);  // the fingers' frame
  const bool in_jaw_x = std::abs(d.x()) <= 0.5 * opening;
  const bool in_jaw_y = std::abs(d.y()) < half;
  const bool tips_below_top = g.z() < s.part_m.z() + half_height;
  const bool fingers_above_bottom = g.z() + p_.gripper.finger_length_m > s.part_m.z() - half_height;
  return in_jaw_x && in_jaw_y && tips_below_top && fingers_above_bottom;
}

Eigen::Vector2d PickPlaceWorld::rubbing_force(const Eigen::Vector2d& motion, double dt_s,
                                              double coulomb_N) const noexcept {
  const double d = motion.norm();
  if (d <= 0.0) return Eigen::Vector2d::Zero();
  // Coulomb friction against the motion, regularised below the creep velocity v_c:
  // F = -F_c tanh(|v| / v_c) v/|v|. The pure sign law would switch its full value at every
  // reversal of a micrometre jitter, which a teleoperator amplifies into chatter.
  const double v = dt_s > 0.0 ? d / dt_s : std::numeric_limits<double>::infinity();
  return -coulomb_N * std::tanh(v / p_.creep_velocity_m_s) * motion / d;
}

PickPlaceOutput PickPlaceWorld::step(PickPlaceState& s, const Eigen::Vector3d& g, double opening_command_m,
                                     double dt_s, double yaw, const AlignDrives& align_V,
                                     double seat_tilt_rad) const noexcept {
  PickPlaceOutput out;
  s.seat_tilt_rad = seat_tilt_rad;
  const double tilt = seat_tilt_rad;
  step_gripper(p_.gripper, s.gripper, opening_command_m, dt_s);
  // Only the align benders are driven (the closing is step_gripper's): the grasp pair, never
  // driven, is not stepped.
  for (std::size_t k = 0; k < 2; ++k)
    step_bender(finger_bender(fingers_, fingers_.align, static_cast<int>(k)), s.fingers.align[k], align_V[k],
                dt_s);
  out.tips = read_tips(fingers_, s.fingers, -g.z());
  out.tip_misalignment_m = misalignment_m(fingers_, s.fingers);
  const double side = p_.part_side_m;
  const Eigen::Vector3d motion = g - s.last_gripper_m;
  const Eigen::Vector3d last_g = s.last_gripper_m;
  const double last_yaw = s.last_gripper_yaw_rad;
  s.last_gripper_m = g;
  s.last_gripper_yaw_rad = yaw;

  // A finger tip below the substrate: a crash, reported as a stiff vertical reaction.
  if (g.z() < 0.0) {
    out.force_on_gripper_N.z() += p_.substrate_stiffness_N_m * (-g.z());
    s.crashed = true;
  } else {
    out.force_on_gripper_N.z() += out.tips.contact_N[0] + out.tips.contact_N[1];
  }

  const bool held = s.phase != PartPhase::kOnSubstrate;
  const bool in_hole = inserted(s);
  const bool between = held || between_fingers(s, g, yaw);
  const double grip = between ? grip_force_N(p_.gripper, s.gripper, side) : 0.0;
  out.part_between_fingers = between;
  out.grip_force_N = grip;
  out.opening_m = grip > 0.0 ? side : s.gripper.free_opening_m;
  // The friction the grip can transmit: over the faces' overlap only (thesis §1.1.4, F_hold).
  const double hold_capacity = holding_force_N(fingers_, grip, out.tip_misalignment_m);
  out.holding_force_N = hold_capacity;
  const double substrate_hold = p_.substrate_pulloff_N + weight_;  // force to tear the part off

  switch (s.phase) {
    case PartPhase::kOnSubstrate: {
      if (grip <= 0.0) break;
      // The closing fingers centre the part in the jaw (it slides: the fingers are far stronger
      // than the substrate friction) and square it against their flats; in its hole the walls
      // keep its yaw. Dragged, it keeps its place along the fingers (their frame's y).
      const Eigen::Vector2d lateral(motion.x(), motion.y());
      const double drag_resistance = p_.substrate_friction * substrate_hold;
      const bool dragged = (lateral.norm() > 0.0 || yaw != last_yaw) && hold_capacity >= drag_resistance;
      const double along = dragged ? turned((s.part_m - last_g).head<2>(), -last_yaw).y()
                                   : turned((s.part_m - g).head<2>(), -yaw).y();
      s.part_m.head<2>() = g.head<2>() + turned({0.0, along}, yaw);
      if (!in_hole) s.part_yaw_rad -= wrap_quarter_turn(s.part_yaw_rad - yaw);  // to yaw + k 90 deg
      if (dragged && lateral.norm() > 0.0)
        out.force_on_gripper_N.head<2>() += rubbing_force(lateral, dt_s, drag_resistance);
      Eigen::Vector2d slid;  // the part is centred in the jaw again at every step: no slip kept
      out.force_on_gripper_N.head<2>() +=
          confine_to_hole(s.part_m, s.part_yaw_rad, yaw, in_hole, hold_capacity, slid);
      if (motion.z() > 0.0 && g.z() > s.part_m.z() - 0.5 * p_.height_m() - 1e-12) {
        if (hold_capacity >= substrate_hold) {
          s.phase = PartPhase::kGrasped;  // lift-off: the grip beats adhesion + weight
          s.part_m.z() += motion.z();     // from now on the part moves with the fingers
          s.offset_m.head<2>() = turned((s.part_m - g).head<2>(), -yaw);
          s.offset_m.z() = s.part_m.z() - g.z();
          s.yaw_offset_rad = s.part_yaw_rad - yaw;
        } else {
          out.force_on_gripper_N.z() -= hold_capacity;  // fingers slip upward along the part
        }
      }
      break;
    }
    case PartPhase::kGrasped:
    case PartPhase::kStuckToFinger: {
      Eigen::Vector3d next = g;
      next.head<2>() += turned(s.offset_m.head<2>(), yaw);
      next.z() += s.offset_m.z();
      // In the hole, its walls hold the part: it slips in the fingers, which feel the wall, and
      // keeps its yaw while they turn round it. Stuck to an opened finger on its seat, the seat's
      // friction may hold it too (release.h, roll): the finger's contact peels as it turns.
      const bool stuck_on_seat =
          s.phase == PartPhase::kStuckToFinger &&
          s.part_m.z() <= rest_z_m(s.part_m.x(), s.part_m.y(), s.part_yaw_rad, tilt) + p_.meniscus_rupture_m;
      const bool seat_holds_turn =
          stuck_on_seat && (in_hole || seat_moment_Nm(p_) > finger_peel_moment_Nm(p_)) && yaw != last_yaw;
      if (seat_holds_turn) {
        s.stuck_turn_rad += std::abs(yaw - last_yaw);
        if (s.stuck_turn_rad >= p_.roll_peel_angle_rad) s.finger_contact_rolled = true;
        next = s.part_m;  // it stays where it is, as it is
        s.offset_m.head<2>() = turned((s.part_m - g).head<2>(), -yaw);
        s.offset_m.z() = s.part_m.z() - g.z();
        s.yaw_offset_rad = s.part_yaw_rad - yaw;
      } else if (in_hole) {
        s.yaw_offset_rad = s.part_yaw_rad - yaw;
      } else {
        s.part_yaw_rad = yaw + s.yaw_offset_rad;
      }
      const double held_by = s.phase == PartPhase::kGrasped ? hold_capacity : p_.finger_pulloff_N;
      Eigen::Vector2d slip;
      out.force_on_gripper_N.head<2>() += confine_to_hole(next, s.part_yaw_rad, yaw, in_hole, held_by, slip);
      s.offset_m.head<2>() += slip;
      const double floor = rest_z_m(next.x(), next.y(), s.part_yaw_rad, tilt);
      if (next.z() < floor) {  // pressed onto the substrate: the part stops, the fingers slide down
        const double press = floor - next.z();
        s.offset_m.z() += press;
        next.z() = floor;
        out.force_on_gripper_N.z() += s.phase == PartPhase::kGrasped ? hold_capacity : 0.0;
      }
      s.part_m = next;
      // The meniscus bridges a gap up to its rupture distance: a part that close still touches.
      const bool on_substrate = s.part_m.z() <= floor + p_.meniscus_rupture_m;
      // Which adhesion keeps the part once the fingers are open (release.h: the shake's inertia,
      // a contact rolled onto its edge).
      const bool shaking = s.gripper.shaking;
      const bool rolled = s.finger_contact_rolled;
      if (s.phase == PartPhase::kGrasped && grip <= 0.0) {
        if (on_substrate && seat_keeps(p_, shaking, rolled)) {
          s.phase = PartPhase::kOnSubstrate;
          s.part_m.z() = floor;
        } else if (!on_substrate && drops_off(p_, shaking, rolled)) {
          s.phase = PartPhase::kOnSubstrate;  // falls
          s.part_m.z() = floor;
        } else {
          s.phase = PartPhase::kStuckToFinger;
        }
      } else if (s.phase == PartPhase::kStuckToFinger) {
        if (grip > 0.0) {
          s.phase = PartPhase::kGrasped;  // grasped again
        } else if (on_substrate && seat_keeps(p_, shaking, rolled)) {
          s.phase = PartPhase::kOnSubstrate;  // on its seat: the seat wins
          s.part_m.z() = floor;
        } else if (!on_substrate && drops_off(p_, shaking, rolled)) {
          s.phase = PartPhase::kOnSubstrate;  // shaken off in the air: it falls
          s.part_m.z() = floor;
        }
      }
      if (s.phase != PartPhase::kStuckToFinger) {  // a fresh contact the next time it sticks
        s.stuck_turn_rad = 0.0;
        s.finger_contact_rolled = false;
      }
      // A held part dragged on the substrate rubs on it.
      if (on_substrate && s.phase == PartPhase::kGrasped) {
        const Eigen::Vector2d lateral(motion.x(), motion.y());
        if (lateral.norm() > 0.0) {
          out.force_on_gripper_N.head<2>() +=
              rubbing_force(lateral, dt_s, p_.substrate_friction * substrate_hold);
        }
      }
      break;
    }
  }
  // The scene's other parts: struck, they push back on the fingers (and on the held part, hence on them).
  bool touching = false;
  out.force_on_gripper_N.head<2>() += neighbour_reaction(s, g, yaw, out.opening_m, touching);
  out.touching_neighbour = touching;
  if (touching) ++s.neighbour_contacts;
  // The lateral force on the fingers bends them along their closing axis (common mode, 2 k_finger);
  // the walls' share is the bend confine_to_hole left unslipped.
  const Eigen::Vector2d on_fingers = turned(out.force_on_gripper_N.head<2>(), -yaw);
  s.finger_deflection_m = turned({on_fingers.x() / (2.0 * p_.gripper.finger_stiffness_N_m), 0.0}, yaw);
  out.part_on_substrate =
      s.part_m.z() <= rest_z_m(s.part_m.x(), s.part_m.y(), s.part_yaw_rad, tilt) + p_.meniscus_rupture_m;
  s.part_tilt_rad =
      s.phase == PartPhase::kGrasped ? part_tilt_rad(out.tip_misalignment_m, p_.part_side_m) : 0.0;
  return out;
}

}  // namespace mc::microworld
