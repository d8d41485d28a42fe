#include "microcobot/devices/camera_device.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <thread>
#include <vector>

#include "microcobot/core/error.h"
#include "microcobot/core/jpeg.h"
#include "microcobot/platform/platform.h"
#include "support/counting_allocator.h"
#include "support/sanitizers.h"
#include "support/test_camera.h"
#include "support/test_support.h"

namespace mc::devices {
namespace {

using namespace std::chrono_literals;

// How long a frame may take to form: instrumented by a sanitizer on a loaded machine, the camera
// thread can wait seconds for a core.
constexpr std::chrono::seconds kFrameWait = MC_UNDER_SANITIZER ? 30s : 5s;

platform::PlatformConfig camera_config() {
  test::register_test_camera();
  platform::PlatformConfig c;
  c.devices.camera.driver = "test-pattern";
  c.camera.sensor.width_px = 320;
  c.camera.sensor.height_px = 256;
  c.camera.sensor.bit_depth = 8;
  c.camera.objective = 1;  // 5x: 1.06 um a pixel, a 339 um wide field
  c.camera.view_center_x_m = c.world.part_start_m.x();
  c.camera.view_center_y_m = c.world.part_start_m.y();
  return c;
}

// Frames collected by a sink (the camera thread) for the test thread.
struct Frames {
  std::mutex mutex;
  std::vector<CameraFrame> frames;
  void add(const CameraFrame& f) {
    std::lock_guard lock(mutex);
    frames.push_back(f);
  }
  std::size_t size() {
    std::lock_guard lock(mutex);
    return frames.size();
  }
};

TEST(Camera, FramesCarryTheLoopTimeAtMidExposureAndTheObjectiveAndFocusState) {
  platform::PlatformConfig config = camera_config();
  Frames got;  // declared before the platform: the camera thread writes to it until it stops
  platform::Platform platform(config);
  ASSERT_NE(platform.camera(), nullptr);
  ASSERT_NE(platform.focus(), nullptr);
  platform.camera()->set_sink([&](const CameraFrame& f) { got.add(f); });
  // Unpaced, the loop would outrun the camera: run it in steps shorter than a frame period and
  // let the camera form each frame due before going on.
  const double period = 1.0 / config.camera.frame_rate_Hz(), dt = config.loop.period_s();
  for (std::uint64_t ticks = 100; ticks <= 3400; ticks += 100) {
    platform.loop().run_for(100);
    const auto due =
        static_cast<std::size_t>(std::floor(static_cast<double>(ticks - 1) * dt / period + 1e-9)) + 1;
    ASSERT_TRUE(test::eventually([&] { return got.size() >= due; }, kFrameWait)) << due;
  }
  std::lock_guard lock(got.mutex);
  ASSERT_EQ(got.frames.size(), 11u);
  for (std::size_t k = 0; k < got.frames.size(); ++k) {
    const CameraFrame& f = got.frames[k];
    EXPECT_EQ(f.sequence, k);
    // Frame k's mid-exposure is k / rate, at the first tick that reaches it.
    EXPECT_GE(f.t_mid_s, static_cast<double>(k) * period - 1e-12);
    EXPECT_LT(f.t_mid_s, static_cast<double>(k) * period + dt + 1e-12);
    EXPECT_EQ(f.objective, 1);
    EXPECT_EQ(f.objective_name, "5x");
    EXPECT_NEAR(f.m_per_px, 5.3e-6 / 5.0, 1e-15);
    EXPECT_DOUBLE_EQ(f.focus_z_m, config.camera.focus_start_m);
    EXPECT_DOUBLE_EQ(f.exposure_s, config.camera.sensor.exposure_s);
    EXPECT_EQ(f.image.width, 320);
    // The JPEG decodes to the frame's image (lossy: the square stays where it was drawn).
    const JpegImage decoded = decode_jpeg(f.jpeg);
    ASSERT_EQ(decoded.width, 320);
    ASSERT_EQ(decoded.height, 256);
    const std::size_t centre = 128 * 320 + 160;
    EXPECT_NEAR(decoded.pixels[centre], f.image.data[centre], 8);
    EXPECT_GT(f.image.data[centre], 100) << "the part, at the view's centre, drawn bright";
  }
}

TEST(Camera, TheFocusDriveMovesAtItsSpeedWithinItsLimitsAndTheTurretChangesTheScale) {
  platform::PlatformConfig config = camera_config();
  Frames got;
  platform::Platform platform(config);
  FocusDrive& focus = *platform.focus();
  focus.command_z_m(1.0);  // far beyond the travel: clamped
  EXPECT_DOUBLE_EQ(focus.target_z_m(), config.camera.focus_max_m);
  platform.loop().run_for(1000);  // 0.1 s at 1 mm/s: 100 um
  EXPECT_NEAR(focus.z_m(), 100e-6, 1e-9);
  focus.command_objective(3);
  focus.command_objective(7);  // no such objective: ignored
  EXPECT_EQ(focus.objective(), 3);
  platform.camera()->set_sink([&](const CameraFrame& f) { got.add(f); });
  platform.loop().run_for(334);
  ASSERT_TRUE(test::eventually([&] { return got.size() >= 1; }, kFrameWait));
  std::lock_guard lock(got.mutex);
  const CameraFrame& f = got.frames.back();
  EXPECT_EQ(f.objective_name, "20x");
  EXPECT_NEAR(f.m_per_px, 5.3e-6 / 20.0, 1e-15);
  EXPECT_GT(f.focus_z_m, 100e-6);
  EXPECT_LE(f.focus_z_m, 100e-6 + 334 * 1e-4 * 1e-3 + 1e-12) << "never faster than its speed";

  // E-stop: the drive holds where it is and refuses commands until reset.
  platform.fault_all();
  const double held = focus.z_m();
  focus.command_z_m(-1.0);
  platform.loop().run_for(1000);
  EXPECT_DOUBLE_EQ(focus.z_m(), held);
}

TEST(Camera, AStalledCameraThreadNeitherDelaysNorAllocatesOnTheLoop) {
  using Clock = std::chrono::steady_clock;
  platform::PlatformConfig config = camera_config();
  config.loop.realtime = true;
  const std::uint64_t ticks = 10000;  // 1 s at 10 kHz
  const auto run = [&](platform::Platform& p) {
    const auto t0 = Clock::now();
    p.loop().run_realtime(ticks);
    return std::chrono::duration<double>(Clock::now() - t0).count();
  };

  // Baseline: the same platform with its camera flowing.
  Frames got;
  platform::Platform flowing(config);
  flowing.camera()->set_sink([&](const CameraFrame& f) { got.add(f); });
  flowing.loop().run_for(100);
  const double flowing_s = run(flowing);
  const double flowing_p99 = flowing.loop().tick_stats().quantile_s(0.99);
  EXPECT_GE(got.size(), MC_UNDER_SANITIZER ? 5u : 20u) << "about 30 frames in the second";

  // The camera thread stalls in its first frame (a slow consumer) and the loop runs on.
  std::atomic<int> delivered{0};
  platform::Platform stalled(config);
  test::TestCameraControl& control = test::test_camera();
  stalled.camera()->set_sink([&](const CameraFrame&) {
    delivered.fetch_add(1);
    while (control.stall.load()) std::this_thread::sleep_for(1ms);
  });
  control.stall.store(true);
  stalled.loop().run_for(100);  // warm-up
  // run_realtime() runs the loop on a thread of its own (SCHED_FIFO when allowed): counted
  // from the moment it exists.
  double stalled_s = 0.0;
  std::thread runner([&] { stalled_s = run(stalled); });
  ASSERT_TRUE(
      test::eventually([&] { return stalled.loop().thread_id() != std::this_thread::get_id(); }, kFrameWait));
  std::size_t allocations = 0;
  {
    test::AllocationGuard guard(stalled.loop().thread_id());
    runner.join();
    allocations = guard.allocations();
  }
  const CameraStats s = stalled.camera()->stats();
  control.stall.store(false);
  EXPECT_EQ(allocations, 0u);
  EXPECT_LE(delivered.load(), 1) << "the camera thread was stuck";
  // 30 frames were due: the ring held ring_frames of them, the others were dropped, counted.
  EXPECT_GE(s.dropped, 30u - config.camera.ring_frames - 2);
  // Under AddressSanitizer a tick costs about a period (p99 95-120 us seen): the rate is a
  // property of the optimised build; there the bound only says the loop was not held up.
  const double slack = MC_UNDER_SANITIZER ? 0.5 : 0.05;
  EXPECT_LE(stalled_s, (1.0 + slack) * static_cast<double>(ticks) * config.loop.period_s())
      << "the loop kept its rate";
  EXPECT_LE(stalled_s, flowing_s + slack);
  const double stalled_p99 = stalled.loop().tick_stats().quantile_s(0.99);
  RecordProperty("tick_p99_flowing_us", std::to_string(1e6 * flowing_p99));
  RecordProperty("tick_p99_stalled_us", std::to_string(1e6 * stalled_p99));
  std::printf("tick p99: camera flowing %.1f us, camera stalled %.1f us; wall %.3f s, %.3f s for 1 s\n",
              1e6 * flowing_p99, 1e6 * stalled_p99, flowing_s, stalled_s);
  // The p99 figures are printed, not asserted: on a shared VM the tick time jumps between
  // ~6 and ~40 us in spells of seconds whatever the camera does (a CI run saw 5.7 vs 62.7 us).
  // The proof is above: no allocation on the loop and the loop kept its wall-clock rate.
  // bench/camera_bench measures the tick's ratio over interleaved windows.
  // Released, the camera goes on with the newest scene.
  EXPECT_TRUE(test::eventually(
      [&] {
        stalled.loop().run_for(334);
        return delivered.load() >= 3;
      },
      10s));
}

TEST(Camera, ACameraThatFailsPutsEveryDeviceInItsSafeState) {
  platform::PlatformConfig config = camera_config();
  std::atomic<int> frames{0};
  platform::Platform platform(config);
  platform.camera()->set_sink([&](const CameraFrame&) { frames.fetch_add(1); });
  platform.loop().run_for(334);
  ASSERT_TRUE(test::eventually([&] { return frames.load() >= 1; }, kFrameWait));
  test::test_camera().fail.store(true);
  EXPECT_TRUE(test::eventually(
      [&] {
        platform.loop().run_for(334);
        return platform.faulted();
      },
      10s));
  test::test_camera().fail.store(false);
  EXPECT_EQ(platform.camera()->state(), Lifecycle::kFault);
  EXPECT_EQ(platform.axis(0).state(), Lifecycle::kFault) << "blind: the slave holds";
  EXPECT_NE(platform.camera()->stats().error.find("unplugged"), std::string::npos);
  platform.recover();  // the explicit reset reopens the camera
  EXPECT_EQ(platform.camera()->state(), Lifecycle::kActive);
  const int before = frames.load();
  EXPECT_TRUE(test::eventually(
      [&] {
        platform.loop().run_for(334);
        return frames.load() > before;
      },
      10s));
}

TEST(Camera, NoCameraWhenNoneIsConfiguredAndBadSettingsAreNamed) {
  platform::PlatformConfig none;
  EXPECT_EQ(none.devices.camera.driver, "simulated");
  none.devices.camera.driver = "none";
  platform::Platform platform(none);
  EXPECT_EQ(platform.camera(), nullptr);
  EXPECT_EQ(platform.focus(), nullptr);

  platform::PlatformConfig bad = camera_config();
  bad.devices.camera.driver = "webcam9000";
  try {
    bad.validate();
    FAIL() << "accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.exit_code(), ExitCode::kInvalidInput);
    EXPECT_NE(std::string(e.what()).find("devices.camera.driver"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("webcam9000"), std::string::npos) << e.what();
  }
  bad = camera_config();
  bad.camera.sensor.exposure_s = 0.1;  // longer than a frame at 30 fps
  EXPECT_THROW(bad.validate(), Error);
  bad = camera_config();
  bad.camera.objective = 5;
  EXPECT_THROW(bad.validate(), Error);
}

TEST(Camera, TheTurretsObjectivesComeFromTheConfigurationFile) {
  test::TempDir dir;
  test::write_text(
      dir / "turret.yaml",
      "camera:\n"
      "  objectives:\n"
      "    - {name: 10x, magnification: 10, numerical_aperture: 0.28, working_distance_m: 33.5e-3}\n"
      "    - {name: 100x, magnification: 100, numerical_aperture: 0.7, working_distance_m: 6e-3}\n"
      "  objective: 1\n");
  const platform::PlatformConfig c = platform::load_platform_config(dir / "turret.yaml");
  ASSERT_EQ(c.camera.objectives.size(), 2u);
  EXPECT_EQ(c.camera.objectives[1].name, "100x");
  EXPECT_DOUBLE_EQ(c.camera.objectives[1].wavelength_m, 550e-9);  // the element's default
  EXPECT_NEAR(c.camera.m_per_px(1), 5.3e-6 / 100.0, 1e-15);
  // An objective the turret does not hold, and a bad objective, are named.
  test::write_text(dir / "bad.yaml",
                   "camera:\n  objectives:\n    - {name: 10x, magnification: 10}\n  objective: 1\n");
  try {
    platform::load_platform_config(dir / "bad.yaml");
    FAIL() << "accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("objective"), std::string::npos) << e.what();
  }
  test::write_text(dir / "typo.yaml", "camera:\n  objectives:\n    - {name: 10x, magnificaton: 10}\n");
  try {
    platform::load_platform_config(dir / "typo.yaml");
    FAIL() << "accepted";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("camera.objectives[0].magnificaton"), std::string::npos) << e.what();
  }
}

TEST(Camera, CalibrationsInTheConfigurationAreCheckedAndFoundByObjective) {
  test::TempDir dir;
  test::write_text(dir / "cal.yaml",
                   "camera:\n  calibrations:\n"
                   "    - {objective: 10x, px_per_m: [[1.9e6, 0], [0, -1.9e6]], offset_px: [640, 512]}\n");
  const platform::PlatformConfig c = platform::load_platform_config(dir / "cal.yaml");
  int ten = -1;
  for (std::size_t i = 0; i < c.camera.objectives.size(); ++i)
    if (c.camera.objectives[i].name == "10x") ten = static_cast<int>(i);
  ASSERT_NE(c.camera.calibration(ten), nullptr);
  EXPECT_EQ(c.camera.calibration(ten)->map().pixel_of({1e-6, 0}), Eigen::Vector2d(641.9, 512));
  const auto refused = [&](const std::string& item, const std::string& named) {
    test::write_text(dir / "bad.yaml", "camera:\n  calibrations:\n    - " + item + "\n");
    try {
      platform::load_platform_config(dir / "bad.yaml");
      ADD_FAILURE() << item << " accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(named), std::string::npos) << e.what();
    }
  };
  refused("{objective: 7x, px_per_m: [[1e6, 0], [0, 1e6]], offset_px: [0, 0]}", "calibrations[0].objective");
  refused("{objective: 10x, px_per_m: [[1e6, 0], [0, 0]], offset_px: [0, 0]}", "calibrations[0].px_per_m");
  refused("{objective: 10x, px_per_m: [[1e6, 0]], offset_px: [0, 0]}", "calibrations[0].px_per_m");
  refused("{objective: 10x, px_per_m: [[1e6, 0], [0, 1e6]], offset_px: [0]}", "calibrations[0].offset_px");
}

}  // namespace
}  // namespace mc::devices
