// `microcobot positioner move`: the simulated pose move from the command line: its figures in
// JSON, the CSV and report under --out, one-line refusals with their exit codes.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/test_support.h"

namespace mc::motion {
namespace positioner_move_cli_test {

TEST(PositionerMoveCli, AShortMoveComesToRestOnItsGoalAndWritesItsCsvAndReport) {
  mc::test::TempDir dir;
  // 0.2 mm and 1 deg (SmarPod's vendor units: m, deg).
  const auto r = mc::test::run_cli({"positioner", "move", "--to", "0.0001,-0.0002,0,0,0,1", "--units",
                                    "vendor", "--json", "--out", dir.path().string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(j["at_rest"].get<bool>());
  EXPECT_LE(j["rest_error_m"].get<double>(), 0.5e-6);
  EXPECT_LE(j["rest_error_rad"].get<double>(), 10e-6);
  EXPECT_LE(j["path_deviation_m"].get<double>(), 2e-6);
  EXPECT_GT(j["path_deviation_m"].get<double>(), 0.0);  // the legs step: the platform is never exact
  // sqrt(5) 0.1 mm at 100 um/s (2.24 s) dominates 1 deg at 1 deg/s: L / v + v / a = 2.236 + 0.1 s.
  EXPECT_NEAR(j["move"]["duration_s"].get<double>(), std::sqrt(5.0) * 1e-4 / 100e-6 + 0.1, 1e-9);
  std::ifstream csv(dir / "positioner_move.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_EQ(header.rfind("t_s,ref_x,ref_y,ref_z,ref_rx,ref_ry,ref_rz,true_x", 0), 0u) << header;
  EXPECT_TRUE(std::filesystem::exists(dir / "index.html"));
}

TEST(PositionerMoveCli, UnreachableSingularNanAndTooFastAreOneLineErrorsWithTheirExitCodes) {
  const auto expect = [](std::vector<std::string> args, int code, const std::string& says) {
    args.insert(args.begin(), {"positioner", "move"});
    const auto r = mc::test::run_cli(args);
    EXPECT_EQ(r.exit_code, code) << r.err;
    EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << r.err;  // one line
    EXPECT_TRUE(r.out.empty()) << r.out;
  };
  expect({"--to", "0.009,0,0,0,0,0"}, 3, "unreachable: stroke limit");
  expect({"--to", "0,0,0.0082842,0,0,0"}, 3, "unreachable: singular");
  expect({"--from", "0,0,0.02,0,0,0", "--to", "0,0,0,0,0,0"}, 3,
         "--from 0,0,0.02,0,0,0 (m, rad) unreachable");
  expect({"--to", "nan,0,0,0,0,0"}, 2, "not a finite number");
  expect({"--to", "0.001,0,0,0,0,0", "--speed-um-s", "1500"}, 3, "beyond max_leg_speed_m_s");
}

}  // namespace positioner_move_cli_test
}  // namespace mc::motion
