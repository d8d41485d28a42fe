#pragma once
// The pose options shared by the `microcobot positioner` commands: the convention (SmarPod or PI),
// the units (SI or the vendor's), the pivot and its mode; a pose's six numbers to the platform's
// transform and back.

#include <array>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "cli.h"
#include "microcobot/core/error.h"
#include "microcobot/core/params.h"
#include "microcobot/motion/parallel_kinematics.h"
#include "microcobot/motion/pose.h"

namespace positioner_pose_options {

namespace mm = mc::motion;
using mc::cli::CommonOptions;
using nlohmann::json;

constexpr double kDeg = std::numbers::pi / 180.0;

struct PoseOptions {
  CommonOptions common;
  std::string convention = "smarpod";
  std::string units = "si";
  std::vector<double> pivot{0.0, 0.0, 0.0};
  std::string pivot_mode = "relative";
};

/// The factors from the flags' units to SI: {length, angle}.
inline std::array<double, 2> si_factors(const PoseOptions& o) {
  if (o.units == "si") return {1.0, 1.0};
  return {o.convention == "pi" ? 1e-3 : 1.0, kDeg};
}

inline std::string unit_names(const PoseOptions& o) {
  if (o.units == "si") return "m, rad";
  return o.convention == "pi" ? "mm, deg" : "m, deg";
}

inline mm::ParallelKinematics kinematics(const PoseOptions& o) {
  return mm::ParallelKinematics(o.common.params
                                    ? mc::load_params<mm::ParallelGeometryParams>(*o.common.params)
                                    : mm::ParallelGeometryParams{});
}

inline mm::Pivot pivot_of(const PoseOptions& o) {
  const auto f = si_factors(o);
  mm::Pivot p{{o.pivot[0] * f[0], o.pivot[1] * f[0], o.pivot[2] * f[0]}, mm::parse_pivot_mode(o.pivot_mode)};
  if (o.convention == "pi" && p.mode == mm::PivotMode::kFixed) {
    throw mc::UsageError(
        "--pivot-mode fixed: PI's pivot always moves with the platform (use --convention smarpod)");
  }
  return p;
}

/// The platform transform of six numbers in the options' convention and units.
inline mm::PlatformTransform transform_of(const std::vector<double>& v, const PoseOptions& o) {
  const auto f = si_factors(o);
  const mm::Pivot pivot = pivot_of(o);
  if (o.convention == "pi") {
    return mm::to_transform(
        mm::PiPose{v[0] * f[0], v[1] * f[0], v[2] * f[0], v[3] * f[1], v[4] * f[1], v[5] * f[1]},
        pivot.point_m);
  }
  return mm::to_transform(
      mm::SmarPodPose{v[0] * f[0], v[1] * f[0], v[2] * f[0], v[3] * f[1], v[4] * f[1], v[5] * f[1]}, pivot);
}

/// The pose of `T` in the options' convention and units, as JSON and as the six numbers.
inline std::pair<json, std::array<double, 6>> pose_of(const mm::PlatformTransform& T, const PoseOptions& o) {
  const auto f = si_factors(o);
  const mm::Pivot pivot = pivot_of(o);
  std::array<double, 6> v{};
  std::array<const char*, 6> names{};
  if (o.convention == "pi") {
    const mm::PiPose p = mm::to_pi(T, pivot.point_m);
    v = {p.X, p.Y, p.Z, p.U, p.V, p.W};
    names = {"X", "Y", "Z", "U", "V", "W"};
  } else {
    v = mm::to_smarpod(T, pivot).as_array();
    names = {"x", "y", "z", "rx", "ry", "rz"};
  }
  json j = json::object();
  for (int i = 0; i < 6; ++i) {
    v[i] = v[i] / f[i < 3 ? 0 : 1] + 0.0;  // + 0.0: no -0 in the output
    j[names[i]] = v[i];
  }
  return {j, v};
}

inline json common_json(const PoseOptions& o) {
  return {{"convention", o.convention},
          {"units", unit_names(o)},
          {"pivot", o.pivot},
          {"pivot_mode", o.pivot_mode}};
}

inline std::string numbers(const std::vector<double>& v) {
  std::string s;
  for (double x : v) s += (s.empty() ? "" : ",") + fmt::format("{:g}", x);
  return s;
}

inline void add_pose_options(CLI::App& cmd, PoseOptions& o) {
  cmd.add_option(
         "--convention", o.convention,
         "smarpod (x y z rx ry rz, R = Rz Ry Rx) or pi (X Y Z U V W, U -> V -> W about the moving axes)")
      ->check(CLI::IsMember({"smarpod", "pi"}));
  cmd.add_option("--units", o.units,
                 "si (m, rad) or vendor (SmarPod: m, deg; PI: mm, deg) for the pose and the pivot")
      ->check(CLI::IsMember({"si", "vendor"}));
  cmd.add_option("--pivot", o.pivot, "The pivot point x,y,z (default 0,0,0: the top plate's centre)")
      ->delimiter(',')
      ->expected(3)
      ->check(mc::cli::Range(-1e3, 1e3));
  cmd.add_option("--pivot-mode", o.pivot_mode,
                 "relative (the pivot moves with the platform; PI's only mode) or fixed (stays in space)")
      ->check(CLI::IsMember({"relative", "fixed"}));
  mc::cli::add_output_options(cmd, o.common);
  mc::cli::add_params_option(cmd, o.common);
}

/// Registers `positioner move` (positioner_move_command.cc) in the command group.
void add_positioner_move(CLI::App& group);

}  // namespace positioner_pose_options
