// `microcobot cell run`: a batch of pin insertions run headless by the robot (auto), a
// simulated person (manual), the person with shared control (assisted) or the scripted watchmaker
// (scripted), each cycle measured; cycles.csv and the summary under --out.

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>

#include <fmt/format.h>

#include "cli.h"
#include "microcobot/cell/cell_run.h"
#include "microcobot/cell/task_file.h"
#include "microcobot/core/error.h"
#include "microcobot/core/params.h"
#include "microcobot/report/box_plot.h"

namespace cell_commands {
namespace {

namespace cell = mc::cell;
namespace pf = mc::platform;

struct CellOptions {
  mc::cli::CommonOptions common;
  std::optional<std::filesystem::path> scene;   // AssemblyBatchParams
  std::optional<std::filesystem::path> config;  // the platform
  std::optional<std::filesystem::path> task;    // a task file: autonomy per step, the task's parameters
  bool camera = false;                          // the cell's camera for the robot (camera.enabled)
  std::optional<int> batch, seed;
  std::optional<std::string> mode, master;
  std::vector<std::string> modes{"auto", "manual"};  // compare
};

struct Inputs {
  cell::AssemblyBatchParams scene;
  cell::CellRunParams params;
  pf::PlatformConfig config;
};

// The scene, the run's parameters and the platform, with the flags over the files.
Inputs load_inputs(const CellOptions& o) {
  Inputs in;
  if (o.scene) in.scene = mc::load_params<cell::AssemblyBatchParams>(*o.scene);
  if (o.batch) in.scene.parts = *o.batch;
  if (o.seed) in.scene.seed = *o.seed;
  if (o.common.params) in.params = mc::load_params<cell::CellRunParams>(*o.common.params);
  if (o.mode) in.params.mode = *o.mode;
  if (o.master) in.params.person.master = *o.master;  // before the task file: its manual steps need one
  if (o.task) {
    // Over the run's `task` keys; a step no headless operator can do is refused naming the file.
    const cell::AssemblyTaskFile f = cell::load_task_file(*o.task, in.params.task);
    in.params.task = f.params;
    in.params.autonomy = f.steps.autonomy();
    try {
      cell::CellRunParams check = in.params;
      check.mode = "auto";
      check.validate();
    } catch (const mc::InvalidParams& e) {
      throw mc::InvalidInput(o.task->string(), 0, e.what());
    }
  }
  if (o.camera) in.params.camera.enabled = true;
  mc::cli::naming_flags({{"parts", "--batch"},
                         {"seed", "--seed"},
                         {"mode", "--mode"},
                         {"master", "--master"},
                         {"camera.enabled", "--camera"}},
                        [&] {
                          in.scene.validate();
                          in.params.validate();
                        });
  if (o.config) in.config = pf::load_platform_config(*o.config);
  return in;
}

std::vector<cell::CycleResult> run_mode(const Inputs& in, const std::vector<cell::AssemblyJob>& jobs,
                                        const std::string& mode) {
  cell::CellRunParams params = in.params;
  params.mode = mode;
  params.camera.enabled = params.camera.enabled && mode == "auto";  // the robot's camera
  return cell::run_batch(jobs, params, in.config, [&](const cell::CycleResult& c) {
    mc::cli::progress("cell " + mode, static_cast<std::size_t>(c.index + 1), jobs.size());
  });
}

mc::CsvTable cycles_table(const std::vector<cell::CycleResult>& cycles) {
  std::vector<std::string> columns = {"index",
                                      "success",
                                      "cycle_s",
                                      "placement_error_m",
                                      "peak_grip_N",
                                      "mean_grip_N",
                                      "peak_contact_N",
                                      "grip_violations",
                                      "contact_violations",
                                      "neighbour_contacts",
                                      "clutches",
                                      "search_tries",
                                      "confirmations",
                                      "handovers",
                                      "submovements",
                                      "path_m",
                                      "side_m",
                                      "clearance_m",
                                      "flat",
                                      "release",
                                      "ended_holding",
                                      "wall_s",
                                      "looks",
                                      "looks_found",
                                      "look_error_m",
                                      "look_wall_s"};
  // Where each cycle's time went, step by step (zero for the scripted watchmaker).
  for (std::size_t i = 0; i + 1 < cell::AssemblyTask::kStepCount; ++i)
    columns.push_back(std::string(cell::AssemblyTask::name(static_cast<cell::AssemblyTask::Step>(i))) + "_s");
  mc::CsvTable t(columns);
  for (const auto& c : cycles) {
    // The release strategy as its number (0 open, 1 shake, 2 roll: microworld::ReleaseStrategy).
    mc::microworld::ReleaseStrategy release = mc::microworld::ReleaseStrategy::kOpen;
    const double release_code =
        mc::microworld::parse_release(c.release, release) ? static_cast<double>(release) : std::nan("");
    std::vector<double> row = {static_cast<double>(c.index),
                               c.success ? 1.0 : 0.0,
                               c.cycle_s,
                               c.placement_error_m,
                               c.peak_grip_N,
                               c.mean_grip_N,
                               c.peak_contact_N,
                               static_cast<double>(c.grip_violations),
                               static_cast<double>(c.contact_violations),
                               static_cast<double>(c.neighbour_contacts),
                               static_cast<double>(c.clutches),
                               static_cast<double>(c.search_tries),
                               static_cast<double>(c.confirmations),
                               static_cast<double>(c.handovers),
                               static_cast<double>(c.submovements),
                               c.path_m,
                               c.side_m,
                               c.clearance_m,
                               c.part == "flat" ? 1.0 : 0.0,
                               release_code,
                               c.ended_holding ? 1.0 : 0.0,
                               c.wall_s,
                               static_cast<double>(c.looks),
                               static_cast<double>(c.looks_found),
                               c.look_error_m,
                               c.look_wall_s};
    row.insert(row.end(), c.step_s.begin(), c.step_s.end());
    t.add_row(row);
  }
  return t;
}

std::string who(const std::string& mode) {
  if (mode == "auto") return "the robot";
  if (mode == "manual") return "a simulated person";
  if (mode == "assisted") return "a simulated person with shared control";
  return "the scripted watchmaker";
}

// The batch's page: its figures per part (cycle time, placement against clearance, forces).
mc::report::Report batch_report(const std::vector<cell::CycleResult>& cycles, const cell::BatchSummary& s,
                                int seed) {
  mc::report::Report rep("cell run " + s.mode);
  rep.section(
      "Batch",
      fmt::format("{} parts (seed {}) inserted by {}; each on a fresh simulated platform. Success: the pin "
                  "down in its bore and released (the simulation's truth). docs/cell.md.",
                  s.cycles, seed, who(s.mode)));
  rep.add_result("placed (pins in their bores, flat parts on their seats)", s.successes);
  rep.add_result("success rate", 100.0 * s.success_rate, "%");
  rep.add_result("95 % Wilson interval, low", 100.0 * s.success_low, "%");
  rep.add_result("95 % Wilson interval, high", 100.0 * s.success_high, "%");
  rep.add_result("cycle time, median", s.cycle_median_s, "s");
  rep.add_result("cycle time, first quartile", s.cycle_q1_s, "s");
  rep.add_result("cycle time, third quartile", s.cycle_q3_s, "s");
  rep.add_result("placement error, median", s.placement_median_m, "m");
  rep.add_result("peak grip force", s.peak_grip_max_N, "N");
  rep.add_result("ticks over a force limit", s.force_violations);
  rep.add_result("steps striking a neighbouring part", s.neighbour_contacts);
  if (s.looks > 0) {
    rep.add_result("camera looks", s.looks);
    rep.add_result("camera looks that found the pin", s.looks_found);
    rep.add_result("camera's largest error (x-y, against the truth)", s.look_error_max_m, "m");
  }
  std::vector<double> part, time, clearance_um, placement_um, grip_mN, contact_mN, tries;
  // By clearance: the plots draw each series' points in the order of its x.
  std::vector<const cell::CycleResult*> by_clearance;
  for (const auto& c : cycles) by_clearance.push_back(&c);
  std::stable_sort(by_clearance.begin(), by_clearance.end(),
                   [](const auto* a, const auto* b) { return a->clearance_m < b->clearance_m; });
  for (const auto* c : by_clearance) {
    clearance_um.push_back(1e6 * c->clearance_m);
    placement_um.push_back(1e6 * c->placement_error_m);
    tries.push_back(c->search_tries);
  }
  for (const auto& c : cycles) {
    part.push_back(c.index);
    time.push_back(c.cycle_s);
    grip_mN.push_back(1e3 * c.peak_grip_N);
    contact_mN.push_back(1e3 * c.peak_contact_N);
  }
  rep.add_figure({"Cycle time",
                  "Each part's cycle, from the start to every axis holding.",
                  {"Part", ""},
                  {"Cycle time", "s"},
                  {{"cycle", part, time, true}}});
  rep.add_figure(
      {"Placement against clearance",
       "The pin's distance from its bore's axis against the bore's radial clearance: within the "
       "clearance once inserted.",
       {"Radial clearance", "um"},
       {"Placement error", "um"},
       {{"placement", clearance_um, placement_um, true}, {"clearance", clearance_um, clearance_um, true}}});
  rep.add_figure({"Search tries",
                  "Descents that met the bore's rim before the pin went in.",
                  {"Radial clearance", "um"},
                  {"Tries", ""},
                  {{"tries", clearance_um, tries, true}}});
  rep.add_figure({"Peak forces",
                  "The largest grip and contact forces of each cycle (limits 1 and 2 mN).",
                  {"Part", ""},
                  {"Force", "mN"},
                  {{"grip", part, grip_mN, true}, {"contact", part, contact_mN, true}}});
  return rep;
}

// The modes side by side: box plots of each mode's cycles, one box per mode.
mc::report::Report modes_report(const std::vector<std::vector<cell::CycleResult>>& by_mode) {
  using Groups = std::vector<std::pair<std::string, std::vector<double>>>;
  Groups time, placement, grip, contact;
  for (const auto& cycles : by_mode) {
    const std::string mode = cycles.empty() ? std::string() : cycles.front().mode;
    for (Groups* g : {&time, &placement, &grip, &contact}) g->push_back({mode, {}});
    for (const auto& c : cycles) {
      time.back().second.push_back(c.cycle_s);
      placement.back().second.push_back(1e6 * c.placement_error_m);
      grip.back().second.push_back(1e3 * c.peak_grip_N);
      contact.back().second.push_back(1e3 * c.peak_contact_N);
    }
  }
  mc::report::Report rep("modes");
  rep.section("Modes side by side",
              "Box plots of each mode's cycles on the same parts: the box spans the quartiles, the thick "
              "line is the median, the whiskers reach the furthest cycle within 1.5 IQR of the box, "
              "circles are the cycles beyond.");
  const auto box = [&](std::string title, std::string caption, mc::report::Axis y, Groups g) {
    rep.add_figure(
        mc::report::box_figure(std::move(title), std::move(caption), "Mode", std::move(y), std::move(g)));
  };
  box("Cycle time by mode", "Each cycle, from the start to every axis holding (simulated).",
      {"Cycle time", "s"}, std::move(time));
  box("Placement error by mode", "The pin's distance from its bore's axis at the end of the cycle.",
      {"Placement error", "um"}, std::move(placement));
  box("Peak grip force by mode",
      "The largest grip force of each cycle (the scene's limit world.grip_force_limit_N: 1 mN by default).",
      {"Peak grip force", "mN"}, std::move(grip));
  box("Peak contact force by mode",
      "The largest contact force of each cycle (world.contact_force_limit_N: 2 mN by default).",
      {"Peak contact force", "mN"}, std::move(contact));
  return rep;
}

void run(const CellOptions& o) {
  const Inputs in = load_inputs(o);
  const auto& scene = in.scene;
  const auto cycles = run_mode(in, cell::assembly_jobs(scene), in.params.mode);
  const cell::BatchSummary s = cell::summarize(cycles);
  nlohmann::json summary = s.to_json();
  summary["seed"] = scene.seed;
  summary["cycles_detail"] = nlohmann::json::array();
  for (const auto& c : cycles) summary["cycles_detail"].push_back(c.to_json());
  mc::cli::write_result_table(o.common, "cycles.csv", cycles_table(cycles), summary);
  if (o.common.out) {
    mc::write_file_atomic(*o.common.out / "summary.json", summary.dump(2) + "\n");
    mc::report::Report rep = batch_report(cycles, s, scene.seed);
    rep.append(modes_report({cycles}));
    rep.write(*o.common.out);
  }
  std::string failures;
  for (const auto& c : cycles)
    if (!c.success) failures += fmt::format("\n  part {}: {}", c.index, c.verdict);
  const std::string looks =
      s.looks > 0
          ? fmt::format("; camera: {}/{} looks found the pin, largest error {:.3f} um, {:.1f} s rendering",
                        s.looks_found, s.looks, 1e6 * s.look_error_max_m, s.look_wall_s)
          : std::string();
  mc::cli::emit(
      o.common, summary,
      fmt::format("cell run {} (seed {}): {}/{} placed ({:.0f} %, 95 % CI {:.0f}-{:.0f} %), cycle median "
                  "{:.1f} s (IQR {:.1f}-{:.1f} s), placement median {:.2f} um, peak grip {:.3f} mN, "
                  "{} ticks over a force limit; {:.0f} s simulated in {:.1f} s{}{}",
                  s.mode, scene.seed, s.successes, s.cycles, 100 * s.success_rate, 100 * s.success_low,
                  100 * s.success_high, s.cycle_median_s, s.cycle_q1_s, s.cycle_q3_s,
                  1e6 * s.placement_median_m, 1e3 * s.peak_grip_max_N, s.force_violations, s.simulated_s,
                  s.wall_s, looks, failures));
}

// Several modes on the same parts: each one's summary, and its ratios to the last mode's.
void compare(const CellOptions& o) {
  const Inputs in = load_inputs(o);
  const auto jobs = cell::assembly_jobs(in.scene);
  nlohmann::json summary = {
      {"seed", in.scene.seed}, {"parts", in.scene.parts}, {"modes", nlohmann::json::object()}};
  std::vector<cell::BatchSummary> summaries;
  std::vector<mc::CsvTable> tables;
  std::vector<std::vector<cell::CycleResult>> all;
  for (const std::string& mode : o.modes) {
    all.push_back(run_mode(in, jobs, mode));
    summaries.push_back(cell::summarize(all.back()));
    summary["modes"][mode] = summaries.back().to_json();
    tables.push_back(cycles_table(all.back()));
  }
  const cell::BatchSummary& ref = summaries.back();
  std::string human = fmt::format("cell compare (seed {}, {} parts):", in.scene.seed, in.scene.parts);
  for (const auto& s : summaries) {
    const double time_ratio = s.cycle_median_s / ref.cycle_median_s;
    const double placement_ratio =
        ref.placement_median_m > 0.0 ? s.placement_median_m / ref.placement_median_m : 1.0;
    summary["ratios"][s.mode + "/" + ref.mode] = {{"cycle_median", time_ratio},
                                                  {"placement_median", placement_ratio}};
    human += fmt::format(
        "\n  {:7} {}/{} inserted, cycle median {:.1f} s ({:.2f} x {}), placement median {:.2f} um "
        "({:.2f} x), {} ticks over a force limit",
        s.mode, s.successes, s.cycles, s.cycle_median_s, time_ratio, ref.mode, 1e6 * s.placement_median_m,
        placement_ratio, s.force_violations);
  }
  std::vector<mc::cli::ResultTable> results;
  for (std::size_t i = 0; i < o.modes.size(); ++i)
    results.push_back({"cycles-" + o.modes[i] + ".csv", tables[i], o.modes[i] + "_", {}});
  mc::cli::write_result_tables(o.common, results, summary);
  if (o.common.out) {
    mc::write_file_atomic(*o.common.out / "summary.json", summary.dump(2) + "\n");
    mc::report::Report rep("cell compare");
    rep.append(modes_report(all));
    for (std::size_t i = 0; i < all.size(); ++i)
      rep.append(batch_report(all[i], summaries[i], in.scene.seed));
    rep.write(*o.common.out);
  }
  mc::cli::emit(o.common, summary, human);
}

// What `run` and `compare` share: the batch, the platform, the run's parameters, the outputs.
void add_batch_options(CLI::App& cmd, CellOptions& o) {
  cmd.add_option("--scene", o.scene, "The batch (YAML; keys as `cell params --json` shows under scene)");
  cmd.add_option("--config", o.config, "Platform configuration (YAML; as `run --print-config`)");
  cmd.add_option("--batch", o.batch, "Parts in the batch (default 10)")->check(CLI::Range(1, 10000));
  cmd.add_option("--seed", o.seed, "The batch's seed (default 1)")->check(CLI::NonNegativeNumber);
  cmd.add_option(
         "--master", o.master,
         "The simulated person's master in manual and assisted modes: haptic (handle, thumb wheel, "
         "TéléTweez; default), console (joystick, gripper slider) or click (the console's click-to-go; "
         "manual only); console also for the task's manual steps, which the person takes over (mode auto)")
      ->check(CLI::IsMember({"haptic", "console", "click"}));
  cmd.add_option(
      "--task", o.task,
      "A task file (YAML): each step's autonomy (`steps: {insert: confirm}`; confirm steps are "
      "confirmed after confirm_delay_s, manual ones taken over by the simulated person with --master "
      "console, assisted ones refused headless) and the task's parameters "
      "(`params: {insert_speed_m_s: 1e-5}`); docs/cell.md");
  cmd.add_flag("--camera", o.camera,
               "The robot's camera (mode auto): looks at the pin in its slot, in the fingers and placed, on "
               "rendered frames (camera.* in --params; docs/cell.md)");
  mc::cli::add_params_option(cmd, o.common);
  mc::cli::add_output_options(cmd, o.common);
  mc::cli::add_format_option(cmd, o.common);
}

void add_cell(CLI::App& group) {
  auto o = std::make_shared<CellOptions>();
  auto* cmd = group.add_subcommand(
      "run", "A batch of pin insertions, each cycle measured (time, success, placement, forces)");
  add_batch_options(*cmd, *o);
  cmd->add_option("--mode", o->mode,
                  "auto (the robot), manual (a simulated person), assisted (the person with shared control) "
                  "or scripted (the scripted watchmaker)")
      ->check(CLI::IsMember(cell::cell_modes()));
  cmd->callback([o] { run(*o); });

  auto* cmp = group.add_subcommand("compare", "Several modes on the same parts, with their ratios");
  add_batch_options(*cmp, *o);
  cmp->add_option("--modes", o->modes,
                  "Modes to run, comma-separated; ratios are to the last (default auto,manual)")
      ->delimiter(',')
      ->check(CLI::IsMember(cell::cell_modes()));
  cmp->callback([o] { compare(*o); });

  auto* params = group.add_subcommand("params", "Print the default batch and run parameters");
  auto po = std::make_shared<mc::cli::CommonOptions>();
  params->add_flag("--json", po->json, "As JSON");
  params->callback([po] {
    cell::AssemblyBatchParams scene;
    cell::CellRunParams run;
    const nlohmann::json j = {{"scene", mc::params_to_json(scene)}, {"run", mc::params_to_json(run)}};
    mc::cli::emit(*po, j, "scene:\n" + mc::params_to_yaml(scene) + "run:\n" + mc::params_to_yaml(run));
  });
}

const bool kRegistered = mc::cli::register_group(
    {"cell", "The assembly cell: batches of insertions by the robot or the operator, measured", 6,
     &add_cell});

}  // namespace
}  // namespace cell_commands
