// The contact force by vision: a lateral force on the fingers along their closing
// axis bends both tips together (microworld/pick_place_world.h), and the grip gauge reads the bend
// as the tips' midpoint against the tool point the stage's sensors give, times 2 k_finger. Judged
// here on rendered frames with a known bend (the camera's renderer, the live gauge): bias within 5 %
// of the force, noise within 2x the fingers' stiffness times the tips' tracking noise; the stage's
// own motion is not read as a force; without stage sensors there is none.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <random>
#include <vector>

#include "microcobot/imaging/renderer.h"
#include "microcobot/perception/camera_map.h"
#include "microcobot/perception/vision_grip_force.h"
#include "microcobot/platform/camera_scene.h"

namespace mc::perception {
namespace {

// The pin-in-hole's 200 um pin between the fingers, seen at 10x (0.53 um per pixel) on 800 x 600.
struct ContactScene {
  platform::PlatformConfig config = platform::scene_config("pin-in-hole");
  static constexpr int kObjective = 2;  // 10x
  std::unique_ptr<imaging::Renderer> renderer;
  imaging::CameraControls controls;
  imaging::SceneSnapshot snapshot;
  imaging::Frame rendered;
  platform::CameraScenePose pose;
  std::uint64_t sequence = 0;
  double k = 0.0;

  ContactScene() {
    auto& cam = config.camera;
    cam.sensor.width_px = 800;
    cam.sensor.height_px = 600;
    cam.objective = kObjective;
    cam.view_center_x_m = config.stage.home_x_m;
    cam.view_center_y_m = config.stage.home_y_m;
    k = config.world.gripper.finger_stiffness_N_m;
    renderer = std::make_unique<imaging::Renderer>(platform::renderer_params(cam, kObjective));
    pose.tool_x_m = pose.part_x_m = config.stage.home_x_m;
    pose.tool_y_m = pose.part_y_m = config.stage.home_y_m;
    pose.part_z_m = 0.5 * config.world.height_m();
    pose.tool_z_m = pose.part_z_m + 50e-6;  // grasped 50 um above the pin's middle
    controls = renderer->default_controls();
    controls.focus_z_m = pose.tool_z_m;
  }
  // A frame with the stage at `stage` (offset from the home), the drive's free opening `o`, the
  // fingers bent by `bend_m` along x; the pin between them.
  devices::CameraFrame frame(Eigen::Vector2d stage, double o, double bend_m) {
    const double w = config.world.part_side_m;
    pose.tool_x_m = config.stage.home_x_m + stage.x();
    pose.tool_y_m = config.stage.home_y_m + stage.y();
    pose.part_x_m = pose.tool_x_m + bend_m, pose.part_y_m = pose.tool_y_m;  // in the jaws
    pose.opening_m = std::max(o, w);
    pose.deflection_x_m = bend_m;
    platform::fill_camera_scene(config, pose, snapshot);
    renderer->render(snapshot, controls, 7, sequence, rendered);
    devices::CameraFrame f;
    f.sequence = ++sequence;
    f.t_mid_s = static_cast<double>(sequence) / 30.0;
    f.objective = kObjective;
    f.tool_m[0] = pose.tool_x_m, f.tool_m[1] = pose.tool_y_m, f.tool_m[2] = pose.tool_z_m;
    f.gripper_opening_m = pose.opening_m;
    f.gripper_free_opening_m = o;
    f.image.resize(rendered.width, rendered.height, 1, rendered.bit_depth);
    if (rendered.bit_depth <= 8) {
      for (std::size_t i = 0; i < rendered.pixels.size(); ++i)
        f.image.data[i] = static_cast<std::uint8_t>(rendered.pixels[i]);
    } else {
      std::memcpy(f.image.data.data(), rendered.pixels.data(), 2 * rendered.pixels.size());
    }
    return f;
  }
};

struct Stats {
  double mean = 0.0, sd = 0.0;
};
Stats stats(const std::vector<double>& x) {
  Stats s;
  for (double v : x) s.mean += v / static_cast<double>(x.size());
  for (double v : x) s.sd += (v - s.mean) * (v - s.mean) / static_cast<double>(x.size() - 1);
  s.sd = std::sqrt(s.sd);
  return s;
}

// The gauge tared open, then closed on the pin (1 mN of grip), ready to read contacts.
struct Gauge {
  ContactScene scene;
  VisionGripForce gauge{platform::camera_rig(scene.config), scene.config.vision_force};
  const VisionGripForce::ToolHint sensed{};  // the stage's x, y sensors say where the tool is
  static constexpr double kClosed = 160e-6;

  Gauge() {
    // Open at 300 um (both fingers in the 424 um field), the pin touching neither.
    gauge.on_frame(scene.frame({0, 0}, 300e-6, 0.0), sensed);
    EXPECT_TRUE(gauge.status().tared) << gauge.status().error;
    for (int i = 0; i < 9; ++i) gauge.on_frame(scene.frame({0, 0}, 300e-6, 0.0), sensed);
    for (double o = 290e-6; o > kClosed; o -= 15e-6) gauge.on_frame(scene.frame({0, 0}, o, 0.0), sensed);
    for (int i = 0; i < 3; ++i) gauge.on_frame(scene.frame({0, 0}, kClosed, 0.0), sensed);
  }
  // `n` frames at a stage offset and bend: the contact forces and gaps read.
  void read(Eigen::Vector2d stage, double bend_m, int n, std::vector<double>& force,
            std::vector<double>& gap) {
    force.clear(), gap.clear();
    for (int i = 0; i < 2; ++i) gauge.on_frame(scene.frame(stage, kClosed, bend_m), sensed);  // settle
    for (int i = 0; i < n; ++i) {
      const VisionGripStatus& s = gauge.on_frame(scene.frame(stage, kClosed, bend_m), sensed);
      ASSERT_EQ(s.state, "measuring") << s.error;
      force.push_back(s.contact_force_N);
      gap.push_back(s.gap_m);
    }
  }
};

TEST(VisionContactForce, TheTipsCommonBendReadsTheContactForceWithinFivePercent) {
  Gauge g;
  const double k2 = 2.0 * g.scene.k;
  std::vector<double> force, gap;
  // Bends of 1-5 um (100-500 uN with 2 k = 100 N/m; the grip holds 600 uN) at the stage's home and
  // up to 18 um away from where the gauge was tared; then a seeded random set (bends of 0.5-5.5 um
  // either way, the stage within 20 um): the gauge has no searched parameter, the set only keeps
  // the listed cases from being the only ones.
  struct Case {
    Eigen::Vector2d stage;
    double bend_m;
  };
  std::vector<Case> cases = {Case{{0, 0}, 2e-6}, Case{{0, 0}, -4e-6}, Case{{15e-6, -10e-6}, 3e-6},
                             Case{{-12e-6, 8e-6}, -1e-6}, Case{{6e-6, 0}, 5e-6}};
  std::mt19937_64 rng(20261127);
  std::uniform_real_distribution<double> size(0.5e-6, 5.5e-6), where(-20e-6, 20e-6), coin(-1.0, 1.0);
  for (int i = 0; i < 8; ++i) {
    // One draw per statement: the same set whatever the compiler's evaluation order.
    const double x = where(rng);
    const double y = where(rng);
    const double bend = size(rng);
    const double sign = coin(rng) < 0.0 ? -1.0 : 1.0;
    cases.push_back(Case{{x, y}, sign * bend});
  }
  for (const Case& c : cases) {
    g.read(c.stage, c.bend_m, 12, force, gap);
    const Stats f = stats(force), w = stats(gap);
    const double truth = k2 * c.bend_m;
    SCOPED_TRACE(testing::Message() << "bend " << c.bend_m * 1e6 << " um, stage (" << c.stage.x() * 1e6
                                    << ", " << c.stage.y() * 1e6 << ") um");
    EXPECT_LT(std::abs(f.mean - truth), 0.05 * std::abs(truth))
        << "read " << f.mean * 1e6 << " uN of " << truth * 1e6;
    // The noise goal, for the common mode's stiffness 2 k: within 2x of 2 k times a tip's
    // tracking noise, sd_gap / sqrt(2) (the two tips' errors taken as independent).
    const double tracking_m = w.sd / std::sqrt(2.0);
    EXPECT_LT(f.sd, 2.0 * k2 * tracking_m) << "noise " << f.sd * 1e6 << " uN, gap sd " << w.sd * 1e9 << " nm";
    std::printf(
        "bend %+.2f um at (%+.1f, %+.1f) um: %.2f uN of %.2f (%+.2f %%), sd %.3f uN, tip noise %.2f nm\n",
        c.bend_m * 1e6, c.stage.x() * 1e6, c.stage.y() * 1e6, f.mean * 1e6, truth * 1e6,
        100 * (f.mean / truth - 1), f.sd * 1e6, tracking_m * 1e9);
    // The grip is not disturbed by the common mode.
    EXPECT_NEAR(w.mean, g.scene.config.world.part_side_m, 0.05e-6);
  }
}

TEST(VisionContactForce, TheStagesOwnMotionIsNotAForce) {
  Gauge g;
  std::vector<double> force, gap;
  for (const Eigen::Vector2d& stage : {Eigen::Vector2d(20e-6, 0), Eigen::Vector2d(-15e-6, 12e-6)}) {
    g.read(stage, 0.0, 8, force, gap);
    // Under a tenth of the 60 uN the cell calls a contact.
    EXPECT_LT(std::abs(stats(force).mean), 6e-6) << stats(force).mean * 1e6 << " uN";
    std::printf("stage at (%+.0f, %+.0f) um, no contact: %.2f uN\n", stage.x() * 1e6, stage.y() * 1e6,
                stats(force).mean * 1e6);
  }
}

TEST(VisionContactForce, WithoutTheStagesSensorsThereIsNoContactForce) {
  Gauge g;
  // The vision positioner's tool point is the tips themselves: nothing to measure the bend against.
  VisionGripForce::ToolHint seen;
  seen.pixel = camera_stage_map(platform::camera_rig(g.scene.config), ContactScene::kObjective)
                   .pixel_of(Eigen::Vector2d(3e-6, 0));
  seen.stage_sensed = false;
  const VisionGripStatus& s = g.gauge.on_frame(g.scene.frame({0, 0}, Gauge::kClosed, 3e-6), seen);
  ASSERT_EQ(s.state, "measuring") << s.error;
  EXPECT_TRUE(std::isfinite(s.grip_force_N)) << "the grip needs no stage sensor";
  EXPECT_TRUE(std::isnan(s.contact_force_N));
}

}  // namespace
}  // namespace mc::perception
