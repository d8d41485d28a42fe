#pragma once
/// @file
/// Shared control on the teleoperation coupling: virtual fixtures that
/// guide the slave and keep it out of forbidden regions, whatever the master.
///
/// The fixtures act on the slave target the operator commands (the coupling's stage
/// coordinates), not on the operator's hand, so that they hold with any master and cannot be
/// pushed through (Rosenberg's virtual fixtures, "perceptual overlays", 1993, applied on the
/// slave side as in micro-manipulation's virtual guides: Bolopion and Regnier, IEEE T-ASE 10(3),
/// 2013, §IV). With `raw` the target the master asks for and `e` = raw - guide in the plane:
///
///   guidance   guided = guide + (1 - a w(|e|)) e,  w = 1 within the capture radius R and
///              falling linearly to 0 at 2R (continuous: no jump on entering), a = the
///              assistance level. At a = 1 the slave sits on the insertion axis however the
///              hand trembles within R; outside 2R the master moves it as without fixture.
///              Along a path (`path`): the guide is the nearest point of the segment from
///              path_from_xy_m to guide_xy_m, so that motion along it is free and motion across it
///              is taken out within R (a guidance virtual fixture, Bettini, Marayong, Lang, Okamura
///              and Hager, "Vision-assisted control for manipulation using virtual fixtures", IEEE
///              T-RO 20(6), 2004); its end is the point guide. The field stays conservative: the
///              distance to a segment (a convex set) has the gradient e / |e|.
///   scaling    the motion scale grows with the distance to the guide (coarse far, fine near):
///              g(d) = 1 + a (far_gain - 1) clamp((d - R) / (far_distance - R), 0, 1). The
///              coupling applies it to the master's increments, so changing it never moves the
///              slave (bumpless).
///   pace       where the fixtures act, the target moves toward the guided one at most at
///              max_speed_m_s: the guidance's map is steep at the capture radius' edge.
///   funnel     a forbidden region: the hole's edge. Below `rim_z + cone height` the target's
///              z is kept above the cone z >= rim_z + (d - r0) / tan(half angle) (d: distance to
///              the axis, r0: the allowed radius at the rim), so that a carried part reaches the
///              rim only on the axis, whatever the input. Hard, like the safety limits. Below the
///              rim (the part in its bore) the region goes on as the bore's walls: the target is
///              kept within r0 of the axis (confined_xy), never lifted out by the cone (a
///              target moved off the axis in the bore, e.g. by the contact limit, once had the
///              cone pull it 170 um up at once, the pin half in).
///   height     a stop at a working height (a detent for the Z input, e.g. the grasping or the
///              carrying height): with e_z = raw_z - stop, guided_z = stop + (1 - b w_z(|e_z|)) e_z,
///              w_z as w with the capture height H; b is the stop's own level, slewed from 0
///              whenever the stop moves, so that a new height never jumps the target. Within H
///              the slave sits at the height whatever the wheel or the joystick does; beyond 2H
///              the input moves it as without fixture. Z is a rate input on every master (the
///              thumb wheel, the joystick): nothing is displayed.
///   display    on a haptic master the operator feels the guidance as a spring from the handle
///              to where the guided slave is: F = -k (raw - guided) / s (hand newtons, s the
///              motion scale). It is a radial field, F = -grad Phi with
///              Phi(d) = k a / s^2 int_0^d w(r) r dr, passive as long as the fixture is still.
///              A one-port passivity observer (Hannaford and Ryu, IEEE T-RO 18(1), 2002)
///              books the energy the hand puts in, starting from the field's energy at the
///              handle when the fixture set is installed, E = Phi(h0) + int -F.v dt; when the
///              level rises or the coupling re-indexes, E would go negative and the passivity
///              controller adds the damping that dissipates exactly the excess (f' = f + b v,
///              teleop/passivity.h's rule).
///   keep-out   forbidden regions round the neighbouring parts: each a vertical
///              cylinder (centre c, radius r: the neighbour's footprint grown by the gripper's) up to
///              a height z_top (its top plus a clearance). The target never has both |xy - c| < r
///              and z < z_top: a target inside the circle (above the part) is held at z_top at least,
///              and a target below z_top is held on the circle's edge (projected radially). Hard and
///              independent of the level, like the funnel; the master's own target goes with it (no
///              wind-up: leaving the region never jumps). A region installed round a target already
///              inside it and below its top holds nothing until the target has left it.
///
/// The assistance level follows its set value at a bounded rate, from 0 whenever the guide moves
/// (no jump in the target).
/// Everything here is real-time safe: no allocation, lock, exception or I/O.

#include <array>
#include <cmath>
#include <limits>

#include <Eigen/Core>

namespace mc::teleop {

struct VirtualFixtureParams {
  double capture_radius_m = 25e-6;  ///< R: full guidance within it, none beyond 2R
  double far_gain = 4.0;            ///< motion-scale gain at far_distance_m and beyond (level 1)
  double far_distance_m = 600e-6;   ///< distance to the guide where the gain is full
  /// Where the fixtures act the target moves no faster than this: a target running far ahead
  /// of the stick-slip stage (0.5-1.2 mm/s at most, by axis and load) makes it overshoot.
  double max_speed_m_s = 0.5e-3;
  double display_stiffness_N_m = 60.0;  ///< k: hand newtons per hand metre (below the finger's 228 N/m)
  double max_display_N = 1.0;           ///< cap on the guidance force on the handle
  double funnel_half_angle_deg = 60.0;  ///< the funnel's cone, from the vertical
  double funnel_height_m = 60e-6;       ///< above the rim, where the funnel begins
  double level_rate_1_s = 2.0;          ///< the assistance level's largest rate of change
  double height_capture_m = 25e-6;      ///< H: a height stop holds within it, lets go beyond 2H
  /// A yaw stop (rotary_axis.h) holds within it, lets go beyond twice it: 20 mrad (1.15 deg), the
  /// turn within which a 300 um pin still fits a bore of 3 um radial clearance (docs/cell.md).
  double yaw_capture_rad = 0.02;

  template <class V>
  void visit(V& v) {
    v("capture_radius_m", capture_radius_m);
    v("far_gain", far_gain);
    v("far_distance_m", far_distance_m);
    v("max_speed_m_s", max_speed_m_s);
    v("display_stiffness_N_m", display_stiffness_N_m);
    v("max_display_N", max_display_N);
    v("funnel_half_angle_deg", funnel_half_angle_deg);
    v("funnel_height_m", funnel_height_m);
    v("level_rate_1_s", level_rate_1_s);
    v("height_capture_m", height_capture_m);
    v("yaw_capture_rad", yaw_capture_rad);
  }
  /// Throws mc::InvalidParams naming the field.
  void validate() const;
};

/// The fixtures for the coming ticks, in the coupling's coordinates (stage, relative to home).
struct FixtureSet {
  double level = 0.0;  ///< assistance level in [0, 1] (0: none)
  bool guide = false;  ///< a vertical insertion axis at guide_xy_m
  Eigen::Vector2d guide_xy_m = Eigen::Vector2d::Zero();
  bool path = false;  ///< guidance along the segment from path_from_xy_m to guide_xy_m (needs `guide`)
  Eigen::Vector2d path_from_xy_m = Eigen::Vector2d::Zero();
  bool funnel = false;           ///< the forbidden region round the axis' rim (needs `guide`)
  double rim_z_m = 0.0;          ///< tool-point height at which the part meets the rim
  double funnel_radius_m = 0.0;  ///< r0: the allowed distance to the axis at the rim
  bool height = false;           ///< a height stop at height_z_m (at the set's level)
  double height_z_m = 0.0;       ///< tool-point height of the stop
  bool yaw = false;  ///< a yaw stop at yaw_rad on the rotary axis (rotary_axis.h, at the set's level)
  double yaw_rad = 0.0;
  /// A forbidden cylinder round a neighbouring part (header, keep-out).
  struct KeepOut {
    Eigen::Vector2d xy_m = Eigen::Vector2d::Zero();
    double radius_m = 0.0;
    double top_z_m = 0.0;  ///< tool-point height below which the circle is forbidden
    bool operator==(const KeepOut& o) const noexcept {
      return xy_m == o.xy_m && radius_m == o.radius_m && top_z_m == o.top_z_m;
    }
  };
  static constexpr int kMaxKeepOuts = 8;
  std::array<KeepOut, kMaxKeepOuts> keep_outs{};
  int keep_out_count = 0;  ///< the first keep_out_count of keep_outs are in force
  bool operator==(const FixtureSet& o) const noexcept {
    return level == o.level && guide == o.guide && guide_xy_m == o.guide_xy_m && path == o.path &&
           path_from_xy_m == o.path_from_xy_m && funnel == o.funnel && rim_z_m == o.rim_z_m &&
           funnel_radius_m == o.funnel_radius_m && height == o.height && height_z_m == o.height_z_m &&
           yaw == o.yaw && yaw_rad == o.yaw_rad && keep_out_count == o.keep_out_count &&
           keep_outs == o.keep_outs;
  }
};

class VirtualFixtures {
 public:
  /// Validates (throws mc::InvalidParams).
  explicit VirtualFixtures(const VirtualFixtureParams& params);

  /// Installs `set` for the coming ticks (its level is reached at level_rate_1_s; a guide that
  /// moves starts again from level 0). Invalid
  /// numbers (NaN, a level outside [0, 1]) remove the fixtures instead. Real-time safe.
  void set(const FixtureSet& set) noexcept;
  const FixtureSet& fixtures() const noexcept { return set_; }
  /// The assistance level in force now.
  double level() const noexcept { return level_; }
  /// Slews the level for one tick of `dt_s`.
  void tick(double dt_s) noexcept;
  bool active() const noexcept { return set_.guide && (level_ > 0.0 || set_.funnel); }
  /// The height stop acts (its level above zero).
  bool height_active() const noexcept { return set_.height && height_level_ > 0.0; }

  /// The motion-scale gain g(d) at the target `xy` (1 without a guide).
  double scale_gain(const Eigen::Vector2d& xy) const noexcept;
  /// The guided target for the master's raw target.
  Eigen::Vector2d guided(const Eigen::Vector2d& raw_xy) const noexcept;
  /// The guide's point nearest `xy`: guide_xy_m, or along a path the segment's nearest point.
  Eigen::Vector2d nearest_guide(const Eigen::Vector2d& xy) const noexcept;
  /// The guided height for the master's raw height (raw_z without a height stop).
  double guided_z(double raw_z) const noexcept;
  /// `xy` kept within the funnel's radius r0 of the axis when `z` is below the rim (the part in
  /// its bore); `xy` otherwise, or without a funnel.
  Eigen::Vector2d confined_xy(const Eigen::Vector2d& xy, double z) const noexcept;
  /// Keeps `to`, the target after a tick that started at `from`, out of the keep-out regions
  /// (header); true if it moved it.
  bool keep_out(const Eigen::Vector3d& from, Eigen::Vector3d& to) const noexcept;
  /// `p` is inside a keep-out region (within its circle, below its top).
  bool in_keep_out(const Eigen::Vector3d& p) const noexcept;
  /// The lowest z allowed at `xy` (-inf without a funnel) for a target now at `from_z`: a target
  /// already in the bore (below the rim) is held by confined_xy, never lifted out by the cone.
  double lowest_z(const Eigen::Vector2d& xy,
                  double from_z = std::numeric_limits<double>::infinity()) const noexcept;
  /// The guidance felt on a haptic handle moving at `handle_v` (hand frame), with the passivity
  /// controller; `scale` is the motion scale in force.
  Eigen::Vector2d display_force(const Eigen::Vector2d& raw_xy, const Eigen::Vector2d& guided_xy,
                                const Eigen::Vector2d& handle_v_m_s, double scale, double dt_s) noexcept;
  /// Re-books the field's energy at the handle (a new fixture set, an engagement): the start of
  /// the passivity observer's account.
  void rebase_energy(const Eigen::Vector2d& raw_xy, double scale) noexcept;
  /// The passivity observer E (>= 0 up to rounding) and what the controller dissipated [J].
  double observed_J() const noexcept { return observed_J_; }
  double dissipated_J() const noexcept { return dissipated_J_; }

 private:
  double weight(double d) const noexcept;
  /// Phi(d) at level `a` and scale `s`.
  double potential_J(double d, double a, double s) const noexcept;

  VirtualFixtureParams p_;
  FixtureSet set_;
  double level_ = 0.0;
  double height_level_ = 0.0;  // the height stop's own level (from 0 when the stop moves)
  double tan_cone_ = 1.0;
  double observed_J_ = 0.0, dissipated_J_ = 0.0;
  bool rebase_ = true;
};

}  // namespace mc::teleop
