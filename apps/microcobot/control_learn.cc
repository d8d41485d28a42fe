// `microcobot control learn`: a thin layer over studies/learning_run (the library runs the trials
// and learns; this file parses flags and prints or writes the per-trial table).

#include "control_learn.h"

#include <algorithm>
#include <memory>
#include <sstream>

#include <fmt/format.h>

#include "cli.h"
#include "microcobot/core/csv.h"
#include "microcobot/core/error.h"
#include "microcobot/core/input_file.h"
#include "microcobot/core/params.h"
#include "microcobot/motion/control_params.h"
#include "microcobot/studies/learning_run.h"

namespace mc::cli {
namespace {

struct LearnOptions {
  CommonOptions common;
  std::string set = "validation";
  long long seed = -1;    // -1: the set's default seed
  std::string case_name;  // empty: the first --references 1-D cases of the set
  int references = 10;
  int trials = 11;  // the first without learning, then 10 after 1..10 updates
  double gain = -1.0, q_cutoff = -1.0, forgetting = -1.0;  // < 0: from --params / the defaults
  int lead_ticks = -1;
};

// The goals on a repeated reference [m] (docs/concepts/control.md, "Iterative learning").
constexpr double kGoalRms_m = 50e-9;
constexpr double kGoalMax_m = 150e-9;

std::string nm(double m) { return fmt::format("{:.0f}", m * 1e9); }

void run_learn(const LearnOptions& o) {
  auto p =
      o.common.params ? mc::load_params<motion::ControlParams>(*o.common.params) : motion::ControlParams{};
  if (o.gain >= 0.0) p.learning.learning_gain = o.gain;
  if (o.q_cutoff >= 0.0) p.learning.q_cutoff_Hz = o.q_cutoff;
  if (o.forgetting >= 0.0) p.learning.forgetting = o.forgetting;
  if (o.lead_ticks >= 0) p.learning.lead_ticks = o.lead_ticks;
  naming_flags({{"learning.learning_gain", "--gain"},
                {"learning.q_cutoff_Hz", "--q-cutoff"},
                {"learning.forgetting", "--forgetting"},
                {"learning.lead_ticks", "--lead-ticks"}},
               [&] { p.learning.validate(); });
  const studies::CaseSet set = studies::parse_case_set(o.set, "--set");
  const std::uint64_t seed =
      o.seed >= 0 ? static_cast<std::uint64_t>(o.seed)
                  : (set == studies::CaseSet::kTuning ? studies::kTuningSeed : studies::kValidationSeed);
  const int draw = set == studies::CaseSet::kTuning ? studies::kTuningRandomCases : studies::kValidationCases;
  std::vector<studies::ValidationCase> all;
  naming_flags({{"seed", "--seed"}}, [&] { all = studies::make_case_set(set, seed, draw); });
  std::vector<studies::ValidationCase> cases;
  for (const auto& c : all) {
    if (!studies::is_one_d(c)) continue;
    if (!o.case_name.empty() ? c.name == o.case_name : static_cast<int>(cases.size()) < o.references)
      cases.push_back(c);
  }
  if (cases.empty()) {
    std::string names;
    for (const auto& c : all)
      if (studies::is_one_d(c)) names += (names.empty() ? "" : ", ") + c.name;
    throw mc::UsageError(fmt::format("--case '{}': no 1-D case of that name in the {} set (seed {}): {}",
                                     mc::excerpt(o.case_name), to_string(set), seed, names));
  }
  if (o.common.out) mc::ensure_writable_dir(*o.common.out);
  const mc::stickslip::ActuatorModel model(p.model);
  const motion::StepMap map(model, p.step_map);
  const studies::TrackerSetup su = studies::tracker_setup(p);
  long longest = 1;
  for (const auto& c : cases) longest = std::max(longest, studies::case_ticks(c));
  motion::IterativeLearning ilc(p.learning, longest);
  nlohmann::json refs = nlohmann::json::array();
  std::ostringstream csv, human;
  csv << "case,trial,rms_error_m,max_error_m,final_error_m,correction_max_m,change_rms_m\n";
  std::vector<std::vector<double>> rms(static_cast<std::size_t>(o.trials)), mx(rms.size()), chg(rms.size());
  human << fmt::format("{:<12} {}\n", "case", "RMS / max nm per trial (trial 0: no correction yet)");
  for (const auto& c : cases) {
    ilc.reset();
    const auto trials = studies::run_learning(model, map, su, c, ilc, o.trials);
    nlohmann::json rows = nlohmann::json::array();
    int first_ok = -1;
    std::string line;
    for (const auto& t : trials) {
      rows.push_back({{"trial", t.trial},
                      {"rms_error_m", t.rms_m},
                      {"max_error_m", t.max_m},
                      {"final_error_m", t.final_m},
                      {"correction_max_m", t.correction_max_m},
                      {"change_rms_m", t.change_rms_m}});
      csv << fmt::format("{},{},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g}\n", c.name, t.trial, t.rms_m, t.max_m,
                         t.final_m, t.correction_max_m, t.change_rms_m);
      if (first_ok < 0 && t.rms_m <= kGoalRms_m && t.max_m <= kGoalMax_m) first_ok = t.trial;
      rms[static_cast<std::size_t>(t.trial)].push_back(t.rms_m);
      mx[static_cast<std::size_t>(t.trial)].push_back(t.max_m);
      chg[static_cast<std::size_t>(t.trial)].push_back(t.change_rms_m);
      line += fmt::format(" {}/{}", nm(t.rms_m), nm(t.max_m));
    }
    refs.push_back({{"case", c.name},
                    {"description", studies::describe(c)},
                    {"trials", rows},
                    {"first_trial_within_goals", first_ok}});
    human << fmt::format("{:<12}{}   {}\n", c.name, line, studies::describe(c));
  }
  nlohmann::json per_trial = nlohmann::json::array();
  const auto median_of = [](std::vector<double> r) {
    std::sort(r.begin(), r.end());
    return r.size() % 2 ? r[r.size() / 2] : 0.5 * (r[r.size() / 2 - 1] + r[r.size() / 2]);
  };
  for (std::size_t t = 0; t < rms.size(); ++t) {
    auto r = rms[t];
    std::sort(r.begin(), r.end());
    per_trial.push_back({{"trial", t},
                         {"median_rms_m", median_of(r)},
                         {"median_change_rms_m", median_of(chg[t])},
                         {"worst_rms_m", r.back()},
                         {"worst_max_m", *std::max_element(mx[t].begin(), mx[t].end())}});
  }
  const auto& last = per_trial.back();
  const bool rms_ok = last["worst_rms_m"].get<double>() <= kGoalRms_m;
  const bool max_ok = last["worst_max_m"].get<double>() <= kGoalMax_m;
  nlohmann::json j = {
      {"set", to_string(set)},
      {"seed", seed},
      {"trials", o.trials},
      {"learning", mc::params_to_json(p.learning)},
      {"references", refs},
      {"summary",
       {{"per_trial", per_trial}, {"goals_hold_at_last_trial", {{"rms", rms_ok}, {"max", max_ok}}}}},
      {"goals_m", {{"rms", kGoalRms_m}, {"max", kGoalMax_m}}}};
  if (o.common.out) {
    const std::string head =
        fmt::format("# microcobot control learn --set {} --seed {} --trials {}: {} references\n",
                    to_string(set), seed, o.trials, cases.size());
    mc::write_file_atomic(*o.common.out / "learning.csv", head + csv.str());
  }
  human << "trial  median RMS  worst RMS  worst max  median change from the previous trial [nm]\n";
  for (const auto& t : per_trial) {
    human << fmt::format("{:>5}  {:>10}  {:>9}  {:>9}  {:>9}\n", t["trial"].get<int>(), nm(t["median_rms_m"]),
                         nm(t["worst_rms_m"]), nm(t["worst_max_m"]), nm(t["median_change_rms_m"]));
  }
  human << fmt::format(
      "{} set (seed {}), {} references, trial {}: worst RMS {} nm (goal {}: {}), worst max {} nm (goal {}: "
      "{})",
      to_string(set), seed, cases.size(), o.trials - 1, nm(last["worst_rms_m"]), nm(kGoalRms_m),
      rms_ok ? "met" : "missed", nm(last["worst_max_m"]), nm(kGoalMax_m), max_ok ? "met" : "missed");
  emit(o.common, j, human.str());
}

}  // namespace

void add_control_learn(CLI::App& group) {
  auto o = std::make_shared<LearnOptions>();
  auto* cmd = group.add_subcommand(
      "learn", "Iterative learning control: N trials of repeated references, per-trial RMS and max");
  cmd->add_option("--set", o->set, "tuning | validation")->check(CLI::IsMember({"tuning", "validation"}));
  cmd->add_option("--seed", o->seed, "Random draw's seed (default: tuning 15, validation 31)")
      ->check(CLI::Range(0LL, 1LL << 53));
  auto* one = cmd->add_option("--case", o->case_name, "One 1-D case of the set by name (e.g. trapezoid00)");
  cmd->add_option("--references", o->references, "Without --case: the set's first N 1-D cases (default 10)")
      ->check(CLI::Range(1, 1000))
      ->excludes(one);
  cmd->add_option("--trials", o->trials, "Trials per reference, the first without correction (default 11)")
      ->check(CLI::Range(1, 100));
  cmd->add_option("--gain", o->gain, "learning.learning_gain, in (0, 2)")->check(CLI::Range(0.0, 2.0));
  cmd->add_option("--lead-ticks", o->lead_ticks, "learning.lead_ticks")->check(CLI::Range(0, 100));
  cmd->add_option("--q-cutoff", o->q_cutoff, "learning.q_cutoff_Hz (0: no filter)")
      ->check(CLI::Range(0.0, 5000.0));
  cmd->add_option("--forgetting", o->forgetting, "learning.forgetting, in [0, 1)")
      ->check(CLI::Range(0.0, 1.0));
  add_output_options(*cmd, o->common);
  add_params_option(*cmd, o->common);
  cmd->callback([o] { run_learn(*o); });
}

}  // namespace mc::cli
