#include "microcobot/motion/parallel_workspace.h"

#include <array>
#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/format.h>

namespace mc::motion {

namespace {

constexpr double kDegreesPerRadian = 180.0 / std::numbers::pi;
constexpr std::array<const char*, 6> kCoordinateNames = {"x", "y", "z", "rx", "ry", "rz"};

}  // namespace

std::string to_string(Reach r) {
  switch (r) {
    case Reach::kReachable:
      return "reachable";
    case Reach::kNotFinite:
      return "not finite";
    case Reach::kOutOfReach:
      return "out of reach";
    case Reach::kSingular:
      return "singular";
    case Reach::kStrokeLimit:
      return "stroke limit";
    case Reach::kJointLimit:
      return "joint limit";
  }
  return "reachable";
}

namespace {

// What failed, for the check's detail: the leg or positioner and the quantity beyond its limit.
struct Failure {
  Reach reach = Reach::kReachable;
  int index = 0;       // the leg (out of reach, joints) or the positioner (stroke)
  double value = 0.0;  // the conditioning, the positioner's q [m] or the joint's angle [rad]
  bool revolute = false;
};

// The header's checks in order, without a word of text: nothing allocates. `conditioning`: the
// Jacobian's conditioning is computed (an SVD) where a bound would decide the check alone.
Failure classify(const ParallelKinematics& k, const PlatformTransform& T, LegCoordinates& q,
                 double* conditioning) noexcept {
  if (!T.R.allFinite() || !T.d.allFinite()) {
    q.setConstant(std::numeric_limits<double>::quiet_NaN());
    return {Reach::kNotFinite};
  }
  const ParallelGeometryParams& p = k.params();
  LegClosure legs[kParallelLegs];
  if (!k.closures(T, legs, q)) {
    q.setConstant(std::numeric_limits<double>::quiet_NaN());
    for (int i = 0; i < kParallelLegs; ++i)
      if (!(legs[i].discriminant >= 0.0)) return {Reach::kOutOfReach, i};
    return {Reach::kOutOfReach};
  }
  const ParallelJacobian J = k.jacobian(T, legs);
  if (conditioning != nullptr) {
    *conditioning = k.conditioning(J);
    if (*conditioning < p.min_conditioning) return {Reach::kSingular, 0, *conditioning};
  } else if (!k.conditioning_at_least(J, p.min_conditioning)) {
    return {Reach::kSingular, 0, k.conditioning(J)};
  }
  const double half = 0.5 * p.stroke_m;
  for (int j = 0; j < 6; ++j)
    if (std::abs(q[j]) > half) return {Reach::kStrokeLimit, j, q[j]};
  double sph[kParallelLegs], rev[kParallelLegs];
  k.joint_angles(T, legs, sph, rev);
  for (int i = 0; i < kParallelLegs; ++i) {
    if (sph[i] > p.spherical_limit_rad) return {Reach::kJointLimit, i, sph[i], false};
    if (std::abs(rev[i]) > p.revolute_limit_rad) return {Reach::kJointLimit, i, rev[i], true};
  }
  return {};
}

}  // namespace

Reach reach_of(const ParallelKinematics& k, const PlatformTransform& T, LegCoordinates& q) noexcept {
  return classify(k, T, q, nullptr).reach;
}

ReachCheck check_pose(const ParallelKinematics& k, const PlatformTransform& T) {
  ReachCheck c;
  const Failure f = classify(k, T, c.q, &c.conditioning);
  c.reach = f.reach;
  const ParallelGeometryParams& p = k.params();
  switch (f.reach) {
    case Reach::kReachable:
      break;
    case Reach::kNotFinite:
      c.detail = "the pose has a NaN or infinite coordinate";
      break;
    case Reach::kOutOfReach:
      c.detail =
          fmt::format("leg {} cannot close (its {:.4g} mm leg does not reach the base plane's carriage)",
                      f.index, k.geometry().leg_length_m * 1e3);
      break;
    case Reach::kSingular:
      c.detail = fmt::format("conditioning {:.3g} < {:g}", f.value, p.min_conditioning);
      break;
    case Reach::kStrokeLimit:
      c.detail =
          fmt::format("leg {}'s {} positioner at {:.6g} mm beyond its stroke +-{:g} mm", f.index / 2,
                      f.index % 2 == 0 ? "radial" : "tangential", f.value * 1e3, 0.5 * p.stroke_m * 1e3);
      break;
    case Reach::kJointLimit:
      c.detail =
          f.revolute
              ? fmt::format("leg {}'s revolute joint at {:.4g} deg beyond +-{:.4g} deg", f.index,
                            f.value * kDegreesPerRadian, p.revolute_limit_rad * kDegreesPerRadian)
              : fmt::format("leg {}'s spherical joint at {:.4g} deg beyond its {:.4g} deg cone", f.index,
                            f.value * kDegreesPerRadian, p.spherical_limit_rad * kDegreesPerRadian);
      break;
  }
  return c;
}

ReachCheck check_pose(const ParallelKinematics& k, const SmarPodPose& p, const Pivot& pivot) {
  if (!is_finite(p) || !pivot.point_m.allFinite()) {
    ReachCheck c;
    c.reach = Reach::kNotFinite;
    c.detail = "the pose or its pivot has a NaN or infinite coordinate";
    c.q.setConstant(std::numeric_limits<double>::quiet_NaN());
    return c;
  }
  return check_pose(k, to_transform(p, pivot));
}

PoseUnreachable::PoseUnreachable(const SmarPodPose& p, const ReachCheck& c)
    : InvalidInput("pose " + describe(p) + " unreachable: " + to_string(c.reach) + ": " + c.detail),
      reason_(c.reach) {}

LegCoordinates inverse_checked(const ParallelKinematics& k, const SmarPodPose& p, const Pivot& pivot) {
  const ReachCheck c = check_pose(k, p, pivot);
  if (!c.ok()) throw PoseUnreachable(p, c);
  return c.q;
}

RotationRange rotation_range(const ParallelKinematics& k, const SmarPodPose& at, int axis,
                             const Pivot& pivot) {
  require(axis >= 0 && axis <= 2, "axis", "must be 0 (rx), 1 (ry) or 2 (rz)", axis);
  const ReachCheck start = check_pose(k, at, pivot);
  if (!start.ok()) throw PoseUnreachable(at, start);
  auto a0 = at.as_array();
  const double centre = a0[3 + axis];
  const auto reach_at = [&](double angle) {
    auto a = a0;
    a[3 + axis] = angle;
    return check_pose(k, SmarPodPose::from_array(a), pivot).reach;
  };
  RotationRange out;
  constexpr double kScan = 0.25 / kDegreesPerRadian;
  for (int sign : {-1, +1}) {
    double inside = centre, outside = centre;
    Reach why = Reach::kReachable;
    while (std::abs(outside - centre) < 0.5 * std::numbers::pi) {
      outside = centre + sign * std::min(std::abs(outside - centre) + kScan, 0.5 * std::numbers::pi);
      why = reach_at(outside);
      if (why != Reach::kReachable) break;
      inside = outside;
    }
    if (why != Reach::kReachable) {
      while (std::abs(outside - inside) > 1e-9) {
        const double mid = 0.5 * (inside + outside);
        const Reach r = reach_at(mid);
        if (r == Reach::kReachable) {
          inside = mid;
        } else {
          outside = mid;
          why = r;
        }
      }
    }
    (sign < 0 ? out.min_rad : out.max_rad) = inside;
    (sign < 0 ? out.min_reason : out.max_reason) = why;
  }
  return out;
}

void SliceSpec::validate() const {
  require(axis_a >= 0 && axis_a < 6, "axis_a", "must be a pose coordinate 0..5", axis_a);
  require(axis_b >= 0 && axis_b < 6 && axis_b != axis_a, "axis_b",
          "must be a pose coordinate 0..5 other than axis_a", axis_b);
  require(std::isfinite(lo_a) && std::isfinite(hi_a) && lo_a < hi_a, "lo_a", "must be finite and < hi_a",
          lo_a);
  require(std::isfinite(lo_b) && std::isfinite(hi_b) && lo_b < hi_b, "lo_b", "must be finite and < hi_b",
          lo_b);
  require(n_a >= 2 && n_a <= 2001, "n_a", "must be within [2, 2001]", n_a);
  require(n_b >= 2 && n_b <= 2001, "n_b", "must be within [2, 2001]", n_b);
  require(is_finite(base), "base", "must be finite");
}

CsvTable workspace_slice(const ParallelKinematics& k, const SliceSpec& s) {
  s.validate();
  CsvTable t;
  for (const char* name : {"x_m", "y_m", "z_m", "rx_rad", "ry_rad", "rz_rad", "reach", "conditioning"}) {
    t.add_column(name, {});
  }
  std::array<double, 8> row{};
  for (int ib = 0; ib < s.n_b; ++ib) {
    for (int ia = 0; ia < s.n_a; ++ia) {
      auto a = s.base.as_array();
      a[s.axis_a] = s.lo_a + (s.hi_a - s.lo_a) * ia / (s.n_a - 1);
      a[s.axis_b] = s.lo_b + (s.hi_b - s.lo_b) * ib / (s.n_b - 1);
      const ReachCheck c = check_pose(k, SmarPodPose::from_array(a), s.pivot);
      for (int j = 0; j < 6; ++j) row[j] = a[j];
      row[6] = static_cast<double>(c.reach);
      row[7] = c.conditioning;
      t.add_row(row);
    }
  }
  return t;
}

const char* pose_coordinate_name(int index) { return kCoordinateNames.at(static_cast<std::size_t>(index)); }

int parse_pose_coordinate(const std::string& name) {
  for (int i = 0; i < 6; ++i) {
    if (name == kCoordinateNames[i]) return i;
  }
  throw UsageError("a pose coordinate must be x, y, z, rx, ry or rz (got '" + name + "')");
}

}  // namespace mc::motion
