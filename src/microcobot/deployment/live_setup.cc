#include "microcobot/deployment/live_setup.h"

#include <string>
#include <vector>

#include <fmt/format.h>

#include "microcobot/cell/assembly_batch.h"
#include "microcobot/cell/task_file.h"
#include "microcobot/cell/task_io.h"
#include "microcobot/core/error.h"
#include "microcobot/core/field_names.h"
#include "microcobot/core/input_file.h"
#include "microcobot/core/params.h"
#include "microcobot/platform/camera_scene.h"
#include "microcobot/platform/platform_config.h"

namespace mc::deployment {
namespace {

namespace pf = mc::platform;

// `cell`: one part of a batch (its microworld becomes the scene) and the task the console
// supervises on it, with the task file's autonomy and parameters.
void use_cell(const ServeConfig& o, live::LiveParams& lp, const Log& log) {
  if (o.role != Role::kSingle) throw UsageError("--cell: runs where the console drives: not with --role");
  cell::AssemblyBatchParams batch;
  if (o.scene) batch = load_params<cell::AssemblyBatchParams>(*o.scene);
  if (o.seed) batch.seed = *o.seed;
  const int part = o.part.value_or(0);
  if (part < 0 || part >= batch.parts)
    throw UsageError("--part " + std::to_string(part) + ": the batch has " + std::to_string(batch.parts) +
                     " parts (0 to " + std::to_string(batch.parts - 1) + ")");
  // The batch's seed is the --seed flag's value: the message blames what the user typed.
  naming_fields({{"seed", "--seed"}}, [&] { batch.validate(); });
  const std::vector<cell::AssemblyJob> jobs = cell::assembly_jobs(batch);
  const cell::AssemblyJob& job = jobs[static_cast<std::size_t>(part)];
  live::LiveTaskParams tp;
  tp.goal = cell::assembly_goal(job);
  // The whole batch, so that the console's Next part goes through it.
  for (const cell::AssemblyJob& j : jobs) tp.parts.push_back({j.index, j.world, cell::assembly_goal(j)});
  tp.part = part;
  if (o.task) {
    const cell::AssemblyTaskFile f = cell::load_task_file(*o.task);
    tp.task = f.params;
    tp.autonomy = f.steps.autonomy();
  }
  tp.camera.enabled = o.cell_camera;
  lp.platform.microworld = "pick-place";
  lp.platform.world = job.world;
  lp.platform.validate();
  lp.task = tp;
  if (!log) return;
  std::string levels;
  for (int i = 0; i + 1 < cell::AssemblyTask::kStepCount; ++i)
    if (tp.autonomy[static_cast<std::size_t>(i)] != cell::AssemblyTask::Autonomy::kAuto)
      levels += fmt::format("{}{} {}", levels.empty() ? "" : ", ",
                            cell::AssemblyTask::name(static_cast<cell::AssemblyTask::Step>(i)),
                            cell::AssemblyTask::name(tp.autonomy[static_cast<std::size_t>(i)]));
  log(fmt::format(
      "cell part {} of the batch of seed {} ({} parts): a {:.0f} um {} with {:.1f} um of {}{}; steps "
      "{}{}; the task waits for Start in the console (Next part: the batch's next)",
      part, batch.seed, batch.parts, 1e6 * job.side_m, job.flat ? "plate onto its seat" : "pin into a bore",
      1e6 * job.clearance_m, job.flat ? "seat tolerance" : "radial clearance",
      job.world.neighbour_count > 0 ? fmt::format(", among {} other parts", job.world.neighbour_count) : "",
      levels.empty() ? "all auto" : levels + " (the rest auto)",
      o.cell_camera ? "; the cell's camera looks" : ""));
}

}  // namespace

live::LiveParams live_params(const ServeConfig& o, const Log& log) {
  live::LiveParams lp;
  if (o.config_file) {
    lp.platform = pf::load_platform_config(*o.config_file);
  } else {
    lp.platform = o.platform;
    lp.platform.validate();
  }
  if (!o.cell && (o.seed || o.part || o.task || o.cell_camera))
    throw UsageError(std::string(o.task          ? "--task"
                                 : o.seed        ? "--seed"
                                 : o.cell_camera ? "--cell-camera"
                                                 : "--part") +
                     ": needs --cell");
  const std::string scene = o.scene.value_or("pick-place");
  if (o.cell) {
    use_cell(o, lp, log);
  } else {
    pf::use_scene(lp.platform, scene);
  }
  // The hexapod twin drives the platform's parallel positioner: the thesis's assembly, the part on
  // the positioner and the gripper on the Cartesian robot.
  for (const auto& t : o.twins) {
    if (t.protocol != twins::Protocol::kGcs2Hexapod || lp.platform.parallel_positioner_enabled()) continue;
    lp.platform.positioner = "parallel";
    lp.platform.validate();
    log("--emulate gcs2-hexapod: the part rides on the platform's parallel positioner (positioner: "
        "parallel)");
  }
  // A live session steps the simulated positioner's legs as a real controller does, on a thread of
  // their own beside the loop (devices/parallel_positioner_controller.h).
  auto& controller = lp.platform.parallel_positioner.controller;
  if (controller == "auto") controller = "thread";
  return lp;
}

}  // namespace mc::deployment
