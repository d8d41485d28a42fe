// `microcobot control validate`: a thin layer over studies/validation_set (the library runs the
// cases and judges them; this file parses flags and prints or writes the table).

#include "control_validate.h"

#include <memory>
#include <sstream>

#include <fmt/format.h>

#include "cli.h"
#include "microcobot/core/csv.h"
#include "microcobot/core/error.h"
#include "microcobot/core/params.h"
#include "microcobot/motion/control_params.h"
#include "microcobot/studies/validation_set.h"

namespace mc::cli {
namespace {

struct ValidateOptions {
  CommonOptions common;
  std::string set = "validation";
  long long seed = -1;  // -1: the set's default seed
  int cases = -1;       // -1: the set's default number of random cases
};

std::string nm(double m) { return m < 0.0 ? "-" : fmt::format("{:.0f}", m * 1e9); }

std::string csv_field(const std::string& s) {
  std::string q = "\"";
  for (char ch : s) q += ch == '"' ? std::string("\"\"") : std::string(1, ch);
  return q + "\"";
}

void run_validate(const ValidateOptions& o) {
  const auto p =
      o.common.params ? mc::load_params<motion::ControlParams>(*o.common.params) : motion::ControlParams{};
  const studies::CaseSet set = studies::parse_case_set(o.set, "--set");
  const std::uint64_t seed =
      o.seed >= 0 ? static_cast<std::uint64_t>(o.seed)
                  : (set == studies::CaseSet::kTuning ? studies::kTuningSeed : studies::kValidationSeed);
  const int n = o.cases >= 0 ? o.cases
                             : (set == studies::CaseSet::kTuning ? studies::kTuningRandomCases
                                                                 : studies::kValidationCases);
  std::vector<studies::ValidationCase> cases;
  naming_flags({{"seed", "--seed"}, {"cases", "--cases"}},
               [&] { cases = studies::make_case_set(set, seed, n); });
  if (cases.empty()) throw mc::UsageError("--cases must be >= 1 for the validation set");
  if (o.common.out) mc::ensure_writable_dir(*o.common.out);
  const mc::stickslip::ActuatorModel model(p.model);
  const motion::StepMap map(model, p.step_map);
  const studies::TrackerSetup su = studies::tracker_setup(p);
  const studies::TrackingGoals goals;
  std::vector<studies::CaseResult> results;
  nlohmann::json rows = nlohmann::json::array();
  std::ostringstream csv, human;
  csv << "case,description,rms_error_m,max_error_m,path_deviation_m,final_error_m,steps,pass\n";
  human << fmt::format("{:<22} {:>7} {:>7} {:>8} {:>7}  {:<4} {}\n", "case", "RMS nm", "max nm", "path nm",
                       "final", "ok", "reference");
  for (const auto& c : cases) {
    const studies::CaseResult r = studies::run_case(model, map, su, c, goals);
    results.push_back(r);
    nlohmann::json row = {{"case", c.name},
                          {"description", studies::describe(c)},
                          {"profile", to_string(c.profile)},
                          {"power_up", c.power_up},
                          {"rms_error_m", r.rms_m},
                          {"max_error_m", r.max_m},
                          {"final_error_m", r.final_m},
                          {"steps", r.edges},
                          {"pass", r.pass}};
    if (r.path_deviation_m >= 0.0) row["path_deviation_m"] = r.path_deviation_m;
    rows.push_back(row);
    csv << fmt::format("{},{},{:.6g},{:.6g},{},{:.6g},{},{}\n", c.name, csv_field(studies::describe(c)),
                       r.rms_m, r.max_m,
                       r.path_deviation_m >= 0.0 ? fmt::format("{:.6g}", r.path_deviation_m) : std::string(),
                       r.final_m, r.edges, r.pass ? 1 : 0);
    human << fmt::format("{:<22} {:>7} {:>7} {:>8} {:>7}  {:<4} {}\n", c.name, nm(r.rms_m), nm(r.max_m),
                         nm(r.path_deviation_m), nm(r.final_m), r.pass ? "yes" : "NO", studies::describe(c));
  }
  const studies::ValidationSummary s = studies::summarise(cases, results, goals);
  nlohmann::json j = {{"set", to_string(set)},
                      {"seed", seed},
                      {"cases", rows},
                      {"summary",
                       {{"cases", s.cases},
                        {"passed", s.passed},
                        {"median_rms_m", s.median_rms_m},
                        {"worst_rms_m", s.worst_rms_m},
                        {"worst_max_m", s.worst_max_m},
                        {"worst_path_deviation_m", s.worst_path_deviation_m},
                        {"worst_powerup_backward_m", s.worst_powerup_backward_m},
                        {"goals_hold",
                         {{"rms", s.rms_ok},
                          {"median", s.median_ok},
                          {"max", s.max_ok},
                          {"path_deviation", s.path_ok},
                          {"powerup_backward", s.powerup_ok}}}}},
                      {"goals_m",
                       {{"rms", goals.rms_m},
                        {"median_rms", goals.median_rms_m},
                        {"max", goals.max_m},
                        {"path_deviation", goals.path_deviation_m},
                        {"powerup_backward", goals.powerup_backward_m}}}};
  if (o.common.out) {
    std::ostringstream head;
    head << fmt::format(
        "# microcobot control validate --set {} --seed {}: {} cases, {} pass; median RMS {} nm\n",
        to_string(set), seed, s.cases, s.passed, nm(s.median_rms_m));
    mc::write_file_atomic(*o.common.out / (to_string(set) + ".csv"), head.str() + csv.str());
  }
  human << fmt::format(
      "{} set (seed {}): {}/{} cases pass; median RMS {} nm (goal {}), worst RMS {} nm ({}), worst max {} nm "
      "({}), worst path deviation {} nm ({}), power-up backward max {} nm ({})",
      to_string(set), seed, s.passed, s.cases, nm(s.median_rms_m), nm(goals.median_rms_m), nm(s.worst_rms_m),
      nm(goals.rms_m), nm(s.worst_max_m), nm(goals.max_m), nm(s.worst_path_deviation_m),
      nm(goals.path_deviation_m), nm(s.worst_powerup_backward_m), nm(goals.powerup_backward_m));
  emit(o.common, j, human.str());
}

}  // namespace

void add_control_validate(CLI::App& group) {
  auto o = std::make_shared<ValidateOptions>();
  auto* cmd = group.add_subcommand(
      "validate", "Tracking controller on a seeded random tuning or validation set of references");
  cmd->add_option("--set", o->set, "tuning | validation")->check(CLI::IsMember({"tuning", "validation"}));
  cmd->add_option("--seed", o->seed, "Random draw's seed (default: tuning 15, validation 31)")
      ->check(CLI::Range(0LL, 1LL << 53));
  cmd->add_option("--cases", o->cases, "Number of random cases (default: tuning 32 + 9 named, validation 32)")
      ->check(CLI::Range(0, 1000));
  add_output_options(*cmd, o->common);
  add_params_option(*cmd, o->common);
  cmd->callback([o] { run_validate(*o); });
}

}  // namespace mc::cli
