#pragma once
/// @file
/// The pi-gcs2 driver's test rig, shared by vendor_driver_test.cc (TCP) and
/// serial_line_test.cc (a pseudo-terminal): an E-873-like scriptable controller, the platform's
/// configuration for it, a console holding control, and the loop run at wall-clock pace.

#include <Eigen/Core>

#include <atomic>
#include <chrono>
#include <mutex>
#include <string>
#include <thread>

#include <fmt/format.h>

#include "drivers/fake_controller.h"
#include "microcobot/drivers/gcs2_codec.h"
#include "microcobot/drivers/register_drivers.h"
#include "microcobot/platform/driver_registry.h"

namespace mc::drivers::gcs2_test_rig {

using Clock = std::chrono::steady_clock;
using platform::Platform;
using platform::PlatformConfig;

enum class Mode { kNormal, kSlow, kTruncated, kGarbage, kDisconnect, kError };

// An E-873-like controller whose axes reach every MOV at once.
struct FakeGcs2 {
  std::atomic<Mode> mode{Mode::kNormal};
  std::string axes_reply = "1 \n2 \n3\n";
  std::mutex m;
  double pos_mm[3] = {0, 0, 0};
  int error = 0;
  std::atomic<int> halts{0};
  test::FakeController server;

  explicit FakeGcs2(test::FakeController::Transport transport = test::FakeController::Transport::kTcp)
      : server([this](const std::string& line) { return answer(line); }, {}, transport) {}

  test::FakeController::Answer answer(const std::string& line) {
    std::lock_guard lock(m);
    const auto r = gcs2::parse_line(line);
    if (!r) return {};
    const std::string& c = r->mnemonic;
    auto per_axis = [&](auto value) {
      std::string out;
      for (int i = 0; i < 3; ++i) out += fmt::format("{}={}{}", i + 1, value(i), i < 2 ? " \n" : "\n");
      return out;
    };
    if (c == "*IDN?") return {"(c)2026 Physik Instrumente (PI) fake E-873\n"};
    if (c == "CSV?") return {"2.0\n"};
    if (c == "SAI?") return {axes_reply};
    if (c == "ERR?") {
      const int e = error;
      error = 0;
      return {fmt::format("{}\n", e)};
    }
    if (c == "TMN?") return {per_axis([](int) { return "-5.000000"; })};
    if (c == "TMX?") return {per_axis([](int) { return "5.000000"; })};
    if (c == "FRF?") return {per_axis([](int) { return 1; })};
    if (c == "VEL?") return {per_axis([](int) { return "1.000000"; })};
    if (c == "HLT") {
      ++halts;
      error = 10;
      return {};
    }
    if (c == "MOV") {
      for (std::size_t k = 0; k + 1 < r->args.size(); k += 2)
        pos_mm[r->args[k][0] - '1'] = *gcs2::parse_number(r->args[k + 1]);
      if (mode == Mode::kError) error = gcs2::kPositionOutOfLimits;
      return {};
    }
    if (c == "POS?") {
      switch (mode.load()) {
        case Mode::kSlow:
          return {};  // never answered
        case Mode::kTruncated:
          return {"1=0.000000 \n2=0.0"};  // the rest never comes
        case Mode::kGarbage:
          return {"\x01\x7f@@ garbage\n"};
        case Mode::kDisconnect:
          return {"", true};
        default:
          return {per_axis([this](int i) { return fmt::format("{:.6f}", pos_mm[i]); })};
      }
    }
    return {};  // SVO, VEL, FRF: set commands have no reply
  }
  double x_mm(int i) {
    std::lock_guard lock(m);
    return pos_mm[i];
  }
};

inline PlatformConfig gcs2_config(std::uint16_t port, const std::string& options = "") {
  register_vendor_drivers();
  PlatformConfig c;
  c.devices.driver = "pi-gcs2";
  c.devices.connection = fmt::format("127.0.0.1:{}{}", port, options);
  return c;
}

// The console holding control with its deadman, going to `goal` (stage coordinates).
struct Console {
  teleop::ConsoleInput in;
  Eigen::Vector3d home;
  explicit Console(Platform& p, const Eigen::Vector3d& goal) {
    const auto& s = p.config().stage;
    home = {s.home_x_m, s.home_y_m, s.home_z_m};
    in.active = in.fresh = in.deadman = true;
    in.has_goal = true;
    in.goal_m = home + goal;
    in.goal_speed_m_s = 1e-3;
    p.set_operator([this, &p](const runtime::TickInfo&) { p.set_console_input(in); });
  }
};

// The loop at wall-clock pace (10 ticks a millisecond) on this thread, until `done` or `s`.
template <class Done>
double run_paced(Platform& p, double s, Done done) {
  const auto start = Clock::now();
  for (int ms = 0; ms < static_cast<int>(s * 1e3); ++ms) {
    p.loop().run_for(10);
    if (done()) break;
    std::this_thread::sleep_until(start + std::chrono::milliseconds(ms + 1));
  }
  return std::chrono::duration<double>(Clock::now() - start).count();
}
inline double run_paced(Platform& p, double s) {
  return run_paced(p, s, [] { return false; });
}

}  // namespace mc::drivers::gcs2_test_rig
