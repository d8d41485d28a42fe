// Live: the grip force measured by vision on the camera's frames (the finger
// tips' distance against the drive's free opening, times the fingers' stiffness) agrees with the
// simulated gripper's sensor; it is tared at the scene's start and on request; it needs no stage
// sensor; without frames there is none.
// Figures: docs/benchmarks.md ("Force by vision, live").

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <random>
#include <thread>
#include <vector>

#include "microcobot/core/error.h"
#include "microcobot/live/live_platform.h"
#include "microcobot/microworld/pick_place_world.h"
#include "support/live_status_wait.h"
#include "support/sanitizers.h"
#include "support/test_support.h"

namespace mc::live {
namespace {

using namespace std::chrono_literals;

// The part between the open fingers from the start, the tips at its mid-height, the microscope
// on them at 5x (1.06 um per pixel; the 600 um opening and both fingers inside 848 um).
LiveParams grip_params() {
  LiveParams p;
  auto& st = p.platform.stage;
  auto& w = p.platform.world;
  st.home_z_m = 0.5 * w.height_m();
  w.part_start_m.x() = st.home_x_m;
  w.part_start_m.y() = st.home_y_m;
  w.grip_force_limit_N = 20e-3;  // up to what the closed gripper squeezes (7.5 mN on 300 um)
  auto& cam = p.platform.camera;
  cam.sensor.width_px = 800;
  cam.sensor.height_px = 600;
  cam.objective = 1;  // 5x
  cam.view_center_x_m = st.home_x_m;
  cam.view_center_y_m = st.home_y_m;
  cam.focus_start_m = st.home_z_m;
  return p;
}

// The live platform with the console in control and the deadman held (the gripper moves only
// with it), its gripper command set by the test; the sensor's grip force collected from the
// telemetry, the vision's from the gauge's status, once per frame.
struct GripRig {
  LivePlatform live;
  std::mutex m;
  std::vector<double> sensor, contact;
  bool collecting = false;
  std::atomic<bool> run{true};
  std::atomic<double> opening{600e-6};
  std::atomic<double> theta_goal{std::nan("")};                        // the rotary axis' goal (NaN: none)
  std::atomic<double> theta{0.0};                                      // its sensor, from the telemetry
  std::atomic<double> goal_x{std::nan("")}, goal_y{0.0}, goal_z{0.0};  // click-to-go (NaN: none)
  std::thread sender;
  const std::size_t grip = test::telemetry_channel("grip_force_N");
  const std::size_t yaw = test::telemetry_channel("measured_theta_rad");
  const std::size_t contact_x = test::telemetry_channel("contact_x_N");

  explicit GripRig(LiveParams p) : live(std::move(p)) {
    live.set_camera_wanted(true);  // a console watching: the camera forms frames
    live.start([this](const platform::TelemetrySample& s, std::size_t) {
      theta.store(s[yaw]);
      std::lock_guard lock(m);
      if (!collecting) return;
      sensor.push_back(s[grip]);
      contact.push_back(s[contact_x]);
    });
    live.set_console_in_control(true);
    sender = std::thread([this] {
      while (run.load()) {
        ConsoleCommand c;
        c.deadman = true;
        c.has_gripper = true;
        c.gripper_opening_m = opening.load();
        c.has_theta_goal = std::isfinite(theta_goal.load());
        c.theta_goal_rad = c.has_theta_goal ? theta_goal.load() : 0.0;
        c.has_goal = std::isfinite(goal_x.load());
        if (c.has_goal) c.goal_m = {goal_x.load(), goal_y.load(), goal_z.load()};
        live.push_command(c);
        std::this_thread::sleep_for(20ms);
      }
    });
  }
  ~GripRig() {
    run = false;
    sender.join();
    live.stop();
  }
  template <class Done>
  bool wait(Done done, double timeout_s) {
    return test::wait_status(live, done, timeout_s);
  }
  // The mean of each force over `window`, and on until `min_frames` frames came (a loaded machine
  // forms fewer a second; at most 20 s more): the sensor's; the vision's over the frames that
  // measured one, and how many frames there were.
  struct Means {
    double sensor_N = 0.0, vision_N = 0.0;
    double contact_sensor_N = 0.0, contact_vision_N = 0.0;  // along x (the fingers' closing axis)
    std::size_t measured_frames = 0, frames = 0;
  };
  Means collect(std::chrono::milliseconds window, std::size_t min_frames = 0) {
    {
      std::lock_guard lock(m);
      sensor.clear();
      contact.clear();
      collecting = true;
    }
    Means r;
    std::uint64_t last_frame = 0;
    const auto start = std::chrono::steady_clock::now();
    const auto more = [&] {
      const auto t = std::chrono::steady_clock::now();
      return t < start + window || (r.frames < min_frames && t < start + window + 20s);
    };
    while (more()) {
      const auto g = live.status().grip_vision;
      if (g && g->frames != last_frame) {
        if (last_frame != 0) {
          ++r.frames;
          if (std::isfinite(g->grip_force_N)) {
            r.vision_N += g->grip_force_N;
            r.contact_vision_N += g->contact_force_N;
            ++r.measured_frames;
          }
        }
        last_frame = g->frames;
      }
      std::this_thread::sleep_for(3ms);
    }
    if (r.measured_frames > 0) r.vision_N /= static_cast<double>(r.measured_frames);
    if (r.measured_frames > 0) r.contact_vision_N /= static_cast<double>(r.measured_frames);
    std::lock_guard lock(m);
    collecting = false;
    for (double v : sensor) r.sensor_N += v / static_cast<double>(sensor.size());
    for (double v : contact) r.contact_sensor_N += v / static_cast<double>(contact.size());
    return r;
  }
};

TEST(VisionGripForce, TheGripForceSeenAgreesWithTheSensorAndIsPublishedBesideIt) {
  LiveParams p = grip_params();
  const double k = p.platform.world.gripper.finger_stiffness_N_m, w = p.platform.world.part_side_m;
  GripRig rig(std::move(p));
  const double boot_s = MC_UNDER_SANITIZER ? 30.0 : 10.0;
  ASSERT_TRUE(rig.wait(
      [](const LiveStatus& s) { return s.grip_vision && s.grip_vision->tared && s.grip_vision->frames > 3; },
      boot_s))
      << "not tared: " << (rig.live.status().grip_vision ? rig.live.status().grip_vision->error : "no gauge");
  // Open, nothing touched: no force, seen as none.
  const auto open = rig.collect(600ms, 6);
  std::printf("open: vision %.2f uN\n", 1e6 * open.vision_N);
  EXPECT_EQ(open.sensor_N, 0.0);
  ASSERT_GT(open.frames, 5u) << "the camera forms no frames";
  EXPECT_EQ(open.measured_frames, open.frames) << "a frame without a force";
  EXPECT_LT(std::abs(open.vision_N), 20e-6);

  // Squeezed at 1, 4 and 7 mN (the free opening w - 2 F / k): the estimate within 5 % of the
  // sensor (the bias goal) once the fingers have settled.
  for (double force : {1e-3, 4e-3, 7e-3}) {
    rig.opening = w - 2.0 * force / k;
    std::this_thread::sleep_for(MC_UNDER_SANITIZER ? 1500ms : 500ms);
    const auto g = rig.collect(MC_UNDER_SANITIZER ? 1500ms : 600ms);
    const auto st = rig.live.status().grip_vision.value();
    std::printf(
        "grip %.1f mN: sensor %.4f mN, vision %.4f mN (%+.2f %%), %zu of %zu frames measured, state %s\n",
        1e3 * force, 1e3 * g.sensor_N, 1e3 * g.vision_N, 100.0 * (g.vision_N / g.sensor_N - 1.0),
        g.measured_frames, g.frames, st.state.c_str());
    EXPECT_NEAR(g.sensor_N, force, 0.02 * force) << "the gripper did not squeeze as commanded";
    ASSERT_GT(g.measured_frames, g.frames / 2) << st.state << ": " << st.error;
    EXPECT_NEAR(g.vision_N, g.sensor_N, 0.05 * g.sensor_N);
    EXPECT_EQ(st.state, "measuring");
    EXPECT_GT(st.confidence, 0.8);
  }
  // Let go: back to no force.
  rig.opening = 600e-6;
  std::this_thread::sleep_for(500ms);
  const auto released = rig.collect(600ms);
  std::printf("released: vision %.2f uN\n", 1e6 * released.vision_N);
  EXPECT_EQ(released.sensor_N, 0.0);
  EXPECT_LT(std::abs(released.vision_N), 20e-6);
}

// The contact force: the pin gripped in its bore (10 um of play each side) and
// the stage sent past the wall: the fingers bend (microworld/pick_place_world.h), the gripper's
// sensor feels 2 k times the push, and the camera sees the tips' common bend against where the
// stage's sensors put the fingers.
TEST(VisionGripForce, ThePinPushedIntoItsBoresWallIsAContactForceSeenAsTheSensorFeelsIt) {
  LiveParams p = grip_params();
  auto& w = p.platform.world;
  auto& st = p.platform.stage;
  w = microworld::pin_in_hole_scene();
  w.part_start_m.head<2>() = w.target_m.head<2>();  // down in its bore
  w.gripper.max_opening_m = 300e-6;                 // a pin gripper: both fingers open in the 10x field
  st.home_x_m = w.target_m.x(), st.home_y_m = w.target_m.y();
  st.home_z_m = 200e-6;  // the tips 100 um below the pin's top, 200 um above the substrate
  auto& cam = p.platform.camera;
  cam.objective = 2;  // 10x: 0.53 um per pixel, the 200 um pin and both fingers in 424 um
  cam.view_center_x_m = st.home_x_m, cam.view_center_y_m = st.home_y_m;
  cam.focus_start_m = st.home_z_m;
  const double k2 = 2.0 * w.gripper.finger_stiffness_N_m, home_x = st.home_x_m;
  GripRig rig(std::move(p));
  ASSERT_TRUE(rig.wait(
      [](const LiveStatus& s) { return s.grip_vision && s.grip_vision->tared && s.grip_vision->frames > 10; },
      MC_UNDER_SANITIZER ? 30.0 : 10.0));
  rig.goal_y = 0.0, rig.goal_z = 200e-6;
  rig.opening = 160e-6;  // 1 mN on the 200 um pin: the grip holds 600 uN
  const auto settle = MC_UNDER_SANITIZER ? 2500ms : 1200ms;
  const auto window = MC_UNDER_SANITIZER ? 1500ms : 800ms;
  std::this_thread::sleep_for(settle);
  const auto centred = rig.collect(window);
  std::printf("centred: contact sensor %.1f uN, vision %.1f uN\n", 1e6 * centred.contact_sensor_N,
              1e6 * centred.contact_vision_N);
  ASSERT_GT(centred.sensor_N, 0.9e-3) << "not gripped";
  EXPECT_EQ(centred.contact_sensor_N, 0.0);
  EXPECT_LT(std::abs(centred.contact_vision_N), 10e-6);
  // 3 um past the right wall, then 4 um past the left one: 300 and 400 uN.
  for (double past : {13e-6, -14e-6}) {
    rig.goal_x = home_x + past;
    std::this_thread::sleep_for(settle);
    const auto c = rig.collect(window);
    const auto g = rig.live.status().grip_vision.value();
    std::printf("pushed %+.0f um: contact sensor %.1f uN, vision %.1f uN (%+.2f %%), %zu of %zu frames\n",
                1e6 * past, 1e6 * c.contact_sensor_N, 1e6 * c.contact_vision_N,
                100.0 * (c.contact_vision_N / c.contact_sensor_N - 1.0), c.measured_frames, c.frames);
    const double want = -k2 * (past - std::copysign(10e-6, past));
    EXPECT_NEAR(c.contact_sensor_N, want, 0.1 * std::abs(want)) << "the stage did not push as sent";
    ASSERT_GT(c.measured_frames, c.frames / 2) << g.state << ": " << g.error;
    EXPECT_NEAR(c.contact_vision_N, c.contact_sensor_N, 0.05 * std::abs(c.contact_sensor_N));
  }
}

TEST(VisionGripForce, WithoutTheStagesXYSensorsTheTipsAreLookedForWhereThePositionerSeesTheTool) {
  LiveParams p = grip_params();
  p.platform.stage.xy_sensor = "vision";
  const double k = p.platform.world.gripper.finger_stiffness_N_m, w = p.platform.world.part_side_m;
  GripRig rig(std::move(p));
  ASSERT_TRUE(rig.wait(
      [](const LiveStatus& s) {
        return s.vision && s.vision->found && s.grip_vision && s.grip_vision->tared &&
               s.grip_vision->frames > 3;
      },
      MC_UNDER_SANITIZER ? 30.0 : 10.0));
  const double force = 3e-3;
  rig.opening = w - 2.0 * force / k;
  std::this_thread::sleep_for(MC_UNDER_SANITIZER ? 1500ms : 500ms);
  const auto g = rig.collect(MC_UNDER_SANITIZER ? 1500ms : 600ms);
  const auto st = rig.live.status().grip_vision.value();
  std::printf("grip %.1f mN, stage on vision: sensor %.4f mN, vision %.4f mN\n", 1e3 * force,
              1e3 * g.sensor_N, 1e3 * g.vision_N);
  ASSERT_GT(g.measured_frames, g.frames / 2) << st.state << ": " << st.error;
  EXPECT_NEAR(g.vision_N, g.sensor_N, 0.05 * g.sensor_N);
  // The positioner follows the tool while the part is held (its templates leave the jaw out).
  EXPECT_TRUE(rig.live.status().vision->found) << rig.live.status().vision->state;
}

// The fingers turned by the rotary axis: while they turn the gauge says so and
// measures nothing; still at the new yaw, it measures the held part's grip again (the tips taught
// there, the gap chained from before the turn) within 5 % of the sensor. A gripper that moved
// while the fingers turned leaves the gap unknown: the gauge asks for a tare.
TEST(VisionGripForce, TurnedFingersAreMeasuredOnceStillAndAGripperMovedWhileTurningAsksForATare) {
  LiveParams p = grip_params();
  const double k = p.platform.world.gripper.finger_stiffness_N_m, w = p.platform.world.part_side_m;
  GripRig rig(std::move(p));
  ASSERT_TRUE(rig.wait(
      [](const LiveStatus& s) { return s.grip_vision && s.grip_vision->tared && s.grip_vision->frames > 3; },
      MC_UNDER_SANITIZER ? 30.0 : 10.0));
  const double force = 4e-3, turn = 20.0 * M_PI / 180.0;
  rig.opening = w - 2.0 * force / k;
  std::this_thread::sleep_for(MC_UNDER_SANITIZER ? 1500ms : 500ms);
  rig.theta_goal = turn;
  bool saw_turning = false;
  ASSERT_TRUE(test::eventually(
      [&] {
        const auto g = rig.live.status().grip_vision;
        saw_turning = saw_turning ||
                      (g && g->error.find("turning") != std::string::npos && !std::isfinite(g->grip_force_N));
        return std::abs(rig.theta.load() - turn) < 1e-5;
      },
      MC_UNDER_SANITIZER ? 30s : 10s));
  EXPECT_TRUE(saw_turning) << "the gauge did not say the fingers were turning";
  ASSERT_TRUE(rig.wait([](const LiveStatus& s) { return s.grip_vision->state == "measuring"; }, 5.0))
      << rig.live.status().grip_vision->error;
  std::this_thread::sleep_for(MC_UNDER_SANITIZER ? 1000ms : 300ms);
  const auto g = rig.collect(MC_UNDER_SANITIZER ? 1500ms : 600ms);
  const auto st = rig.live.status().grip_vision.value();
  std::printf(
      "grip %.1f mN, fingers at %.1f deg: sensor %.4f mN, vision %.4f mN (%+.2f %%), %zu of %zu frames\n",
      1e3 * force, rig.theta.load() * 180.0 / M_PI, 1e3 * g.sensor_N, 1e3 * g.vision_N,
      100.0 * (g.vision_N / g.sensor_N - 1.0), g.measured_frames, g.frames);
  EXPECT_NEAR(g.sensor_N, force, 0.02 * force);
  ASSERT_GT(g.measured_frames, g.frames / 2) << st.state << ": " << st.error;
  EXPECT_NEAR(g.vision_N, g.sensor_N, 0.05 * g.sensor_N);

  // Back to 0 deg while the gripper opens: the gap after the turn is unknown.
  rig.theta_goal = 0.0;
  std::this_thread::sleep_for(300ms);
  rig.opening = 600e-6;
  ASSERT_TRUE(
      test::eventually([&] { return std::abs(rig.theta.load()) < 1e-5; }, MC_UNDER_SANITIZER ? 30s : 10s));
  ASSERT_TRUE(rig.wait([](const LiveStatus& s) { return s.grip_vision->state == "untared"; }, 5.0))
      << rig.live.status().grip_vision->state;
  EXPECT_NE(rig.live.status().grip_vision->error.find("tare again"), std::string::npos)
      << rig.live.status().grip_vision->error;
  // The operator's tare (nothing between the open fingers): measuring again, no force.
  ASSERT_TRUE(rig.live.request_vision_tare());
  ASSERT_TRUE(rig.wait([](const LiveStatus& s) { return s.grip_vision->state == "measuring"; }, 5.0));
  const auto open = rig.collect(600ms);
  EXPECT_LT(std::abs(open.vision_N), 20e-6);
}

// The console's default view (2x, the tips out of focus: a frame's tips' distance is good to about
// a pixel, +-50 uN of grip): open fingers turned to yaws drawn at random read no force once still.
// Each turn tares afresh over frames; a noisy frame must neither cut that average short nor pass
// for a held part, or the tare keeps one frame's error (up to 50 uN).
TEST(VisionGripForce, OpenFingersTurnedAnywhereReadNoForceAtTheConsolesDefaultView) {
  LiveParams p;  // the console's default scene and view
  GripRig rig(std::move(p));
  ASSERT_TRUE(
      rig.wait([](const LiveStatus& s) { return s.grip_vision && s.grip_vision->state == "measuring"; },
               MC_UNDER_SANITIZER ? 60.0 : 20.0));
  std::mt19937 draw(20261206);
  std::uniform_real_distribution<double> yaw_deg(-20.0, 20.0);
  for (int turn = 0; turn < 12; ++turn) {
    const double goal = yaw_deg(draw) * M_PI / 180.0;
    rig.theta_goal = goal;
    ASSERT_TRUE(test::eventually([&] { return std::abs(rig.theta.load() - goal) < 1e-5; },
                                 MC_UNDER_SANITIZER ? 60s : 20s));
    rig.theta_goal = std::nan("");  // let go, as the console does once there
    ASSERT_TRUE(rig.wait([](const LiveStatus& s) { return s.grip_vision->state == "measuring"; }, 10.0))
        << rig.live.status().grip_vision->error;
    // The mean over the first 20 frames measured (their noise: 50 uN / sqrt(20) = 11 uN): no grip.
    const auto open = rig.collect(0ms, 20);
    std::printf("open fingers at %+6.2f deg: %+6.1f uN over %zu of %zu frames\n", goal * 180.0 / M_PI,
                open.vision_N * 1e6, open.measured_frames, open.frames);
    ASSERT_GE(open.measured_frames, 10u);
    EXPECT_LT(std::abs(open.vision_N), 30e-6) << "at " << goal * 180.0 / M_PI << " deg";
  }
}

TEST(VisionGripForce, ATareOnRequestAndNoneWithoutFrames) {
  LiveParams p = grip_params();
  p.platform.vision_force.tare_at_start = false;
  GripRig rig(std::move(p));
  ASSERT_TRUE(rig.wait([](const LiveStatus& s) { return s.grip_vision && s.grip_vision->frames > 3; },
                       MC_UNDER_SANITIZER ? 30.0 : 10.0));
  // Untared: no force published.
  auto st = rig.live.status().grip_vision.value();
  EXPECT_EQ(st.state, "untared");
  EXPECT_FALSE(st.tared);
  const auto untared = rig.collect(300ms);
  EXPECT_GT(untared.frames, 0u);
  EXPECT_EQ(untared.measured_frames, 0u);
  ASSERT_TRUE(rig.live.request_vision_tare());
  ASSERT_TRUE(rig.wait([](const LiveStatus& s) { return s.grip_vision->tares == 1; }, 5.0));
  st = rig.live.status().grip_vision.value();
  EXPECT_EQ(st.state, "measuring");
  EXPECT_GT(rig.collect(300ms).measured_frames, 0u);
  // The camera unwanted: no frames, no new force.
  rig.live.set_camera_wanted(false);
  std::this_thread::sleep_for(300ms);
  EXPECT_EQ(rig.collect(300ms).frames, 0u);
}

TEST(VisionGripForce, ItsParametersAreRefusedNamingTheirKey) {
  LiveParams p = grip_params();
  p.platform.world.gripper.finger_width_m = 0.0;
  try {
    LivePlatform live(p);
    FAIL() << "accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("gripper.finger_width_m"), std::string::npos) << e.what();
  }
  p = grip_params();
  p.platform.vision_force.tracker.lost_below = std::nan("");
  try {
    LivePlatform live(p);
    FAIL() << "accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("vision_force.tracker.lost_below"), std::string::npos) << e.what();
  }
  // Off: no gauge, no status, the channel null.
  p = grip_params();
  p.platform.vision_force.enabled = false;
  LivePlatform live(p);
  EXPECT_FALSE(live.status().grip_vision.has_value());
  EXPECT_FALSE(live.request_vision_tare());
}

}  // namespace
}  // namespace mc::live
