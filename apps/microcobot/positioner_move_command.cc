// `microcobot positioner move`: a point-to-point move of the parallel positioner in pose space,
// simulated with each of the six leg positioners a stick-slip axis (motion/parallel_stage.h): the
// time it takes, the true pose's error at rest and its deviation from the straight line.

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <Eigen/Geometry>

#include "cli.h"
#include "microcobot/core/csv.h"
#include "microcobot/core/error.h"
#include "microcobot/core/params.h"
#include "microcobot/motion/parallel_stage.h"
#include "microcobot/motion/parallel_workspace.h"
#include "microcobot/motion/step_map.h"
#include "microcobot/report/report.h"
#include "microcobot/stickslip/actuator.h"
#include "positioner_pose_options.h"

namespace positioner_pose_options {
namespace {

struct MoveOptions : PoseOptions {
  std::vector<double> from{0, 0, 0, 0, 0, 0};
  std::vector<double> to;
  double speed_um_s = 100.0;
  double speed_deg_s = 1.0;
};

/// The pose refused at the command line: the flag, its numbers and the reason in one line.
mm::PlatformTransform checked(const char* flag, const std::vector<double>& v, const MoveOptions& o,
                              const mm::ParallelKinematics& k) {
  const mm::PlatformTransform T = transform_of(v, o);
  const mm::ReachCheck c = mm::check_pose(k, T);
  if (!c.ok()) {
    throw mc::InvalidInput(fmt::format("{} {} ({}) unreachable: {}: {}", flag, numbers(v), unit_names(o),
                                       mm::to_string(c.reach), c.detail));
  }
  return T;
}

void run_move(const MoveOptions& o) {
  mm::ParallelStageParams p = o.common.params ? mc::load_params<mm::ParallelStageParams>(*o.common.params)
                                              : mm::ParallelStageParams{};
  p.move.max_speed_m_s = o.speed_um_s * 1e-6;
  p.move.max_angular_speed_rad_s = o.speed_deg_s * kDeg;
  p.validate();
  const mm::ParallelKinematics k(p.geometry);
  const mm::PlatformTransform from = checked("--from", o.from, o, k);
  const mm::PlatformTransform to = checked("--to", o.to, o, k);

  const mc::stickslip::ActuatorModel model{mc::stickslip::StickSlipParams{}};
  const mm::StepMap map(model);
  mm::ParallelStage stage(model, map, p);
  stage.place(from);
  // Powered up and at rest before the move (the trackers' power-up edge drags a slider by up to
  // ~1 um, which the hold then takes back): the figures are the move's.
  while (!stage.at_rest() && !stage.fault() && stage.time_s() < 1.0) stage.tick();
  const mm::MoveCheck check = stage.move_to(to);
  const auto& traj = stage.trajectory();

  // One row every 10 ms (and the last): t, the reference and the true pose in the convention.
  const std::array<const char*, 6> names = o.convention == "pi"
                                               ? std::array<const char*, 6>{"X", "Y", "Z", "U", "V", "W"}
                                               : std::array<const char*, 6>{"x", "y", "z", "rx", "ry", "rz"};
  std::vector<std::string> cols{"t_s"};
  for (const char* pre : {"ref_", "true_"})
    for (const char* n : names) cols.push_back(std::string(pre) + n);
  cols.push_back("path_deviation_m");
  cols.push_back("path_deviation_rad");
  mc::CsvTable table(cols);
  mm::PathDeviation worst;
  const int every = std::max(1, static_cast<int>(std::lround(10e-3 / stage.tick_s())));
  const double budget_s = traj.duration_s() + 10.0;  // the power-up and a generous settle
  auto record = [&](const mm::PathDeviation& d) {
    std::vector<double> row{stage.time_s()};
    for (const auto& T : {stage.reference_pose(), stage.true_pose()}) {
      const auto v = pose_of(T, o).second;
      row.insert(row.end(), v.begin(), v.end());
    }
    row.push_back(d.position_m);
    row.push_back(d.rotation_rad);
    table.add_row(row);
  };
  for (long n = 0; stage.moving() && !stage.fault() && stage.time_s() < budget_s; ++n) {
    stage.tick();
    const mm::PathDeviation d = traj.deviation(stage.true_pose());
    worst.position_m = std::max(worst.position_m, d.position_m);
    worst.rotation_rad = std::max(worst.rotation_rad, d.rotation_rad);
    if (n % every == 0) record(d);
  }
  while (!stage.at_rest() && !stage.fault() && stage.time_s() < budget_s) stage.tick();
  const bool rested = stage.at_rest();
  for (int n = 0; n < 200 && !stage.fault(); ++n) stage.tick();  // 20 ms of hold
  if (stage.fault())
    throw mc::ComputationFailed("positioner move: a leg's model diverged or no pose fits the legs");
  record(traj.deviation(stage.true_pose()));
  const mm::PlatformTransform& T = stage.true_pose();
  const Eigen::Vector3d c = p.move.tool_m();
  const double rest_m = ((T.R * c + T.d) - (to.R * c + to.d)).norm();
  const double rest_rad = Eigen::AngleAxisd(to.R.transpose() * T.R).angle();

  json j = common_json(o);
  j["from"] = pose_of(from, o).first;
  j["to"] = pose_of(to, o).first;
  j["move"] = {{"length_m", traj.length_m()},
               {"angle_rad", traj.angle_rad()},
               {"duration_s", traj.duration_s()},
               {"samples_checked", check.samples},
               {"peak_leg_speed_m_s", check.peak_leg_speed_m_s}};
  j["time_s"] = stage.time_s();
  j["at_rest"] = rested;
  j["rest_error_m"] = rest_m;
  j["rest_error_rad"] = rest_rad;
  j["path_deviation_m"] = worst.position_m;
  j["path_deviation_rad"] = worst.rotation_rad;
  mc::cli::write_result_table(o.common, "positioner_move.csv", table, j);
  if (o.common.out) {
    mc::report::Report r("positioner move");
    r.section("Pose move",
              fmt::format("microcobot positioner move --from {} --to {} ({}) at {} um/s, {} deg/s; six "
                          "stick-slip legs (docs/concepts/parallel-positioner.md, \"Pose control\")",
                          numbers(o.from), numbers(o.to), unit_names(o), o.speed_um_s, o.speed_deg_s));
    r.add_result("move duration", traj.duration_s(), "s");
    r.add_result("pose error at rest", rest_m, "m");
    r.add_result("rotation error at rest", rest_rad, "rad");
    r.add_result("path deviation (tool point)", worst.position_m, "m");
    r.add_result("rotation deviation", worst.rotation_rad, "rad");
    mc::report::Figure fig{"Deviation from the line",
                           "The true tool point's distance from the straight line and the true "
                           "orientation's angle from the path's, every 10 ms.",
                           {"t", "s"},
                           {"deviation", "m, rad"},
                           {}};
    fig.series.push_back({"position [m]", table.column("t_s"), table.column("path_deviation_m"), false});
    fig.series.push_back({"rotation [rad]", table.column("t_s"), table.column("path_deviation_rad"), false});
    r.add_figure(std::move(fig));
    mc::cli::write_report_if_requested(o.common, r);
  }
  mc::cli::emit(
      o.common, j,
      fmt::format("moved in {:.3f} s ({:.3f} s simulated with the power-up and the settling); at rest "
                  "{:.3f} um, {:.3f} urad from the goal; path deviation {:.3f} um, {:.2f} urad",
                  traj.duration_s(), stage.time_s(), rest_m * 1e6, rest_rad * 1e6, worst.position_m * 1e6,
                  worst.rotation_rad * 1e6));
}

}  // namespace

void add_positioner_move(CLI::App& group) {
  auto o = std::make_shared<MoveOptions>();
  auto* cmd = group.add_subcommand(
      "move", "Simulate a straight move in pose space with six stick-slip legs (--out: CSV and report)");
  cmd->add_option("--from", o->from,
                  "The start pose x,y,z,rx,ry,rz (or X,Y,Z,U,V,W) in --units (default home)")
      ->delimiter(',')
      ->expected(6)
      ->check(mc::cli::Range(-1e3, 1e3));
  cmd->add_option("--to", o->to, "The goal pose in --units")
      ->required()
      ->delimiter(',')
      ->expected(6)
      ->check(mc::cli::Range(-1e3, 1e3));
  cmd->add_option("--speed-um-s", o->speed_um_s, "The tool point's speed limit [um/s] (default 100)")
      ->check(mc::cli::Range(0.1, 2000.0));
  cmd->add_option("--speed-deg-s", o->speed_deg_s, "The platform's angular speed limit [deg/s] (default 1)")
      ->check(mc::cli::Range(0.001, 20.0));
  add_pose_options(*cmd, *o);
  mc::cli::add_format_option(*cmd, o->common);
  cmd->callback([o] { run_move(*o); });
}

}  // namespace positioner_pose_options
