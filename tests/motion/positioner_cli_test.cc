// `microcobot positioner ...`: the command line over the parallel kinematics: the same numbers as
// the library, the vendors' units and conventions, one-line refusals with their exit codes, the
// workspace's files, the geometry from a parameter file.
#include <cmath>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "microcobot/motion/parallel_kinematics.h"
#include "support/test_support.h"

namespace mc::motion {
namespace positioner_cli_test {

LegCoordinates legs_of(const nlohmann::json& j) {
  LegCoordinates q;
  for (int i = 0; i < 6; ++i) q[i] = j["legs_m"][i].get<double>();
  return q;
}

TEST(PositionerCli, IkPrintsTheLibrarysLegCoordinatesExactly) {
  const auto r =
      mc::test::run_cli({"positioner", "ik", "--pose", "0.001,-0.002,0.0005,0.03,-0.02,0.05", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  LegCoordinates q;
  ASSERT_TRUE(
      ParallelKinematics().inverse(to_transform(SmarPodPose{1e-3, -2e-3, 0.5e-3, 0.03, -0.02, 0.05}), q));
  EXPECT_EQ(legs_of(j), q);  // 17 significant digits in the JSON: the same doubles
  EXPECT_EQ(j["reach"], "reachable");
  EXPECT_GT(j["conditioning"].get<double>(), 0.02);
}

TEST(PositionerCli, PiPoseInMillimetresAndDegreesIsThePiPoseInSiUnits) {
  const auto vendor = mc::test::run_cli({"positioner", "ik", "--convention", "pi", "--units", "vendor",
                                         "--pose", "1,0.5,0.5,3,-2,2", "--json"});
  ASSERT_EQ(vendor.exit_code, 0) << vendor.err;
  LegCoordinates q;
  const double deg = M_PI / 180.0;
  ASSERT_TRUE(ParallelKinematics().inverse(
      to_transform(PiPose{1e-3, 0.5e-3, 0.5e-3, 3 * deg, -2 * deg, 2 * deg}), q));
  EXPECT_LT((legs_of(nlohmann::json::parse(vendor.out)) - q).lpNorm<Eigen::Infinity>(), 1e-18);
  // FK gives the pose back in the same convention and units.
  std::string legs;
  for (int i = 0; i < 6; ++i) legs += (i ? "," : "") + nlohmann::json(q[i]).dump();
  const auto fk = mc::test::run_cli(
      {"positioner", "fk", "--convention", "pi", "--units", "vendor", "--legs", legs, "--json"});
  ASSERT_EQ(fk.exit_code, 0) << fk.err;
  const auto pose = nlohmann::json::parse(fk.out)["pose"];
  EXPECT_NEAR(pose["X"].get<double>(), 1.0, 1e-12);
  EXPECT_NEAR(pose["Z"].get<double>(), 0.5, 1e-12);
  EXPECT_NEAR(pose["V"].get<double>(), -2.0, 1e-10);
  EXPECT_NEAR(pose["W"].get<double>(), 2.0, 1e-10);
}

TEST(PositionerCli, RefusalsAreOneLineWithTheirExitCodes) {
  const auto expect = [](const std::vector<std::string>& args, int code, const std::string& needle) {
    std::vector<std::string> full{"positioner"};
    full.insert(full.end(), args.begin(), args.end());
    const auto r = mc::test::run_cli(full);
    EXPECT_EQ(r.exit_code, code) << r.err;
    EXPECT_NE(r.err.find(needle), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << r.err;  // one line
    EXPECT_TRUE(r.out.empty()) << r.out;
  };
  expect({"ik", "--pose", "0.009,0,0,0,0,0"}, 3, "unreachable: stroke limit: leg 0's tangential positioner");
  expect({"ik", "--pose", "0,0,0.00828,0,0,0"}, 3, "unreachable: singular");  // legs nearly vertical
  expect({"ik", "--pose", "0,0,0.009,0,0,0"}, 3, "unreachable: out of reach");
  expect({"ik", "--pose", "0,0,0,0,0,nan"}, 2, "--pose");
  expect({"ik", "--pose", "0,0,0"}, 2, "--pose");
  expect({"ik", "--pose", "0,0,0,0,0,0", "--convention", "pi", "--pivot-mode", "fixed"}, 2, "--pivot-mode");
  expect({"fk", "--legs", "0.007,0,0,0,0,0"}, 3, "beyond the stroke");
  expect({"fk", "--legs", "0.006,-0.006,0.006,0.006,-0.006,0.006"}, 4,
         "forward kinematics of leg coordinates");
  expect({"workspace", "--slice", "x,x"}, 2, "--slice");
  expect({"workspace", "--at", "0.009,0,0,0,0,0"}, 3, "unreachable: stroke limit");
}

TEST(PositionerCli, WorkspaceOutWritesTheSliceAndItsReport) {
  mc::test::TempDir dir;
  const auto r = mc::test::run_cli({"positioner", "workspace", "--slice", "x,rz", "--points", "11", "--units",
                                    "vendor", "--json", "--out", dir.path().string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["slice"]["points"], 121);
  EXPECT_GT(j["slice"]["reachable"].get<int>(), 0);
  EXPECT_LT(j["slice"]["reachable"].get<int>(), 121);  // +-8 mm passes the +-6 mm strokes
  for (const char* axis : {"rx", "ry", "rz"}) {
    const auto& range = j["rotation_range"][axis];
    EXPECT_LT(range["min"].get<double>(), -5.0) << axis;  // deg: --units vendor
    EXPECT_GT(range["max"].get<double>(), 5.0) << axis;
  }
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "workspace_slice.csv"));
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "index.html"));
}

TEST(PositionerCli, AParameterFileChangesTheGeometryAndABadOneIsRefusedNamingItsKey) {
  mc::test::TempDir dir;
  const auto narrow = dir.path() / "narrow.yaml";
  mc::test::write_text(narrow, "stroke_m: 0.008\n");
  EXPECT_EQ(mc::test::run_cli({"positioner", "ik", "--pose", "0.005,0,0,0,0,0"}).exit_code, 0);
  const auto r =
      mc::test::run_cli({"positioner", "ik", "--pose", "0.005,0,0,0,0,0", "--params", narrow.string()});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("beyond its stroke +-4 mm"), std::string::npos) << r.err;
  const auto bad = dir.path() / "bad.yaml";
  mc::test::write_text(bad, "platform_radius_m: 0.05\n");
  const auto b = mc::test::run_cli({"positioner", "params", "--params", bad.string()});
  EXPECT_EQ(b.exit_code, 3);
  EXPECT_NE(b.err.find("platform_radius_m"), std::string::npos) << b.err;
}

}  // namespace positioner_cli_test
}  // namespace mc::motion
