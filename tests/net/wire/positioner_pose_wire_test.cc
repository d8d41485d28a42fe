// The parallel positioner as any ROS 2 node reads it: a real `serve --role slave` with
// `positioner: parallel` (its pose only the legs' sensors move: a slave's twin takes no moves, its
// master drives), and the plain C listener built from ROS 2's IDL takes
// /microcobot/slave/positioner/pose (geometry_msgs/msg/PoseStamped) and /tf once the legs have
// settled at home after power-up. The pose is the one the platform reports through its PI C-887
// twin's GCS port (`--emulate gcs2-hexapod`, POS?: a query takes no control), at the home pose, in
// the positioner's home frame (/tf's `world`), at a state topic's 1 kHz, stamped with ROS time; /tf's
// `world -> positioner` agrees. The quaternion's formula away from the identity is
// RobotFrames.TheParallelPositionersPoseIsItsZyxRotationAsAQuaternion's (the same transforms()).

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>
#include <algorithm>

#include <array>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "microcobot/drivers/gcs2_codec.h"
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
constexpr double kRadPerDeg = std::numbers::pi / 180.0;

// A GCS 2.0 client on the twin's port: a query sent, its reply read whole.
class GcsClient {
 public:
  explicit GcsClient(std::uint16_t port) : fd_(::socket(AF_INET, SOCK_STREAM, 0)) {
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(port);
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    connected_ = ::connect(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
    timeval tv{5, 0};
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  }
  ~GcsClient() { ::close(fd_); }
  GcsClient(const GcsClient&) = delete;
  GcsClient& operator=(const GcsClient&) = delete;
  bool connected() const { return connected_; }
  // Sends `line`; a query (ending in '?') returns its reply, a command "".
  std::string ask(const std::string& line) {
    const std::string l = line + "\n";
    ::send(fd_, l.data(), l.size(), MSG_NOSIGNAL);
    std::string text;
    if (line.back() != '?' && line.find("? ") == std::string::npos) return text;
    char buf[1024];
    while (!drivers::gcs2::reply_complete(text)) {
      const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
      if (n <= 0) break;
      text.append(buf, static_cast<std::size_t>(n));
    }
    return text;
  }
  // X, Y, Z [mm], U, V, W [deg] of POS?.
  std::array<double, 6> position() {
    std::array<double, 6> p{};
    p.fill(std::nan(""));
    const auto v = drivers::gcs2::parse_axis_values(ask("POS? X Y Z U V W"));
    for (std::size_t i = 0; i < 6 && v.size() == 6; ++i) p[i] = v[i].second;
    return p;
  }

 private:
  int fd_;
  bool connected_ = false;
};

std::int64_t stamp_ns(const json& m) {
  return m["stamp"]["sec"].get<std::int64_t>() * 1000000000 + m["stamp"]["nanosec"].get<std::int64_t>();
}

// q = qz(rz) qy(ry) qx(rx), as x, y, z, w.
std::array<double, 4> zyx_quaternion(double rx, double ry, double rz) {
  const double cx = std::cos(0.5 * rx), sx = std::sin(0.5 * rx), cy = std::cos(0.5 * ry),
               sy = std::sin(0.5 * ry), cz = std::cos(0.5 * rz), sz = std::sin(0.5 * rz);
  return {cz * cy * sx - sz * sy * cx, cz * sy * cx + sz * cy * sx, sz * cy * cx - cz * sy * sx,
          cz * cy * cx + sz * sy * sx};
}

TEST(WireCompat, ACProgramReadsTheParallelPositionersPoseAtHome) {
  TempDir dir;
  Reaper reaper;
  const std::string domain = std::to_string(net::test::test_domain_id());
  test::write_text(dir / "parallel.yaml", "positioner: parallel\n");
  const pid_t slave =
      test::spawn_process({MC_CLI_PATH, "serve", "--role", "slave", "--domain", domain, "--listen",
                           "127.0.0.1:0", "--out", (dir / "slave").string(), "--duration", "90", "--config",
                           (dir / "parallel.yaml").string(), "--emulate", "gcs2-hexapod=127.0.0.1:0"},
                          dir / "slave.out", dir / "slave.err");
  reaper.pids.push_back(slave);
  std::uint16_t port = 0;
  ASSERT_TRUE(test::eventually(
      [&] {
        std::smatch m;
        const std::string out = test::read_text(dir / "slave.out");
        if (!std::regex_search(out, m, std::regex(R"(emulate gcs2-hexapod 127\.0\.0\.1:(\d+))")))
          return false;
        port = static_cast<std::uint16_t>(std::stoi(m[1]));
        return true;
      },
      std::chrono::seconds(60)))
      << test::read_text(dir / "slave.err");

  // Settled: two readings of POS? 0.2 s apart within a nanometre and a microdegree.
  GcsClient gcs(port);
  ASSERT_TRUE(gcs.connected());
  std::array<double, 6> before = gcs.position();
  ASSERT_TRUE(test::eventually(
      [&] {
        std::this_thread::sleep_for(std::chrono::milliseconds(200));
        const std::array<double, 6> now = gcs.position();
        bool still = true;
        for (std::size_t i = 0; i < 6; ++i) still = still && std::abs(now[i] - before[i]) <= 1e-6;
        before = now;
        return still;
      },
      std::chrono::seconds(30)));

  constexpr int kPoses = 300;
  const std::int64_t t0 = system_ns();
  const pid_t poses = test::spawn_process(
      {MC_ROS2_LISTENER_PATH, "--domain", domain, "--topic", "/microcobot/slave/positioner/pose", "--type",
       "pose", "--count", std::to_string(kPoses), "--timeout", "40"},
      dir / "poses.out", dir / "poses.err");
  reaper.pids.push_back(poses);
  const pid_t frames = test::spawn_process({MC_ROS2_LISTENER_PATH, "--domain", domain, "--topic", "/tf",
                                            "--type", "tf", "--count", "10", "--timeout", "40"},
                                           dir / "frames.out", dir / "frames.err");
  reaper.pids.push_back(frames);
  ASSERT_EQ(test::wait_process(poses, std::chrono::seconds(50)), 0)
      << test::read_text(dir / "poses.err") << test::read_text(dir / "slave.err");
  ASSERT_EQ(test::wait_process(frames, std::chrono::seconds(50)), 0) << test::read_text(dir / "frames.err");
  const std::int64_t t1 = system_ns();
  const std::array<double, 6> pos = gcs.position();  // the platform's measured pose, mm and deg
  ::kill(slave, SIGTERM);
  EXPECT_EQ(test::wait_process(slave, std::chrono::seconds(30)), 0) << test::read_text(dir / "slave.err");
  EXPECT_NE(test::read_text(dir / "slave.err").find("ROS 2 topic /microcobot/slave/positioner/pose"),
            std::string::npos);

  // Home: the base's origin to a tenth of a micrometre, no turn to a tenth of a millidegree.
  for (std::size_t i = 0; i < 6; ++i) ASSERT_NEAR(pos[i], 0.0, 1e-4) << i;
  const std::array<double, 3> p_m{1e-3 * pos[0], 1e-3 * pos[1], 1e-3 * pos[2]};
  const std::array<double, 4> q =
      zyx_quaternion(kRadPerDeg * pos[3], kRadPerDeg * pos[4], kRadPerDeg * pos[5]);

  const std::vector<json> samples = json_lines(test::read_text(dir / "poses.out"));
  ASSERT_EQ(samples.size(), static_cast<std::size_t>(kPoses));
  std::int64_t last_ns = 0;
  for (const json& m : samples) {
    EXPECT_EQ(m["type"], kPoseType) << m;
    EXPECT_EQ(m["frame_id"], "world") << m;  // /tf's frame of `world -> positioner`
    const std::int64_t ns = stamp_ns(m);
    EXPECT_GE(ns, t0) << m;
    EXPECT_LE(ns, t1) << m;
    EXPECT_GE(ns, last_ns) << m;
    last_ns = ns;
    // At rest at the pose POS? reports, to the legs' sensors' noise (POS? is one reading of it).
    const auto p = m["position"].get<std::vector<double>>();
    const auto o = m["orientation"].get<std::vector<double>>();
    for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(p[i], p_m[i], 50e-9) << i << " " << m;
    for (std::size_t i = 0; i < 4; ++i) EXPECT_NEAR(o[i], q[i], 3e-7) << i << " " << m;
    EXPECT_NEAR(std::hypot(std::hypot(o[0], o[1]), std::hypot(o[2], o[3])), 1.0, 1e-12) << m;
  }
  // Every loop sample's pose (1 ms apart), not the console's 60 Hz (17 ms apart): the median gap
  // between two stamps, which a late loop's few long gaps (a sanitizer, a loaded machine) and the
  // listener's few losses leave in place.
  std::vector<double> gaps_s;
  for (std::size_t i = 1; i < samples.size(); ++i)
    gaps_s.push_back(1e-9 * static_cast<double>(stamp_ns(samples[i]) - stamp_ns(samples[i - 1])));
  std::nth_element(gaps_s.begin(), gaps_s.begin() + static_cast<std::ptrdiff_t>(gaps_s.size() / 2),
                   gaps_s.end());
  EXPECT_LT(gaps_s[gaps_s.size() / 2], 8e-3) << "the poses come at the console's rate, not the loop's";

  // /tf's `world -> positioner` is the same pose.
  int seen = 0;
  for (const json& m : json_lines(test::read_text(dir / "frames.out"))) {
    for (const json& t : m["transforms"]) {
      if (t["child"] != "positioner") continue;
      ++seen;
      EXPECT_EQ(t["parent"], "world") << t;
      for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(t["translation"][i].get<double>(), p_m[i], 50e-9) << t;
      for (std::size_t i = 0; i < 4; ++i) EXPECT_NEAR(t["rotation"][i].get<double>(), q[i], 3e-7) << t;
    }
  }
  EXPECT_EQ(seen, 10);
}

}  // namespace
}  // namespace mc
