#pragma once
/// @file
/// The parallel positioner's workspace: whether a pose is reachable and, if not, why; the travel
/// of each rotation at a given position; a slice of the workspace over two pose coordinates.
///
/// A pose is reachable when, in this order (the first that fails is the reason):
///  1. every number is finite (kNotFinite);
///  2. every leg closes: the closure's discriminant rho^2 - c^2 >= 0 (parallel_kinematics.h;
///     kOutOfReach, e.g. the platform raised beyond the legs' length);
///  3. the conditioning is at least params.min_conditioning (kSingular; at a double root of a
///     leg's closure or where the held positioners no longer hold the platform);
///  4. every positioner within its stroke, |q_k| <= stroke_m / 2 (kStrokeLimit);
///  5. every passive joint within its limit: the spherical joint's cone and the revolute joint's
///     travel (kJointLimit).

#include <string>

#include "microcobot/core/csv.h"
#include "microcobot/core/error.h"
#include "microcobot/motion/parallel_kinematics.h"

namespace mc::motion {

enum class Reach {
  kReachable = 0,
  kNotFinite = 1,
  kOutOfReach = 2,
  kSingular = 3,
  kStrokeLimit = 4,
  kJointLimit = 5
};
/// "reachable", "not finite", "out of reach", "singular", "stroke limit", "joint limit".
std::string to_string(Reach r);

struct ReachCheck {
  Reach reach = Reach::kReachable;
  /// What failed, e.g. "leg 1's tangential positioner at 7.2 mm beyond its stroke +-6 mm".
  std::string detail;
  LegCoordinates q = LegCoordinates::Zero();  ///< valid when the legs close (reach >= kSingular)
  double conditioning = 0.0;
  bool ok() const noexcept { return reach == Reach::kReachable; }
};

/// The check of the header, for the platform transform `T`.
ReachCheck check_pose(const ParallelKinematics& k, const PlatformTransform& T);
/// The same check without its words, for the loop: the first reason that fails (kReachable when
/// none), `q` the legs' coordinates where they close. Never allocates.
Reach reach_of(const ParallelKinematics& k, const PlatformTransform& T, LegCoordinates& q) noexcept;
/// The same for a SmarPod pose about `pivot` (a NaN in the pose is kNotFinite).
ReachCheck check_pose(const ParallelKinematics& k, const SmarPodPose& p, const Pivot& pivot = {});

/// A refused pose: "pose (x, y, z) mm, (rx, ry, rz) deg unreachable: <reason>: <detail>". Exit 3.
class PoseUnreachable : public InvalidInput {
 public:
  PoseUnreachable(const SmarPodPose& p, const ReachCheck& c);
  Reach reason() const noexcept { return reason_; }

 private:
  Reach reason_;
};

/// The leg coordinates of a reachable pose; throws PoseUnreachable otherwise.
LegCoordinates inverse_checked(const ParallelKinematics& k, const SmarPodPose& p, const Pivot& pivot = {});

/// The travel of one rotation (rx, ry or rz: index 0, 1, 2) at the translation and other angles of
/// `at`, about `pivot`: the interval around the angle of `at` over which every pose is reachable,
/// each end to 1e-9 rad (a scan by 0.25 deg from `at`, then bisection), searched within
/// +-pi/2; with the reason each end stops at. `at` itself must be reachable (else PoseUnreachable).
struct RotationRange {
  double min_rad = 0.0, max_rad = 0.0;
  Reach min_reason = Reach::kReachable, max_reason = Reach::kReachable;  ///< kReachable: pi/2 reached
};
RotationRange rotation_range(const ParallelKinematics& k, const SmarPodPose& at, int axis,
                             const Pivot& pivot = {});

/// A rectangular slice of the workspace: `base`'s coordinates, with the two named coordinates
/// (0..5: x, y, z, rx, ry, rz) swept over [lo, hi] in n points each.
struct SliceSpec {
  SmarPodPose base;
  Pivot pivot;
  int axis_a = 0, axis_b = 1;
  double lo_a = -6e-3, hi_a = 6e-3, lo_b = -6e-3, hi_b = 6e-3;
  int n_a = 41, n_b = 41;
  void validate() const;  ///< throws InvalidParams naming the field
};
/// One row per grid point, columns x_m, y_m, z_m, rx_rad, ry_rad, rz_rad, reach (the Reach code),
/// conditioning (0 where a leg does not close).
CsvTable workspace_slice(const ParallelKinematics& k, const SliceSpec& s);

/// "x", "y", "z", "rx", "ry", "rz" for 0..5, and back (else UsageError).
const char* pose_coordinate_name(int index);
int parse_pose_coordinate(const std::string& name);

}  // namespace mc::motion
