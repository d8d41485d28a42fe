// Wire compatibility of the DDS link: a separate plain C program, compiled by idlc from
// the ROS 2 IDL in this directory (not the platform's), subscribes by the ROS 2 names to what a real
// `microcobot link ping` (master) and `microcobot link echo` (slave) publish over loopback, and
// reads the values ping sends: target i is (1 mm cos(2 pi i / 1000), 1 mm sin(2 pi i / 1000), 0),
// gripper target i an opening of 5 mm + 2 mm sin(2 pi i / 1000); the echo returns both with the
// target's stamp; the e-stop is true.

#include <signal.h>
#include <sys/wait.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "net/net_test_support.h"
#include "net/wire/wire_test_support.h"
#include "support/test_support.h"

namespace mc {
namespace {

using nlohmann::json;
using test::TempDir;
using wire::json_lines;
using wire::Reaper;
using wire::system_ns;

constexpr char kPoseType[] = "geometry_msgs::msg::dds_::PoseStamped_";
constexpr char kJointType[] = "sensor_msgs::msg::dds_::JointState_";
constexpr char kBoolType[] = "std_msgs::msg::dds_::Bool_";
constexpr int kPatternPeriod = 1000;  // link ping's targets go round the circle in 1000 steps
constexpr double kTol = 1e-15;        // m: the values as sent (a few ulp of 1 mm)

double phase(int i) { return 2.0 * M_PI * static_cast<double>(i) / kPatternPeriod; }

// The index of ping's target pattern at (x, y), -1 when the point is not on it.
int target_index(double x, double y) {
  for (int i = 0; i < kPatternPeriod; ++i) {
    if (std::abs(x - 1e-3 * std::cos(phase(i))) <= kTol && std::abs(y - 1e-3 * std::sin(phase(i))) <= kTol)
      return i;
  }
  return -1;
}

double gripper_opening(int i) { return 5e-3 + 2e-3 * std::sin(phase(i)); }

bool on_gripper_pattern(double opening) {
  for (int i = 0; i < kPatternPeriod; ++i) {
    if (std::abs(opening - gripper_opening(i)) <= kTol) return true;
  }
  return false;
}

struct Listener {
  std::string topic, type;
  int count;
  pid_t pid = -1;
  std::filesystem::path out{}, err{}, ready{};
  std::vector<json> samples{};
};

TEST(WireCompat, ACProgramFromTheRos2IdlReadsThePlatformsTopics) {
  TempDir dir;
  Reaper reaper;
  const std::string domain = std::to_string(net::test::test_domain_id());

  // --duration: a safety net should the test die before it signals the echo.
  const pid_t echo =
      test::spawn_process({MC_CLI_PATH, "link", "echo", "--domain", domain, "--json", "--duration", "60"},
                          dir / "echo.out", dir / "echo.err");
  reaper.pids.push_back(echo);

  std::vector<Listener> listeners{{"/microcobot/slave/target_pose", "pose", 20},
                                  {"/microcobot/slave/pose", "pose", 20},
                                  {"/microcobot/slave/gripper/target", "joint", 20},
                                  {"/microcobot/slave/gripper/state", "joint", 20},
                                  {"/microcobot/estop", "bool", 1}};
  for (std::size_t k = 0; k < listeners.size(); ++k) {
    Listener& l = listeners[k];
    const std::string n = std::to_string(k);
    l.out = dir / ("listener" + n + ".out");
    l.err = dir / ("listener" + n + ".err");
    l.ready = dir / ("listener" + n + ".ready");
    l.pid = test::spawn_process(
        {MC_ROS2_LISTENER_PATH, "--domain", domain, "--topic", l.topic, "--type", l.type, "--count",
         std::to_string(l.count), "--timeout", "20", "--ready-file", l.ready.string()},
        l.out, l.err);
    reaper.pids.push_back(l.pid);
  }
  // Every reader exists before the first target is published.
  for (const Listener& l : listeners) {
    ASSERT_TRUE(test::eventually([&] { return std::filesystem::exists(l.ready); })) << l.topic;
  }

  const std::int64_t t0 = system_ns();
  // 3 s of targets at 1 kHz: every listener discovers ping and takes its samples meanwhile.
  const auto ping = test::run_cli(
      {"link", "ping", "--domain", domain, "--count", "3000", "--gripper", "--estop", "--json"});
  const std::int64_t t1 = system_ns();
  ASSERT_EQ(ping.exit_code, 0) << ping.err;
  EXPECT_TRUE(json::parse(ping.out)["estop_acknowledged"].get<bool>()) << ping.out;

  for (Listener& l : listeners) {
    const int rc = test::wait_process(l.pid, std::chrono::seconds(25));
    ASSERT_EQ(rc, 0) << l.topic << ": " << test::read_text(l.err);
    l.samples = json_lines(test::read_text(l.out));
    ASSERT_EQ(l.samples.size(), static_cast<std::size_t>(l.count)) << l.topic;
  }
  ::kill(echo, SIGTERM);
  ASSERT_EQ(test::wait_process(echo, std::chrono::seconds(10)), 0) << test::read_text(dir / "echo.err");

  // The stamp of every sample: within the ping's run, strictly increasing on each topic; one stamp
  // is one target index across topics (the echo keeps the target's stamp).
  std::map<std::int64_t, int> index_of_stamp;
  auto check_header = [&](const json& s, std::int64_t& last) {
    EXPECT_EQ(s["frame_id"], "microcobot_stage") << s;
    const auto sec = s["stamp"]["sec"].get<std::int64_t>();
    const auto nanosec = s["stamp"]["nanosec"].get<std::int64_t>();
    EXPECT_LT(nanosec, 1'000'000'000) << s;
    const std::int64_t stamp = sec * 1'000'000'000 + nanosec;
    EXPECT_GE(stamp, t0) << s;
    EXPECT_LE(stamp, t1) << s;
    EXPECT_GT(stamp, last) << s;
    last = stamp;
    return stamp;
  };

  for (const Listener& l : listeners) {
    std::int64_t last = 0;
    for (const json& s : l.samples) {
      EXPECT_EQ(s["topic"], l.topic);
      if (l.type == "pose") {
        EXPECT_EQ(s["type"], kPoseType);
        const std::int64_t stamp = check_header(s, last);
        const auto p = s["position"].get<std::vector<double>>();
        ASSERT_EQ(p.size(), 3u);
        const int i = target_index(p[0], p[1]);
        EXPECT_GE(i, 0) << "not one of ping's targets: " << s;
        EXPECT_EQ(p[2], 0.0) << s;
        EXPECT_EQ(s["orientation"], json::parse("[0, 0, 0, 1]")) << s;
        const auto it = index_of_stamp.emplace(stamp, i).first;
        EXPECT_EQ(it->second, i) << "the same stamp with another target: " << s;
      } else if (l.type == "joint") {
        EXPECT_EQ(s["type"], kJointType);
        check_header(s, last);
        EXPECT_EQ(s["name"], json::parse(R"(["gripper_opening"])")) << s;
        const auto q = s["position"].get<std::vector<double>>();
        ASSERT_EQ(q.size(), 1u) << s;
        EXPECT_TRUE(on_gripper_pattern(q[0])) << "not one of ping's gripper targets: " << s;
        EXPECT_TRUE(s["velocity"].empty()) << s;
        EXPECT_TRUE(s["effort"].empty()) << s;
      } else {
        EXPECT_EQ(s["type"], kBoolType);
        EXPECT_EQ(s["data"], true) << s;
      }
    }
  }
  // A gripper sample whose stamp is also a pose sample's: the opening of that same index.
  for (const Listener& l : listeners) {
    if (l.type != "joint") continue;
    for (const json& s : l.samples) {
      const std::int64_t stamp =
          s["stamp"]["sec"].get<std::int64_t>() * 1'000'000'000 + s["stamp"]["nanosec"].get<std::int64_t>();
      const auto it = index_of_stamp.find(stamp);
      if (it == index_of_stamp.end() || it->second < 0) continue;
      EXPECT_NEAR(s["position"][0].get<double>(), gripper_opening(it->second), kTol) << s;
    }
  }
}

// The slave of a distributed platform (`serve --role slave`) publishes its measurements and
// device states from the start, with or without a master: the listener reads them by their ROS 2
// names, with the values of a stage at rest (the gripper above the part, nothing touched).
TEST(WireCompat, TheListenerReadsTheSlavesForcesPoseAndDeviceStates) {
  TempDir dir;
  Reaper reaper;
  const std::string domain = std::to_string(net::test::test_domain_id());
  std::vector<Listener> listeners{{"/microcobot/slave/pose", "pose", 5},
                                  {"/microcobot/slave/contact_wrench", "wrench", 5},
                                  {"/microcobot/slave/grip_wrench", "wrench", 5},
                                  {"/diagnostics", "diag", 2},
                                  {"/microcobot/slave/port_energy", "vector3", 5}};
  for (std::size_t k = 0; k < listeners.size(); ++k) {
    Listener& l = listeners[k];
    const std::string n = std::to_string(k);
    l.out = dir / ("listener" + n + ".out");
    l.err = dir / ("listener" + n + ".err");
    l.pid = test::spawn_process({MC_ROS2_LISTENER_PATH, "--domain", domain, "--topic", l.topic, "--type",
                                 l.type, "--count", std::to_string(l.count), "--timeout", "40"},
                                l.out, l.err);
    reaper.pids.push_back(l.pid);
  }
  const pid_t slave =
      test::spawn_process({MC_CLI_PATH, "serve", "--role", "slave", "--domain", domain, "--listen",
                           "127.0.0.1:0", "--out", (dir / "slave").string(), "--duration", "60"},
                          dir / "slave.out", dir / "slave.err");
  reaper.pids.push_back(slave);
  for (Listener& l : listeners) {
    ASSERT_EQ(test::wait_process(l.pid, std::chrono::seconds(50)), 0)
        << l.topic << ": " << test::read_text(l.err);
    l.samples = json_lines(test::read_text(l.out));
    ASSERT_EQ(l.samples.size(), static_cast<std::size_t>(l.count)) << l.topic;
  }
  ::kill(slave, SIGTERM);
  EXPECT_EQ(test::wait_process(slave, std::chrono::seconds(30)), 0) << test::read_text(dir / "slave.err");

  for (const json& s : listeners[0].samples) {
    EXPECT_EQ(s["frame_id"], "microcobot_stage") << s;
    for (double x : s["position"].get<std::vector<double>>())
      EXPECT_LT(std::abs(x), 1e-6) << "at home: " << s;
  }
  for (const Listener& l : {listeners[1], listeners[2]}) {
    for (const json& s : l.samples) {
      EXPECT_EQ(s["type"], "geometry_msgs::msg::dds_::WrenchStamped_") << s;
      EXPECT_EQ(s["frame_id"], "microcobot_stage") << s;
      EXPECT_EQ(s["force"], json::parse("[0, 0, 0]")) << "nothing touched: " << s;
      EXPECT_EQ(s["torque"], json::parse("[0, 0, 0]")) << s;
    }
  }
  const char* devices[] = {"microcobot/slave/axis_x", "microcobot/slave/axis_y", "microcobot/slave/axis_z",
                           "microcobot/slave/gripper"};
  for (const json& s : listeners[3].samples) {
    EXPECT_EQ(s["type"], "diagnostic_msgs::msg::dds_::DiagnosticArray_") << s;
    ASSERT_EQ(s["status"].size(), 4u) << s;
    for (std::size_t i = 0; i < 4; ++i) {
      const json& st = s["status"][i];
      EXPECT_EQ(st["name"], devices[i]) << st;
      EXPECT_EQ(st["level"], 0) << "OK: " << st;
      EXPECT_EQ(st["message"], "active") << st;
      EXPECT_EQ(st["hardware_id"], "microcobot_slave") << st;
    }
  }
  for (const json& s : listeners[4].samples) {
    EXPECT_EQ(s["type"], "geometry_msgs::msg::dds_::Vector3Stamped_") << s;
    EXPECT_EQ(s["vector"], json::parse("[0, 0, 0]")) << "no master, no motion, no energy: " << s;
  }
}

// The slave's microscope camera as a ROS 2 image topic: the C program subscribes to
// /microcobot/slave/camera/image_raw/compressed by its ROS 2 name and type and decodes each
// JPEG itself (libjpeg-turbo): the sensor's size, an image that is neither black nor saturated,
// stamps at the camera's frame rate. The camera forms frames because this reader matched
// (nobody else looks at that server).
TEST(WireCompat, ACProgramReadsTheSlavesCameraImagesAndDecodesTheirJpeg) {
  TempDir dir;
  Reaper reaper;
  const std::string domain = std::to_string(net::test::test_domain_id());
  const pid_t listener = test::spawn_process(
      {MC_ROS2_LISTENER_PATH, "--domain", domain, "--topic", "/microcobot/slave/camera/image_raw/compressed",
       "--type", "image", "--count", "5", "--timeout", "40"},
      dir / "listener.out", dir / "listener.err");
  reaper.pids.push_back(listener);
  const pid_t slave =
      test::spawn_process({MC_CLI_PATH, "serve", "--role", "slave", "--domain", domain, "--listen",
                           "127.0.0.1:0", "--out", (dir / "slave").string(), "--duration", "60"},
                          dir / "slave.out", dir / "slave.err");
  reaper.pids.push_back(slave);
  ASSERT_EQ(test::wait_process(listener, std::chrono::seconds(50)), 0)
      << test::read_text(dir / "listener.err");
  ::kill(slave, SIGTERM);
  EXPECT_EQ(test::wait_process(slave, std::chrono::seconds(30)), 0) << test::read_text(dir / "slave.err");
  EXPECT_NE(test::read_text(dir / "slave.err").find("camera images on DDS"), std::string::npos);

  const std::vector<json> samples = json_lines(test::read_text(dir / "listener.out"));
  ASSERT_EQ(samples.size(), 5u);
  double last_s = -1.0;
  for (const json& s : samples) {
    EXPECT_EQ(s["type"], "sensor_msgs::msg::dds_::CompressedImage_") << s;
    EXPECT_EQ(s["frame_id"], "camera_optical_frame") << s;
    EXPECT_EQ(s["format"], "jpeg") << s;
    ASSERT_TRUE(s["jpeg"].is_object()) << "the JPEG decodes: " << s;
    EXPECT_EQ(s["jpeg"]["width"], 1280) << s;  // the default sensor (e2v EV76C560)
    EXPECT_EQ(s["jpeg"]["height"], 1024) << s;
    EXPECT_GT(s["jpeg"]["mean"].get<double>(), 5.0) << "not black: " << s;
    EXPECT_LT(s["jpeg"]["mean"].get<double>(), 250.0) << "not saturated: " << s;
    const double t_s = s["stamp"]["sec"].get<double>() + 1e-9 * s["stamp"]["nanosec"].get<double>();
    if (last_s >= 0.0) {
      // Frames at 30 fps in loop time; best effort may lose one now and then, never reorder.
      const double frames = (t_s - last_s) * 30.0;
      EXPECT_NEAR(frames, std::round(frames), 0.05) << s;
      EXPECT_GE(std::round(frames), 1.0) << s;
    }
    last_s = t_s;
  }
}

// The frames as any tf2 listener reads them: a plain C program built from ROS 2's IDL takes /tf
// (tf2_msgs/msg/TFMessage) from a real `serve --role slave`: the tree of live/robot_frames.h, unit
// quaternions, every transform of a message stamped alike, stamps moving on in loop time.
TEST(WireCompat, ACProgramReadsTheSlavesFramesOnTf) {
  TempDir dir;
  Reaper reaper;
  const std::string domain = std::to_string(net::test::test_domain_id());
  const pid_t listener = test::spawn_process({MC_ROS2_LISTENER_PATH, "--domain", domain, "--topic", "/tf",
                                              "--type", "tf", "--count", "10", "--timeout", "40"},
                                             dir / "listener.out", dir / "listener.err");
  reaper.pids.push_back(listener);
  const pid_t slave =
      test::spawn_process({MC_CLI_PATH, "serve", "--role", "slave", "--domain", domain, "--listen",
                           "127.0.0.1:0", "--out", (dir / "slave").string(), "--duration", "60"},
                          dir / "slave.out", dir / "slave.err");
  reaper.pids.push_back(slave);
  ASSERT_EQ(test::wait_process(listener, std::chrono::seconds(50)), 0)
      << test::read_text(dir / "listener.err");
  ::kill(slave, SIGTERM);
  EXPECT_EQ(test::wait_process(slave, std::chrono::seconds(30)), 0) << test::read_text(dir / "slave.err");
  EXPECT_NE(test::read_text(dir / "slave.err").find("ROS 2 topic /tf"), std::string::npos);
  // Without a parallel positioner no pose of it is published.
  EXPECT_EQ(test::read_text(dir / "slave.err").find("/microcobot/slave/positioner/pose"), std::string::npos);

  const std::vector<json> samples = json_lines(test::read_text(dir / "listener.out"));
  ASSERT_EQ(samples.size(), 10u);
  double last_s = -1.0;
  for (const json& m : samples) {
    EXPECT_EQ(m["type"], "tf2_msgs::msg::dds_::TFMessage_") << m;
    std::map<std::string, std::string> parent;
    ASSERT_EQ(m["transforms"].size(), 5u) << "tool, gripper, two fingers and the simulated part: " << m;
    const json& first = m["transforms"][0]["stamp"];
    for (const json& t : m["transforms"]) {
      parent[t["child"].get<std::string>()] = t["parent"].get<std::string>();
      EXPECT_EQ(t["stamp"], first) << "one sample, one stamp: " << m;
      const auto q = t["rotation"].get<std::vector<double>>();
      EXPECT_NEAR(std::hypot(std::hypot(q[0], q[1]), std::hypot(q[2], q[3])), 1.0, 1e-12) << t;
    }
    EXPECT_EQ(parent["tool"], "world");
    EXPECT_EQ(parent["gripper"], "tool");
    EXPECT_EQ(parent["finger_left"], "gripper");
    EXPECT_EQ(parent["finger_right"], "gripper");
    EXPECT_EQ(parent["part"], "world");
    const double t_s = first["sec"].get<double>() + 1e-9 * first["nanosec"].get<double>();
    EXPECT_GT(t_s, last_s) << m;
    last_s = t_s;
  }
}

// The microscope as any ROS 2 node sets it: a plain C program publishes a
// latched JointState command (focus 150 um, objective 2) to a real `serve --role slave`; the C
// listener then reads the slave's state topic: the drive went there and the turret turned.
TEST(WireCompat, ACProgramSetsTheSlavesMicroscopeAndReadsItsState) {
  TempDir dir;
  Reaper reaper;
  const std::string domain = std::to_string(net::test::test_domain_id());
  const pid_t slave =
      test::spawn_process({MC_CLI_PATH, "serve", "--role", "slave", "--domain", domain, "--listen",
                           "127.0.0.1:0", "--out", (dir / "slave").string(), "--duration", "60"},
                          dir / "slave.out", dir / "slave.err");
  reaper.pids.push_back(slave);
  const pid_t talker = test::spawn_process(
      {MC_ROS2_TALKER_PATH, "--domain", domain, "--topic", "/microcobot/slave/microscope/command", "--joint",
       "focus_z=0.00015", "--joint", "objective_turret=2", "--timeout", "40"},
      dir / "talker.out", dir / "talker.err");
  reaper.pids.push_back(talker);
  ASSERT_EQ(test::wait_process(talker, std::chrono::seconds(50)), 0)
      << test::read_text(dir / "talker.err") << test::read_text(dir / "slave.err");
  const pid_t listener = test::spawn_process(
      {MC_ROS2_LISTENER_PATH, "--domain", domain, "--topic", "/microcobot/slave/microscope/state", "--type",
       "joint", "--count", "20", "--timeout", "30"},
      dir / "listener.out", dir / "listener.err");
  reaper.pids.push_back(listener);
  ASSERT_EQ(test::wait_process(listener, std::chrono::seconds(40)), 0)
      << test::read_text(dir / "listener.err");
  ::kill(slave, SIGTERM);
  EXPECT_EQ(test::wait_process(slave, std::chrono::seconds(30)), 0) << test::read_text(dir / "slave.err");
  EXPECT_NE(test::read_text(dir / "slave.err").find("/microcobot/slave/microscope/command"),
            std::string::npos);

  const std::vector<json> samples = json_lines(test::read_text(dir / "listener.out"));
  ASSERT_EQ(samples.size(), 20u);
  for (const json& s : samples) {
    EXPECT_EQ(s["type"], kJointType) << s;
    EXPECT_EQ(s["name"], json({"focus_z", "objective_turret"})) << s;
  }
  // The drive moves at 1 mm/s: 150 um in 0.15 s, long before the last of 2 s of states.
  const json& last = samples.back();
  EXPECT_NEAR(last["position"][0].get<double>(), 150e-6, 1e-12) << last;
  EXPECT_EQ(last["position"][1].get<double>(), 2.0) << last;
}

TEST(WireCompat, TheListenerTimesOutWithOneLine) {
  // This test's own domain, nothing published on it.
  TempDir dir;
  const pid_t pid =
      test::spawn_process({MC_ROS2_LISTENER_PATH, "--domain", std::to_string(net::test::test_domain_id()),
                           "--topic", "/microcobot/slave/pose", "--type", "pose", "--timeout", "0.5"},
                          dir / "out", dir / "err");
  EXPECT_EQ(test::wait_process(pid, std::chrono::seconds(20)), 1);
  const std::string err = test::read_text(dir / "err");
  EXPECT_EQ(test::line_count(err), 1u) << err;
  EXPECT_NE(err.find("0 of 1 samples on rt/microcobot/slave/pose"), std::string::npos) << err;
  EXPECT_TRUE(test::read_text(dir / "out").empty());
}

}  // namespace
}  // namespace mc
