// `microcobot vision calibrate|track|autofocus` as a user runs them: the goals on the
// simulation's truth, the files under --out, and one-line errors with their exit codes.

#include <filesystem>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "microcobot/platform/platform_config.h"
#include "support/test_support.h"

namespace mc {
namespace {

using test::run_cli;
using ::testing::HasSubstr;

TEST(VisionCli, CalibrateRecoversAMisalignedStageWithinTheGoals) {
  test::TempDir dir;
  const auto r =
      run_cli({"vision", "calibrate", "--axis-angle-deg", "-1.7", "--skew-deg", "0.4", "--scale-x", "1.012",
               "--scale-y", "0.993", "--seed", "4", "--json", "--out", dir.path().string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_LT(j["residual_rms_px"].get<double>(), 0.1);
  EXPECT_LT(std::abs(j["scale_error_x"].get<double>()), 2e-3);
  EXPECT_LT(std::abs(j["scale_error_y"].get<double>()), 2e-3);
  EXPECT_NEAR(j["map"]["rotation_deg"].get<double>(), -1.7, 0.02);
  EXPECT_NEAR(j["map"]["shear_deg"].get<double>(), 0.4, 0.02);
  EXPECT_EQ(j["points"].get<int>(), 25);
  for (const char* f : {"calibration.json", "points.csv", "frame-home.png"})
    EXPECT_TRUE(std::filesystem::exists(dir.path() / f)) << f;
}

// The calibration saved as a configuration fragment loads into the platform's camera and maps
// stage points to the pixels the fit found.
TEST(VisionCli, ASavedCalibrationLoadsIntoThePlatformsCamera) {
  test::TempDir dir;
  const auto r = run_cli({"vision", "calibrate", "--objective", "20x", "--axis-angle-deg", "2.5", "--grid",
                          "3", "--save", (dir / "calibration.yaml").string(), "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  const platform::PlatformConfig c = platform::load_platform_config(dir / "calibration.yaml");
  int twenty = -1;
  for (std::size_t i = 0; i < c.camera.objectives.size(); ++i)
    if (c.camera.objectives[i].name == "20x") twenty = static_cast<int>(i);
  ASSERT_GE(twenty, 0);
  const vision::StageCalibration* cal = c.camera.calibration(twenty);
  ASSERT_NE(cal, nullptr);
  EXPECT_EQ(c.camera.calibration((twenty + 1) % static_cast<int>(c.camera.objectives.size())), nullptr);
  const vision::AffineMap m = cal->map();
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b)
      EXPECT_NEAR(m.A(a, b), j["map"]["A_px_per_m"][a][b].get<double>(), 1e-6 * std::abs(m.A(0, 0)));
  EXPECT_NEAR(vision::affine_figures(m).rotation_rad * 180.0 / M_PI, 2.5, 0.02);
}

TEST(VisionCli, TrackFollowsAPartWithinTheGoal) {
  const auto r = run_cli({"vision", "track", "--frames", "30", "--speed-um-s", "35", "--direction-deg",
                          "-120", "--seed", "9", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["found"].get<int>(), 30);
  EXPECT_LT(j["rms_error_px"].get<double>(), 0.05);
}

// The tool's template is sized in the object: 50 um of the tips' ends and gap at 20x and 50x, the
// 96 px floor below. A side fixed in pixels held only the fingers' parallel sides at 50x and slid
// along them by 45 px.
TEST(VisionCli, TheToolsTemplateIsSizedToTheObjective) {
  const std::pair<const char*, int> sides[] = {{"10x", 96}, {"20x", 189}, {"50x", 472}};
  for (const auto& [objective, side] : sides) {
    const auto r = run_cli(
        {"vision", "track", "--target", "tool", "--objective", objective, "--frames", "20", "--json"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["template_px"].get<int>(), side) << objective;
    EXPECT_EQ(j["found"].get<int>(), 20) << objective;
    EXPECT_LT(j["rms_error_px"].get<double>(), 0.5) << objective;
  }
  const auto r = run_cli({"vision", "track", "--target", "tool", "--objective", "20x", "--template-um", "100",
                          "--frames", "2", "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["template_px"].get<int>(), 377);
}

TEST(VisionCli, AutofocusFindsThePartsTopFrom100UmAway) {
  for (const char* offset : {"100", "-100"}) {
    const auto r = run_cli({"vision", "autofocus", "--offset-um", offset, "--seed", "3", "--json"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_TRUE(j["converged"].get<bool>()) << offset;
    EXPECT_LE(j["frames"].get<int>(), 15) << offset;
    EXPECT_LT(std::abs(j["error_m"].get<double>()), 0.3e-6) << offset << " (10x: 0.3 um and DOF/5)";
    EXPECT_LT(std::abs(j["error_dof"].get<double>()), 0.2) << offset;
  }
}

// The tool's tips from 100 um out at 20x and 50x: the strip across the tips sees them only within
// +-40 um (20x) and +-16 um (50x); the coarse scan on a wider square sees their silhouette.
TEST(VisionCli, AutofocusFindsTheToolsTipsFrom100UmAwayAt20xAnd50x) {
  for (const char* objective : {"20x", "50x"}) {
    for (const char* offset : {"100", "-100"}) {
      const auto r = run_cli({"vision", "autofocus", "--target", "tool", "--objective", objective,
                              "--offset-um", offset, "--seed", "3", "--json"});
      ASSERT_EQ(r.exit_code, 0) << r.err;
      const auto j = nlohmann::json::parse(r.out);
      EXPECT_EQ(j["coarse_px"].get<int>(), 192);
      EXPECT_TRUE(j["converged"].get<bool>()) << objective << " " << offset;
      EXPECT_LE(j["frames"].get<int>(), 15) << objective << " " << offset;
      EXPECT_LT(std::abs(j["error_dof"].get<double>()), 0.2) << objective << " " << offset;
    }
  }
}

TEST(VisionCli, BadInputsGetOneLineAndTheirExitCode) {
  auto r = run_cli({"vision", "track", "--objective", "7x"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("--objective"));
  r = run_cli({"vision", "calibrate", "--template-px", "1000"});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_THAT(r.err, HasSubstr("--template-px 1000"));
  r = run_cli({"vision", "calibrate", "--pitch-um", "5000"});
  EXPECT_EQ(r.exit_code, 4);
  EXPECT_THAT(r.err, HasSubstr("lost at grid point 0"));
  r = run_cli({"vision", "autofocus", "--metric", "sharpest"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("--metric: focus metric 'sharpest'"));
  EXPECT_EQ(test::line_count(r.err), 1u) << r.err;
  r = run_cli({"vision", "track", "--template-um", "50", "--template-px", "96"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_THAT(r.err, HasSubstr("--template-um"));
  r = run_cli(
      {"vision", "track", "--objective", "20x", "--template-um", "30"});  // the part's corner is out of view
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_THAT(r.err, HasSubstr("--template-um 30 (113 px at 20x)"));
  EXPECT_EQ(test::line_count(r.err), 1u) << r.err;
  r = run_cli({"vision", "track", "--scene", "optical-trap"});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_THAT(r.err, HasSubstr("has no part"));
  EXPECT_EQ(test::line_count(r.err), 1u) << r.err;
}

}  // namespace
}  // namespace mc
