// `microcobot positioner ...`: the 6-DOF parallel stick-slip positioner's kinematics (thesis §2.3,
// Fig. 2.4; motion/parallel_kinematics.h): inverse and forward kinematics of one pose, its
// workspace (rotation ranges at a position, a slice as CSV), its parameters. Poses in SmarPod's
// (x y z rx ry rz, R = Rz Ry Rx) or PI's (X Y Z U V W, U -> V -> W about moving axes) convention,
// in SI units or the vendor's (SmarPod: m, deg; PI: mm, deg).

#include <array>
#include <cmath>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "cli.h"
#include "microcobot/core/error.h"
#include "microcobot/core/params.h"
#include "microcobot/motion/parallel_kinematics.h"
#include "microcobot/motion/parallel_workspace.h"
#include "microcobot/motion/pose.h"
#include "microcobot/studies/positioner_figures.h"
#include "positioner_pose_options.h"

namespace positioner_commands {
namespace {

namespace mm = mc::motion;
using mc::cli::CommonOptions;
using nlohmann::json;

using namespace positioner_pose_options;

// ---- ik ------------------------------------------------------------------------------------

struct IkOptions : PoseOptions {
  std::vector<double> pose;
};

void run_ik(const IkOptions& o) {
  const mm::ParallelKinematics k = kinematics(o);
  const mm::PlatformTransform T = transform_of(o.pose, o);
  const mm::ReachCheck c = mm::check_pose(k, T);
  if (!c.ok()) {
    throw mc::InvalidInput(fmt::format("--pose {} ({}) unreachable: {}: {}", numbers(o.pose), unit_names(o),
                                       mm::to_string(c.reach), c.detail));
  }
  mm::LegClosure legs[mm::kParallelLegs];
  mm::LegCoordinates q;
  k.closures(T, legs, q);
  double sph[mm::kParallelLegs], rev[mm::kParallelLegs];
  k.joint_angles(T, legs, sph, rev);
  json j = common_json(o);
  j["pose"] = pose_of(T, o).first;
  j["legs_m"] = std::vector<double>(q.data(), q.data() + 6);
  j["conditioning"] = c.conditioning;
  j["reach"] = mm::to_string(c.reach);
  j["spherical_joints_rad"] = std::vector<double>(sph, sph + 3);
  j["revolute_joints_rad"] = std::vector<double>(rev, rev + 3);
  mc::cli::emit(
      o.common, j,
      fmt::format(
          "legs (u0 w0 u1 w1 u2 w2) [mm]: {:.6f} {:.6f} {:.6f} {:.6f} {:.6f} {:.6f}; conditioning {:.3f}",
          q[0] * 1e3, q[1] * 1e3, q[2] * 1e3, q[3] * 1e3, q[4] * 1e3, q[5] * 1e3, c.conditioning));
}

// ---- fk ------------------------------------------------------------------------------------

struct FkOptions : PoseOptions {
  std::vector<double> legs;
  std::vector<double> seed{0, 0, 0, 0, 0, 0};
};

void run_fk(const FkOptions& o) {
  const mm::ParallelKinematics k = kinematics(o);
  mm::LegCoordinates q;
  for (int i = 0; i < 6; ++i) q[i] = o.legs[i];
  const mm::ForwardResult f = k.forward(q, transform_of(o.seed, o));
  const auto [pose, v] = pose_of(f.T, o);
  json j = common_json(o);
  j["legs_m"] = o.legs;
  j["pose"] = pose;
  j["iterations"] = f.iterations;
  j["conditioning"] = k.conditioning(f.T);
  mc::cli::emit(o.common, j,
                fmt::format("pose ({}): {:.9g} {:.9g} {:.9g} {:.9g} {:.9g} {:.9g} ({} Newton steps)",
                            unit_names(o), v[0], v[1], v[2], v[3], v[4], v[5], f.iterations));
}

// ---- workspace -----------------------------------------------------------------------------

struct WorkspaceOptions : PoseOptions {
  std::vector<double> at{0, 0, 0, 0, 0, 0};
  std::vector<std::string> slice{"x", "y"};
  std::vector<double> range_a, range_b;
  int points = 41;
};

void run_workspace(const WorkspaceOptions& o) {
  if (o.convention != "smarpod") {
    throw mc::UsageError(
        "--convention: the workspace is swept in SmarPod's coordinates (x y z rx ry rz) only");
  }
  const mm::ParallelKinematics k = kinematics(o);
  const auto f = si_factors(o);
  const mm::Pivot pivot = pivot_of(o);
  std::array<double, 6> a{};
  for (int i = 0; i < 6; ++i) a[i] = o.at[i] * f[i < 3 ? 0 : 1];
  const mm::SmarPodPose at = mm::SmarPodPose::from_array(a);
  const mm::ReachCheck here = mm::check_pose(k, at, pivot);
  if (!here.ok()) {
    throw mc::InvalidInput(fmt::format("--at {} ({}) unreachable: {}: {}", numbers(o.at), unit_names(o),
                                       mm::to_string(here.reach), here.detail));
  }
  json j = common_json(o);
  j["at"] = o.at;
  j["conditioning"] = here.conditioning;
  json ranges = json::object();
  for (int axis = 0; axis < 3; ++axis) {
    const mm::RotationRange r = mm::rotation_range(k, at, axis, pivot);
    ranges[mm::pose_coordinate_name(3 + axis)] = {{"min", r.min_rad / f[1]},
                                                  {"max", r.max_rad / f[1]},
                                                  {"min_reason", mm::to_string(r.min_reason)},
                                                  {"max_reason", mm::to_string(r.max_reason)}};
  }
  j["rotation_range"] = ranges;

  mm::SliceSpec s;
  s.base = at;
  s.pivot = pivot;
  s.axis_a = mm::parse_pose_coordinate(o.slice[0]);
  s.axis_b = mm::parse_pose_coordinate(o.slice[1]);
  if (s.axis_a == s.axis_b) throw mc::UsageError("--slice: two different coordinates");
  // Default spans: +-8 mm of translation, +-15 deg of rotation about `at`.
  const auto span = [&](int axis, const std::vector<double>& given, double& lo, double& hi) {
    const double fa = f[axis < 3 ? 0 : 1];
    if (!given.empty()) {
      if (!(given[0] < given[1]))
        throw mc::UsageError(fmt::format("--range-{}: lo must be < hi", axis == s.axis_a ? 'a' : 'b'));
      lo = given[0] * fa;
      hi = given[1] * fa;
    } else {
      const double half = axis < 3 ? 8e-3 : 15 * kDeg;
      lo = a[axis] - half;
      hi = a[axis] + half;
    }
  };
  span(s.axis_a, o.range_a, s.lo_a, s.hi_a);
  span(s.axis_b, o.range_b, s.lo_b, s.hi_b);
  s.n_a = s.n_b = o.points;
  const mc::CsvTable t = mm::workspace_slice(k, s);
  json by_reason = json::object();
  int reachable = 0;
  for (double code : t.column("reach")) {
    const auto r = static_cast<mm::Reach>(static_cast<int>(code));
    by_reason[mm::to_string(r)] = by_reason.value(mm::to_string(r), 0) + 1;
    reachable += r == mm::Reach::kReachable ? 1 : 0;
  }
  j["slice"] = {{"a", o.slice[0]},
                {"b", o.slice[1]},
                {"range_a_si", {s.lo_a, s.hi_a}},
                {"range_b_si", {s.lo_b, s.hi_b}},
                {"points", t.rows()},
                {"reachable", reachable},
                {"reachable_fraction", static_cast<double>(reachable) / static_cast<double>(t.rows())},
                {"by_reason", by_reason}};
  mc::cli::write_result_table(o.common, "workspace_slice.csv", t, j);
  if (o.common.out) {
    // The slice as points in its two coordinates, one series per reason.
    mc::report::Report r("positioner workspace");
    r.section(
        "Workspace slice",
        fmt::format("microcobot positioner workspace --at {} --slice {},{} ({}); pivot {} ({})",
                    numbers(o.at), o.slice[0], o.slice[1], unit_names(o), numbers(o.pivot), o.pivot_mode));
    r.add_result("conditioning at --at", here.conditioning);
    r.add_result("reachable points", reachable);
    for (const char* n : {"rx", "ry", "rz"}) {
      r.add_result(fmt::format("{} range min ({})", n, ranges[n]["min_reason"].get<std::string>()),
                   ranges[n]["min"].get<double>(), o.units == "si" ? "rad" : "deg");
      r.add_result(fmt::format("{} range max ({})", n, ranges[n]["max_reason"].get<std::string>()),
                   ranges[n]["max"].get<double>(), o.units == "si" ? "rad" : "deg");
    }
    r.add_figure(mc::studies::workspace_slice_figure(
        t, s, fmt::format("Reach over {} and {}", o.slice[0], o.slice[1]),
        "Each grid point marked by the first check it fails (docs/concepts/parallel-positioner.md)."));
    mc::cli::write_report_if_requested(o.common, r);
  }
  std::string human = fmt::format("conditioning {:.3f}", here.conditioning);
  for (const char* n : {"rx", "ry", "rz"}) {
    human += fmt::format("; {} {:.6g} .. {:.6g} ({} .. {})", n, ranges[n]["min"].get<double>(),
                         ranges[n]["max"].get<double>(), ranges[n]["min_reason"].get<std::string>(),
                         ranges[n]["max_reason"].get<std::string>());
  }
  human +=
      fmt::format("; slice {}-{}: {} of {} points reachable", o.slice[0], o.slice[1], reachable, t.rows());
  mc::cli::emit(o.common, j, human);
}

void add_positioner(CLI::App& group) {
  {
    auto o = std::make_shared<CommonOptions>();
    auto* cmd = group.add_subcommand("params", "Print the geometry's parameters (the --params keys)");
    mc::cli::add_output_options(*cmd, *o);
    mc::cli::add_params_option(*cmd, *o);
    cmd->callback([o] {
      const auto p =
          o->params ? mc::load_params<mm::ParallelGeometryParams>(*o->params) : mm::ParallelGeometryParams{};
      p.validate();
      mc::cli::emit(*o, mc::params_to_json(p), mc::params_to_yaml(p));
    });
  }
  {
    auto o = std::make_shared<IkOptions>();
    auto* cmd = group.add_subcommand("ik", "Inverse kinematics: the six positioners' coordinates of a pose");
    cmd->add_option("--pose", o->pose, "The pose x,y,z,rx,ry,rz (or X,Y,Z,U,V,W) in --units")
        ->required()
        ->delimiter(',')
        ->expected(6)
        ->check(mc::cli::Range(-1e3, 1e3));
    add_pose_options(*cmd, *o);
    cmd->callback([o] { run_ik(*o); });
  }
  {
    auto o = std::make_shared<FkOptions>();
    auto* cmd = group.add_subcommand("fk", "Forward kinematics: the pose of six positioners' coordinates");
    cmd->add_option("--legs", o->legs,
                    "The positioners' coordinates u0,w0,u1,w1,u2,w2 [m] (0: home, +-stroke/2)")
        ->required()
        ->delimiter(',')
        ->expected(6)
        ->check(mc::cli::Range(-1.0, 1.0));
    cmd->add_option("--seed", o->seed, "Newton's start pose, in --convention and --units (default home)")
        ->delimiter(',')
        ->expected(6)
        ->check(mc::cli::Range(-1e3, 1e3));
    add_pose_options(*cmd, *o);
    cmd->callback([o] { run_fk(*o); });
  }
  {
    auto o = std::make_shared<WorkspaceOptions>();
    auto* cmd = group.add_subcommand(
        "workspace",
        "Rotation ranges at a position and a workspace slice over two pose coordinates (--out: CSV)");
    cmd->add_option("--at", o->at, "The pose x,y,z,rx,ry,rz in --units (default home)")
        ->delimiter(',')
        ->expected(6)
        ->check(mc::cli::Range(-1e3, 1e3));
    cmd->add_option("--slice", o->slice, "The two swept coordinates among x,y,z,rx,ry,rz (default x,y)")
        ->delimiter(',')
        ->expected(2)
        ->check(CLI::IsMember({"x", "y", "z", "rx", "ry", "rz"}));
    cmd->add_option("--range-a", o->range_a,
                    "lo,hi of the first swept coordinate in --units (default +-8 mm, +-15 deg)")
        ->delimiter(',')
        ->expected(2)
        ->check(mc::cli::Range(-1e3, 1e3));
    cmd->add_option("--range-b", o->range_b, "lo,hi of the second swept coordinate in --units")
        ->delimiter(',')
        ->expected(2)
        ->check(mc::cli::Range(-1e3, 1e3));
    cmd->add_option("--points", o->points, "Grid points per swept coordinate")->check(CLI::Range(2, 401));
    add_pose_options(*cmd, *o);
    mc::cli::add_format_option(*cmd, o->common);
    cmd->callback([o] { run_workspace(*o); });
  }
  add_positioner_move(group);
}

const bool kRegistered = mc::cli::register_group(
    {"positioner", "The 6-DOF parallel positioner (thesis §2.3, Fig. 2.4): params, ik, fk, workspace, move",
     55, &add_positioner});

}  // namespace
}  // namespace positioner_commands
