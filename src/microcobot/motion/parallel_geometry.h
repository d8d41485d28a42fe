#pragma once
/// @file
/// The leg structure and dimensions of the 6-DOF parallel stick-slip positioner of the thesis's
/// microrobot (T. Lu, "Design and Realization of a Desktop Micro-manipulation Cobotic Platform",
/// PhD thesis, Université Pierre et Marie Curie, 2016: §2.3, Fig. 2.4, "a 6 DOF parallel robot",
/// a SmarPod 110.45 (Fig. 2.1b) whose axes are all SmarAct SLC-1720-S-HV stick-slip positioners).
/// The vendor does not publish the legs; this is a structure of that class that six linear
/// positioners can drive (docs/concepts/parallel-positioner.md; what is assumed: docs/errata.md).
///
/// Structure (3 x PPSR): three legs at the angles phi_i = pi/2 + i 2pi/3 about the base's
/// centre. Each leg is
///  - a two-axis carriage in the base plane: two stacked linear positioners, the lower along the
///    leg's radial direction e_r = (cos phi, sin phi, 0), the upper along its tangential direction
///    e_t = (-sin phi, cos phi, 0); they carry the centre of a spherical joint to
///    B_i = b e_r + u_i e_r + w_i e_t (z = 0 is the plane of these joint centres);
///  - a rigid leg of length L from that spherical joint to
///  - a revolute joint on the platform at p_i = r e_r - o e_z (in the platform's frame {P}, whose
///    origin is the top plate's centre, o above the joints' plane) whose axis is a_i = e_t.
/// Each chain has 2 actuated + 4 passive DOF, so that three of them leave the platform 6 DOF and,
/// the six positioners held, none. At home the platform is level, its joints at height h above the
/// carriages', and every leg lies in its radial plane: L = sqrt((b - r)^2 + h^2).
/// The leg coordinates are q = (u_0, w_0, u_1, w_1, u_2, w_2) [m], 0 at home (mid-stroke).
///
/// The home frame {H} is {P} at home: its origin at (0, 0, h + o) in the base frame {B}.

#include <Eigen/Core>

namespace mc::motion {

inline constexpr int kParallelLegs = 3;

struct ParallelGeometryParams {
  /// b: radius of the carriages' spherical joints at home. 40 mm keeps the carriages (two
  /// stacked 17 mm-wide SLC-1720) inside a 110 mm base.
  double base_radius_m = 40e-3;
  /// r: radius of the platform's revolute joints.
  double platform_radius_m = 20e-3;
  /// h: height of the platform's joints above the carriages' at home (legs at 45 deg: L = 28.3 mm).
  double joint_height_m = 20e-3;
  /// o: the top plate's surface (the platform frame's origin, the default pivot) above the
  /// platform's joints; with the carriages' joints 17 mm above the underside, 17 + 20 + 8 = 45 mm.
  double top_offset_m = 8e-3;
  /// Each positioner's travel (SLC-1720: 12 mm, thesis §2.3), centred on home: +-6 mm.
  double stroke_m = 12e-3;
  /// The spherical joint's cone: the leg within this angle of its home direction.
  double spherical_limit_rad = 0.5235987755982988;  // 30 deg
  /// The revolute joint's travel about its home angle.
  double revolute_limit_rad = 0.5235987755982988;  // 30 deg
  /// A pose whose conditioning (ParallelKinematics::conditioning) is below this is singular: the
  /// platform's motion per metre of the legs' is over 1 / min_conditioning times larger in its
  /// worst direction than in its best.
  double min_conditioning = 0.02;

  template <class V>
  void visit(V& v) {
    v("base_radius_m", base_radius_m);
    v("platform_radius_m", platform_radius_m);
    v("joint_height_m", joint_height_m);
    v("top_offset_m", top_offset_m);
    v("stroke_m", stroke_m);
    v("spherical_limit_rad", spherical_limit_rad);
    v("revolute_limit_rad", revolute_limit_rad);
    v("min_conditioning", min_conditioning);
  }
  /// Throws mc::InvalidParams naming the field.
  void validate() const;

  /// L = sqrt((b - r)^2 + h^2).
  double leg_length_m() const noexcept;
  /// Height of {H}'s origin above the base frame's: h + o.
  double home_height_m() const noexcept { return joint_height_m + top_offset_m; }
};

/// The constant vectors of one leg, computed once from the parameters.
struct LegGeometry {
  Eigen::Vector3d e_r;         ///< the carriage's radial axis (lower positioner), {B}
  Eigen::Vector3d e_t;         ///< the carriage's tangential axis (upper positioner), {B}
  Eigen::Vector3d base_m;      ///< b e_r: the spherical joint's centre at home, {B}
  Eigen::Vector3d platform_m;  ///< p_i = r e_r - o e_z: the revolute joint's centre, {P}
  Eigen::Vector3d axis;        ///< a_i = e_t: the revolute joint's axis, {P}
  Eigen::Vector3d home_leg;    ///< unit vector from the spherical joint to the revolute at home
};

/// The three legs' vectors for `p` (validated).
struct ParallelGeometry {
  explicit ParallelGeometry(const ParallelGeometryParams& p);
  ParallelGeometryParams params;
  LegGeometry legs[kParallelLegs];
  double leg_length_m = 0.0;
  double home_height_m = 0.0;
};

}  // namespace mc::motion
