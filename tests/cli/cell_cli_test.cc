// `microcobot cell run|params` as a user runs them: the batch's summary and files, and
// one-line errors with their exit codes.

#include <filesystem>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "microcobot/core/csv.h"
#include "support/test_support.h"

namespace mc {
namespace {

using test::run_cli;
using ::testing::HasSubstr;

TEST(CellCli, RunsABatchAndWritesItsCyclesAndSummary) {
  test::TempDir dir;
  const auto r =
      run_cli({"cell", "run", "--batch", "2", "--seed", "53", "--json", "--out", dir.path().string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["cycles"].get<int>(), 2);
  EXPECT_EQ(j["successes"].get<int>(), 2);
  EXPECT_EQ(j["force_violations"].get<int>(), 0);
  EXPECT_EQ(j["seed"].get<int>(), 53);
  const CsvTable t = read_csv(dir / "cycles.csv");
  EXPECT_EQ(t.rows(), 2u);
  EXPECT_EQ(t.column("success"), (std::vector<double>{1.0, 1.0}));
  // Where each cycle's time went: its steps add up to it.
  for (std::size_t i = 0; i < t.rows(); ++i) {
    double steps = 0.0;
    for (const char* c : {"approach_s", "align_s", "descend_s", "grasp_s", "lift_s", "transport_s",
                          "rotate_s", "insert_s", "release_s", "retract_s", "verify_s"})
      steps += t.column(c).at(i);
    EXPECT_NEAR(steps, t.column("cycle_s").at(i), 2e-3) << "part " << i;
    EXPECT_GT(t.column("transport_s").at(i), 1.0);
  }
  EXPECT_EQ(nlohmann::json::parse(test::read_text(dir / "summary.json"))["cycles"].get<int>(), 2);
  EXPECT_THAT(test::read_text(dir / "index.html"), HasSubstr("Placement against clearance"));
  EXPECT_EQ(read_csv(dir / "fig-01-cycle-time.csv").rows(), 2u);
}

TEST(CellCli, CompareRunsTheModesOnTheSamePartsWithTheirRatios) {
  test::TempDir dir;
  const auto r =
      run_cli({"cell", "compare", "--batch", "1", "--seed", "59", "--json", "--out", dir.path().string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  const double robot = j["modes"]["auto"]["cycle_median_s"].get<double>();
  const double person = j["modes"]["manual"]["cycle_median_s"].get<double>();
  EXPECT_NEAR(j["ratios"]["auto/manual"]["cycle_median"].get<double>(), robot / person, 1e-12);
  EXPECT_EQ(j["ratios"]["manual/manual"]["cycle_median"].get<double>(), 1.0);
  for (const char* f : {"cycles-auto.csv", "cycles-manual.csv", "summary.json", "index.html"})
    EXPECT_TRUE(std::filesystem::exists(dir / f)) << f;
  // The page opens with the modes' box plots, one box (series) per mode, the
  // cycles' own values behind them.
  const CsvTable box = read_csv(dir / "fig-01-cycle-time-by-mode.csv");
  EXPECT_EQ(box.column("series"), (std::vector<double>{1.0, 2.0}));
  EXPECT_EQ(box.column("cycle_time_s"), (std::vector<double>{robot, person}));
  for (const char* title :
       {"Placement error by mode", "Peak grip force by mode", "Peak contact force by mode"})
    EXPECT_THAT(test::read_text(dir / "index.html"), HasSubstr(title));
  EXPECT_EQ(run_cli({"cell", "compare", "--modes", "auto,psychic"}).exit_code, 2);
}

TEST(CellCli, BadInputGetsOneLineAndItsExitCode) {
  test::TempDir dir;
  auto r = run_cli({"cell", "run", "--batch", "0"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_THAT(r.err, HasSubstr("--batch"));
  r = run_cli({"cell", "run", "--mode", "telepathy"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("telepathy"));
  test::write_text(dir / "scene.yaml", "parts: 2\nbore_depth_m: 1.0\n");
  r = run_cli({"cell", "run", "--scene", (dir / "scene.yaml").string(), "--out", (dir / "o").string()});
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_THAT(r.err, HasSubstr("bore_depth_m"));
  EXPECT_FALSE(std::filesystem::exists(dir / "o")) << "nothing half-written";
  test::write_text(dir / "scene.yaml", "slot_error_m: 1.0e-3\n");
  r = run_cli({"cell", "run", "--scene", (dir / "scene.yaml").string()});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_THAT(r.err, HasSubstr("slot_error_m"));
  const auto p = run_cli({"cell", "params", "--json"});
  ASSERT_EQ(p.exit_code, 0) << p.err;
  EXPECT_EQ(nlohmann::json::parse(p.out)["scene"]["parts"].get<int>(), 10);
}

// Tasks in YAML: a confirm step costs the supervisor's delay and is counted;
// a manual step, a misspelt step or key is refused naming the file and the key (exit 3).
TEST(CellCli, ATaskFileSetsTheStepsAutonomyAndBadOnesAreOneLineNamingTheKey) {
  test::TempDir dir;
  test::write_text(dir / "task.yaml", "steps: {insert: confirm}\nparams: {insert_speed_m_s: 1.5e-5}\n");
  auto r = run_cli({"cell", "run", "--batch", "1", "--seed", "53", "--task", (dir / "task.yaml").string(),
                    "--json", "--out", (dir / "o").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["successes"].get<int>(), 1);
  EXPECT_EQ(j["cycles_detail"][0]["confirmations"].get<int>(), 1);
  EXPECT_EQ(read_csv(dir / "o" / "cycles.csv").column("confirmations"), (std::vector<double>{1.0}));
  const struct {
    std::string yaml, expected;
  } bad[] = {{"steps: {grasp: manual}\n", "steps.grasp"},
             {"steps: {inserting: confirm}\n", "steps.inserting"},
             {"steps: {insert: later}\n", "later"},
             {"params: {insert_speed_m_s: -1}\n", "params.insert_speed_m_s"}};
  for (const auto& b : bad) {
    test::write_text(dir / "bad.yaml", b.yaml);
    r = run_cli({"cell", "run", "--batch", "1", "--task", (dir / "bad.yaml").string()});
    EXPECT_EQ(r.exit_code, 3) << b.yaml << r.err;
    EXPECT_EQ(test::line_count(r.err), 1u) << r.err;
    EXPECT_THAT(r.err, HasSubstr(b.expected));
    EXPECT_THAT(r.err, HasSubstr("bad.yaml"));
  }
}

TEST(CellCli, ServeCellStartsAndItsFlagsAreCheckedLikeAnyOther) {
  test::TempDir dir;
  test::write_text(dir / "task.yaml", "steps: {insert: confirm}\n");
  auto r = run_cli({"serve", "--cell", "--seed", "3", "--part", "1", "--task", (dir / "task.yaml").string(),
                    "--listen", "127.0.0.1:0", "--out", (dir / "out").string(), "--duration", "0.3"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out.rfind("http://127.0.0.1:", 0), 0u) << r.out;
  EXPECT_THAT(r.err, HasSubstr("cell part 1 of the batch of seed 3"));
  EXPECT_THAT(r.err, HasSubstr("insert confirm"));
  r = run_cli(
      {"serve", "--task", (dir / "task.yaml").string(), "--listen", "127.0.0.1:0", "--duration", "0.3"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_THAT(r.err, HasSubstr("--task: needs --cell"));
  r = run_cli({"serve", "--cell-camera", "--listen", "127.0.0.1:0", "--duration", "0.3"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_THAT(r.err, HasSubstr("--cell-camera: needs --cell"));
  // The robot's camera in a person's mode: refused naming the flag, nothing run.
  r = run_cli({"cell", "run", "--mode", "manual", "--camera", "--batch", "1"});
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_EQ(test::line_count(r.err), 1u) << r.err;
  EXPECT_THAT(r.err, HasSubstr("--camera"));
  r = run_cli({"serve", "--cell", "--part", "10", "--listen", "127.0.0.1:0", "--duration", "0.3"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_THAT(r.err, HasSubstr("--part 10"));
  test::write_text(dir / "bad.yaml", "steps: {grab: auto}\n");
  r = run_cli({"serve", "--cell", "--task", (dir / "bad.yaml").string(), "--listen", "127.0.0.1:0",
               "--duration", "0.3"});
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_EQ(test::line_count(r.err), 1u) << r.err;
  EXPECT_THAT(r.err, HasSubstr("steps.grab"));
}

}  // namespace
}  // namespace mc
