// microcobot.positioner: the 6-DOF parallel positioner's kinematics over numpy arrays, the same
// library calls as `microcobot positioner params|ik|fk|workspace` (motion/parallel_geometry.h,
// parallel_kinematics.h, parallel_workspace.h, pose.h). Poses are rows of six numbers in SmarPod's
// or PI's convention about a pivot; leg coordinates rows of six. Only conversion lives here: the
// kinematics, the checks and the conventions are the library's.

#include <algorithm>
#include <numbers>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <Eigen/Core>
#include <Eigen/LU>

#include "common.h"
#include "microcobot/motion/parallel_kinematics.h"
#include "microcobot/motion/parallel_workspace.h"
#include "microcobot/motion/pose.h"

namespace mc::py {
namespace {

namespace mm = mc::motion;
using K = mm::ParallelKinematics;
using namespace pybind11::literals;

constexpr double kDeg = std::numbers::pi / 180.0;

/// How six numbers are a pose: the convention and the pivot (the CLI's --convention, --pivot,
/// --pivot-mode).
struct PoseFrame {
  bool pi = false;
  mm::Pivot pivot;
};

PoseFrame frame_of(const std::string& convention, py::handle pivot, const std::string& mode) {
  PoseFrame f;
  if (convention != "smarpod" && convention != "pi")
    throw InvalidInput("convention: must be 'smarpod' or 'pi' (got '" + convention + "')");
  if (mode != "relative" && mode != "fixed")
    throw InvalidInput("pivot_mode: must be 'relative' or 'fixed' (got '" + mode + "')");
  f.pi = convention == "pi";
  f.pivot.mode = mm::parse_pivot_mode(mode);
  if (f.pi && f.pivot.mode == mm::PivotMode::kFixed)
    throw InvalidInput(
        "pivot_mode 'fixed': PI's pivot always moves with the platform (use convention 'smarpod')");
  if (!pivot.is_none()) {
    const auto p = DoubleArray::ensure(pivot);
    if (!p || p.ndim() != 1 || p.shape(0) != 3) throw InvalidInput("pivot: expected 3 numbers (x, y, z) [m]");
    check_array(p, "pivot", 1, 3);
    f.pivot.point_m = {p.at(0), p.at(1), p.at(2)};
  }
  return f;
}

mm::PlatformTransform transform_of(const double* v, const PoseFrame& f) {
  if (f.pi) return mm::to_transform(mm::PiPose{v[0], v[1], v[2], v[3], v[4], v[5]}, f.pivot.point_m);
  return mm::to_transform(mm::SmarPodPose{v[0], v[1], v[2], v[3], v[4], v[5]}, f.pivot);
}

void pose_of(const mm::PlatformTransform& T, const PoseFrame& f, double* v) {
  if (f.pi) {
    const mm::PiPose p = mm::to_pi(T, f.pivot.point_m);
    const double a[6] = {p.X, p.Y, p.Z, p.U, p.V, p.W};
    std::copy(a, a + 6, v);
  } else {
    const auto a = mm::to_smarpod(T, f.pivot).as_array();
    std::copy(a.begin(), a.end(), v);
  }
}

/// "(x, y, z) mm, (rx, ry, rz) deg", the library's way of naming a pose; PI's numbers say so.
std::string describe_row(const double* v, const PoseFrame& f) {
  return mm::describe(mm::SmarPodPose{v[0], v[1], v[2], v[3], v[4], v[5]}) +
         (f.pi ? " (PI's X Y Z U V W)" : "");
}

py::list reach_names() {
  py::list l;
  for (int c = 0; c <= static_cast<int>(mm::Reach::kJointLimit); ++c)
    l.append(mm::to_string(static_cast<mm::Reach>(c)));
  return l;
}

py::array_t<double> ik(const K& k, py::handle poses, py::handle out, const std::string& convention,
                       py::handle pivot, const std::string& mode) {
  const PoseFrame f = frame_of(convention, pivot, mode);
  const ArrayRows b = array_rows(poses, "poses", {6});
  auto o = output_array(out, b.shape({6}), {&b});
  const double* in = b.a.data();
  double* q = o.mutable_data();
  nogil([&] {
    for (py::ssize_t i = 0; i < b.n; ++i) {
      double v[6];
      std::copy(in + 6 * i, in + 6 * i + 6, v);
      const mm::ReachCheck c = mm::check_pose(k, transform_of(v, f));
      if (!c.ok()) {
        throw InvalidInput(fmt::format("{}: pose {} unreachable: {}: {}", b.row(i), describe_row(v, f),
                                       mm::to_string(c.reach), c.detail));
      }
      std::copy(c.q.data(), c.q.data() + 6, q + 6 * i);
    }
  });
  return o;
}

py::array_t<double> fk(const K& k, py::handle legs, py::handle guess, py::handle out,
                       const std::string& convention, py::handle pivot, const std::string& mode) {
  const PoseFrame f = frame_of(convention, pivot, mode);
  const ArrayRows b = array_rows(legs, "legs", {6});
  ArrayRows g;
  const bool guessed = !guess.is_none();
  if (guessed) {
    g = array_rows(guess, "guess", {6});
    if (!g.single && g.n != b.n)
      throw InvalidInput(
          fmt::format("guess: expected one pose or one per row of legs ({}), got {}", b.n, g.n));
    require_finite(g);
  }
  auto o = output_array(out, b.shape({6}), {&b, guessed ? &g : nullptr});
  const double* in = b.a.data();
  const double* seeds = guessed ? g.a.data() : nullptr;
  double* pose = o.mutable_data();
  nogil([&] {
    for (py::ssize_t i = 0; i < b.n; ++i) {
      const mm::LegCoordinates q = Eigen::Map<const mm::LegCoordinates>(in + 6 * i);
      const mm::PlatformTransform seed =
          seeds ? transform_of(seeds + (g.single ? 0 : 6 * i), f) : mm::PlatformTransform{};
      mm::ForwardResult r;
      try {
        r = k.forward(q, seed);
      } catch (const ComputationFailed& e) {
        throw ComputationFailed(b.row(i) + ": " + e.what());
      } catch (const InvalidInput& e) {
        throw InvalidInput(b.row(i) + ": " + e.what());
      }
      pose_of(r.T, f, pose + 6 * i);
    }
  });
  return o;
}

py::object reach(const K& k, py::handle poses, const PoseFrame& f, bool details) {
  const ArrayRows b = array_rows(poses, "poses", {6});
  py::array_t<bool> ok(b.n);
  py::array_t<int> code(b.n);
  py::array_t<double> cond(b.n);
  std::vector<std::string> reason(static_cast<std::size_t>(b.n)), detail(reason.size());
  const double* in = b.a.data();
  bool* okp = ok.mutable_data();
  int* codep = code.mutable_data();
  double* condp = cond.mutable_data();
  nogil([&] {
    for (py::ssize_t i = 0; i < b.n; ++i) {
      mm::ReachCheck c = mm::check_pose(k, transform_of(in + 6 * i, f));
      okp[i] = c.ok();
      codep[i] = static_cast<int>(c.reach);
      condp[i] = c.conditioning;
      if (!details) continue;
      reason[i] = mm::to_string(c.reach);
      detail[i] = std::move(c.detail);
    }
  });
  if (!details) return per_row(ok, b.single);
  return py::dict("reachable"_a = per_row(ok, b.single), "code"_a = per_row(code, b.single),
                  "reason"_a = per_row(py::cast(reason), b.single),
                  "detail"_a = per_row(py::cast(detail), b.single),
                  "conditioning"_a = per_row(cond, b.single));
}

py::array_t<double> jacobian(const K& k, py::handle poses, py::handle out, const std::string& convention,
                             py::handle pivot, const std::string& mode) {
  const PoseFrame f = frame_of(convention, pivot, mode);
  const ArrayRows b = array_rows(poses, "poses", {6});
  auto o = output_array(out, b.shape({6, 6}), {&b});
  const double* in = b.a.data();
  double* J = o.mutable_data();
  nogil([&] {
    for (py::ssize_t i = 0; i < b.n; ++i) {
      double v[6];
      std::copy(in + 6 * i, in + 6 * i + 6, v);
      const mm::PlatformTransform T = transform_of(v, f);
      const mm::ReachCheck c = mm::check_pose(k, T);
      const mm::ParallelJacobian Ji = k.jacobian(T);
      if (c.reach == mm::Reach::kNotFinite || c.reach == mm::Reach::kOutOfReach || !Ji.allFinite()) {
        throw InvalidInput(fmt::format("{}: pose {} has no Jacobian: {}: {}", b.row(i), describe_row(v, f),
                                       mm::to_string(c.reach),
                                       c.ok() ? "a leg at its double root" : c.detail));
      }
      Eigen::Map<Eigen::Matrix<double, 6, 6, Eigen::RowMajor>>(J + 36 * i) = Ji;
    }
  });
  return o;
}

py::object reachable(const K& k, py::handle poses, const std::string& convention, py::handle pivot,
                     const std::string& mode) {
  return reach(k, poses, frame_of(convention, pivot, mode), false);
}

py::object check(const K& k, py::handle poses, const std::string& convention, py::handle pivot,
                 const std::string& mode) {
  return reach(k, poses, frame_of(convention, pivot, mode), true);
}

py::object conditioning(const K& k, py::handle poses, const std::string& convention, py::handle pivot,
                        const std::string& mode) {
  const PoseFrame f = frame_of(convention, pivot, mode);
  const ArrayRows b = array_rows(poses, "poses", {6});
  require_finite(b);
  py::array_t<double> c(b.n);
  const double* in = b.a.data();
  double* cp = c.mutable_data();
  nogil([&] {
    for (py::ssize_t i = 0; i < b.n; ++i) cp[i] = k.conditioning(transform_of(in + 6 * i, f));
  });
  return per_row(c, b.single);
}

py::dict rotation_range(const K& k, py::handle at, const std::string& axis, py::handle pivot,
                        const std::string& mode) {
  const PoseFrame f = frame_of("smarpod", pivot, mode);
  const int index = mm::parse_pose_coordinate(axis) - 3;
  if (index < 0) throw InvalidInput("axis: must be 'rx', 'ry' or 'rz' (got '" + axis + "')");
  const ArrayRows b = array_rows(at, "at", {6});
  py::array_t<double> lo(b.n), hi(b.n);
  std::vector<std::string> lo_why(static_cast<std::size_t>(b.n)), hi_why(lo_why.size());
  const double* in = b.a.data();
  double* lop = lo.mutable_data();
  double* hip = hi.mutable_data();
  nogil([&] {
    for (py::ssize_t i = 0; i < b.n; ++i) {
      const double* v = in + 6 * i;
      mm::RotationRange r;
      try {
        r = mm::rotation_range(k, mm::SmarPodPose{v[0], v[1], v[2], v[3], v[4], v[5]}, index, f.pivot);
      } catch (const InvalidInput& e) {
        throw InvalidInput(b.row(i) + ": " + e.what());
      }
      lop[i] = r.min_rad;
      hip[i] = r.max_rad;
      lo_why[i] = mm::to_string(r.min_reason);
      hi_why[i] = mm::to_string(r.max_reason);
    }
  });
  return py::dict("min_rad"_a = per_row(lo, b.single), "max_rad"_a = per_row(hi, b.single),
                  "min_reason"_a = per_row(py::cast(lo_why), b.single),
                  "max_reason"_a = per_row(py::cast(hi_why), b.single));
}

std::pair<double, double> range_of(py::handle given, const char* name, int axis, double centre) {
  if (given.is_none()) {
    // The command line's default span about the base pose: +-8 mm of translation, +-15 deg of rotation.
    const double half = axis < 3 ? 8e-3 : 15 * kDeg;
    return {centre - half, centre + half};
  }
  const auto r = DoubleArray::ensure(given);
  if (!r || r.ndim() != 1 || r.shape(0) != 2 || !std::isfinite(r.at(0)) || !std::isfinite(r.at(1)) ||
      !(r.at(0) < r.at(1)))
    throw InvalidInput(std::string(name) + ": expected (lo, hi), finite, lo < hi, in m or rad");
  return {r.at(0), r.at(1)};
}

py::dict workspace_slice(const K& k, py::handle at, const std::string& a, const std::string& bname,
                         py::handle range_a, py::handle range_b, py::handle points, py::handle pivot,
                         const std::string& mode) {
  const PoseFrame f = frame_of("smarpod", pivot, mode);
  mm::SliceSpec s;
  if (!at.is_none()) {
    const ArrayRows base = array_rows(at, "at", {6});
    if (!base.single) throw InvalidInput("at: expected one pose of shape (6,)");
    require_finite(base);
    const double* v = base.a.data();
    s.base = mm::SmarPodPose{v[0], v[1], v[2], v[3], v[4], v[5]};
  }
  s.pivot = f.pivot;
  s.axis_a = mm::parse_pose_coordinate(a);
  s.axis_b = mm::parse_pose_coordinate(bname);
  if (s.axis_a == s.axis_b) throw InvalidInput("b: must be another coordinate than a ('" + a + "')");
  const auto base = s.base.as_array();
  std::tie(s.lo_a, s.hi_a) = range_of(range_a, "range_a", s.axis_a, base[s.axis_a]);
  std::tie(s.lo_b, s.hi_b) = range_of(range_b, "range_b", s.axis_b, base[s.axis_b]);
  if (py::isinstance<py::int_>(points)) {
    s.n_a = s.n_b = points.cast<int>();
  } else {
    try {
      std::tie(s.n_a, s.n_b) = points.cast<std::pair<int, int>>();
    } catch (const py::cast_error&) {
      throw InvalidInput("points: expected an int or (n_a, n_b)");
    }
  }
  if (s.n_a < 2 || s.n_a > 2001 || s.n_b < 2 || s.n_b > 2001)
    throw InvalidInput(fmt::format("points: each within [2, 2001] (got {}, {})", s.n_a, s.n_b));
  s.validate();
  const CsvTable t = nogil([&] { return mm::workspace_slice(k, s); });
  py::dict d("a"_a = a, "b"_a = bname, "reasons"_a = reach_names());
  const std::vector<py::ssize_t> grid{s.n_b, s.n_a};  // rows: b, columns: a (the table's order)
  for (std::size_t c = 0; c < t.cols(); ++c) {
    const auto& col = t.column(c);
    if (t.names()[c] == "reach") {
      py::array_t<int> r(grid);
      std::transform(col.begin(), col.end(), r.mutable_data(), [](double x) { return static_cast<int>(x); });
      d["reach"] = r;
    } else {
      py::array_t<double> r(grid);
      std::copy(col.begin(), col.end(), r.mutable_data());
      d[py::str(t.names()[c])] = r;
    }
  }
  return d;
}

/// Poses -> 4 x 4 homogeneous transforms [R d; 0 1] of the platform in its home frame.
py::array_t<double> to_transform(py::handle poses, const std::string& convention, py::handle pivot,
                                 const std::string& mode) {
  const PoseFrame f = frame_of(convention, pivot, mode);
  const ArrayRows b = array_rows(poses, "poses", {6});
  require_finite(b);
  py::array_t<double> o(b.shape({4, 4}));
  for (py::ssize_t i = 0; i < b.n; ++i) {
    const mm::PlatformTransform T = transform_of(b.a.data() + 6 * i, f);
    Eigen::Map<Eigen::Matrix<double, 4, 4, Eigen::RowMajor>> H(o.mutable_data() + 16 * i);
    H.setIdentity();
    H.topLeftCorner<3, 3>() = T.R;
    H.topRightCorner<3, 1>() = T.d;
  }
  return o;
}

py::array_t<double> from_transform(py::handle transforms, const std::string& convention, py::handle pivot,
                                   const std::string& mode) {
  const PoseFrame f = frame_of(convention, pivot, mode);
  const ArrayRows b = array_rows(transforms, "transforms", {4, 4});
  require_finite(b);
  py::array_t<double> o(b.shape({6}));
  for (py::ssize_t i = 0; i < b.n; ++i) {
    const Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>> H(b.a.data() + 16 * i);
    mm::PlatformTransform T;
    T.R = H.topLeftCorner<3, 3>();
    T.d = H.topRightCorner<3, 1>();
    const double orth = (T.R.transpose() * T.R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
    if (orth > 1e-9 || T.R.determinant() < 0.0 ||
        (H.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > 0.0)
      throw InvalidInput(
          fmt::format("{}: not a rigid transform [R d; 0 0 0 1] (|R^T R - I| = {:.3g}, det R = {:.6g})",
                      b.row(i), orth, T.R.determinant()));
    pose_of(T, f, o.mutable_data() + 6 * i);
  }
  return o;
}

}  // namespace

void bind_positioner(py::module_& m) {
  // The keyword arguments that say how six numbers are a pose, and what they mean.
  const auto conv = "convention"_a = "smarpod";
  const auto pivot = "pivot"_a = py::none();
  const auto mode = "pivot_mode"_a = "relative";
  const auto out = "out"_a = py::none();
  const std::string frame =
      " convention: 'smarpod' (x, y, z, rx, ry, rz; R = Rz(rz) Ry(ry) Rx(rx)) or 'pi' (X, Y, Z, U, V, W; U "
      "-> V "
      "-> W about the moving axes); pivot: the centre of rotation (x, y, z) [m], default the top plate's "
      "centre; pivot_mode: 'relative' (moves with the platform; PI's only mode) or 'fixed' (stays in space).";
  const auto doc = [&frame](const char* what) { return std::string(what) + frame; };

  m.def(
      "params", [](py::handle p) { return params_dict(params_from<mm::ParallelGeometryParams>(p)); },
      "params"_a = py::none(),
      "The geometry's parameters, validated and complete (the 110.45-size defaults for missing keys): the "
      "keys "
      "of `microcobot positioner params --json`.");
  m.def("to_transform", &to_transform, "poses"_a, py::kw_only(), conv, pivot, mode,
        doc("The platform's 4 x 4 transforms [R d; 0 0 0 1] in its home frame ((N, 4, 4), or (4, 4) for one "
            "pose (6,)): a platform point q is at R q + d.")
            .c_str());
  m.def(
      "from_transform", &from_transform, "transforms"_a, py::kw_only(), conv, pivot, mode,
      doc("The poses ((N, 6) or (6,)) of 4 x 4 rigid transforms, to_transform's inverse; a SmarPod pose p in "
          "PI's convention: from_transform(to_transform(p), convention='pi').")
          .c_str());

  py::class_<K>(
      m, "Positioner",
      "The 6-DOF parallel positioner (3 x PPSR, SmarPod 110.45 class; thesis §2.3, Fig. 2.4): its "
      "geometry and kinematics. Positioner(params=None): a dict of params() keys (missing keys keep "
      "their default), a YAML file name, or None for the defaults. Poses: (N, 6) or (6,) float64 in m "
      "and rad; legs: (u0, w0, u1, w1, u2, w2) [m], 0 at mid-stroke.")
      .def(py::init([](py::handle p) { return K(params_from<mm::ParallelGeometryParams>(p)); }),
           "params"_a = py::none())
      .def_property_readonly(
          "params", [](const K& k) { return params_dict(k.params()); },
          "The geometry's parameters as a dict.")
      .def_property_readonly(
          "leg_length_m", [](const K& k) { return k.geometry().leg_length_m; },
          "L = sqrt((b - r)^2 + h^2): the rigid legs' length [m].")
      .def_property_readonly(
          "home_height_m", [](const K& k) { return k.geometry().home_height_m; },
          "h + o: the top plate's height above the carriages' joints at home [m].")
      .def(
          "ik", &ik, "poses"_a, py::kw_only(), out, conv, pivot, mode,
          doc("Closed-form inverse kinematics: the leg coordinates (N, 6) [m] of poses (N, 6) (or (6,) -> "
              "(6,)). "
              "A pose that is not reachable (not finite, out of reach, singular, stroke or joint limit) "
              "raises "
              "ValueError naming its row and the reason; the rows before it are written. out: a caller-owned "
              "C-contiguous float64 array of the result's shape, written in place and returned (it may be "
              "`poses` itself).")
              .c_str())
      .def("fk", &fk, "legs"_a, "guess"_a = py::none(), py::kw_only(), out, conv, pivot, mode,
           doc("Forward kinematics by Newton's method: the poses (N, 6) of leg coordinates (N, 6) [m] (or "
               "(6,) "
               "-> (6,)), from `guess` (one pose (6,) or one per row; default home). Leg coordinates not "
               "finite "
               "or beyond the stroke raise ValueError; where Newton does not converge to a pose of the "
               "positioner (non-singular, passive joints within their limits) it raises "
               "microcobot.ComputationFailed naming the row, never a wrong pose. out: as ik's.")
               .c_str())
      .def("reachable", &reachable, "poses"_a, py::kw_only(), conv, pivot, mode,
           doc("Whether each pose (N, 6) is reachable: a bool array (N,), or a bool for one pose (6,); "
               "check() "
               "says why not.")
               .c_str())
      .def("check", &check, "poses"_a, py::kw_only(), conv, pivot, mode,
           doc("The workspace check of each pose (N, 6), in the library's order (not finite, out of reach, "
               "singular, stroke limit, joint limit: the first that fails is the reason): {'reachable': bool "
               "(N,), 'code': int (N,) (0 reachable .. 5 joint limit), 'reason': [str], 'detail': [str] ('' "
               "when reachable), 'conditioning': (N,) (0 where a leg does not close)}; scalars for one pose "
               "(6,).")
               .c_str())
      .def(
          "jacobian", &jacobian, "poses"_a, py::kw_only(), out, conv, pivot, mode,
          doc("J (N, 6, 6), or (6, 6) for one pose: dq = J (delta d, delta theta), the platform's small "
              "motion "
              "in its home frame (translation [m], then rotation vector [rad]: R' = exp([delta theta]x) R), "
              "not "
              "the pose coordinates' rates. A pose whose legs do not close raises ValueError naming its row. "
              "out: as ik's.")
              .c_str())
      .def("conditioning", &conditioning, "poses"_a, py::kw_only(), conv, pivot, mode,
           doc("sigma_min / sigma_max of J with its rotation columns scaled by the platform radius, per pose "
               "(N,) "
               "or a float for (6,): 1 isotropic, 0 singular, 0 too where a leg does not close. Non-finite "
               "poses raise ValueError.")
               .c_str())
      .def(
          "rotation_range", &rotation_range, "at"_a, "axis"_a = "rz", py::kw_only(), pivot, mode,
          "The travel of one rotation ('rx', 'ry' or 'rz') at SmarPod poses `at` (N, 6) (or (6,)), the other "
          "coordinates held, as `microcobot positioner workspace`: {'min_rad', 'max_rad': (N,), "
          "'min_reason', "
          "'max_reason': [str] (what stops each end; 'reachable' where +-pi/2 is reached)}, each end to 1e-9 "
          "rad. An unreachable `at` raises ValueError naming its row. pivot, pivot_mode: as ik's (SmarPod's "
          "convention only: the library sweeps its coordinates).")
      .def("workspace_slice", &workspace_slice, "at"_a = py::none(), "a"_a = "x", "b"_a = "y", py::kw_only(),
           "range_a"_a = py::none(), "range_b"_a = py::none(), "points"_a = 41, pivot, mode,
           "A slice of the workspace: SmarPod pose `at` (default home) with coordinates a and b ('x', 'y', "
           "'z', "
           "'rx', 'ry', 'rz') swept over range_a and range_b ((lo, hi) in m or rad; default +-8 mm, +-15 deg "
           "about `at`) in `points` points each (an int or (n_a, n_b)): {'a', 'b', 'x_m', 'y_m', 'z_m', "
           "'rx_rad', 'ry_rad', 'rz_rad', 'conditioning': (n_b, n_a) float arrays, 'reach': (n_b, n_a) int "
           "codes, 'reasons': the codes' names}, the rows of `microcobot positioner workspace --out`'s "
           "workspace_slice.csv on a grid.");
}

}  // namespace mc::py
