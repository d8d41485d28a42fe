#pragma once
/// @file
/// The `pi-gcs2` driver: the platform's three stage axes on a PI controller speaking
/// GCS 2.0 over TCP (E-873 Q-Motion, E-871, C-867; or `microcobot serve --emulate gcs2`). The
/// controller closes each axis' position loop: the axes are position-controlled
/// (devices/device.h), the platform sends them the coupling's targets, the bus thread sends the
/// latest as `MOV` and polls `POS?` (bus_controller.h). Commands (docs/hardware.md, "Drivers"):
///
///   configure  *IDN?, CSV? (2.x), SAI? ALL (every configured axis listed, else an error naming
///              what was found), ERR? (a stale error cleared), TMN?/TMX? (the targets are clamped
///              to them), SVO a 1 ..., [VEL a v ...], FRF? and, for an unreferenced axis, FRF then
///              FRF? until referenced; ERR? after every set command (non-zero: the configuration
///              fails naming the code and its text), POS? (the first positions)
///   each cycle MOV a x ... of the targets that changed (then ERR?, which must read 0), POS?
///   safe state HLT, ERR? (0 or 10, "stopped by command")
///
/// Positions are in mm on the wire (%.6f: 1 nm), m in the platform; the controller's zero is the
/// platform's stage zero (its home).
///
/// The rotary axis under the gripper, with the option `theta=ID`: the
/// controller's rotation stage ID, checked at configure (listed by SAI?, PUN? `deg`, its TMN?..TMX?
/// holding 0), referenced, moved and polled with the three: deg on the wire (%.6f: 1 udeg), the
/// platform's rotary axis position (the arc at stage.rotary.radius_m from its home) in the platform.

#include <array>
#include <memory>
#include <string>

#include "microcobot/devices/device_set.h"
#include "microcobot/drivers/bus_controller.h"
#include "microcobot/platform/platform_config.h"

namespace mc::drivers {

/// The serial rate of a PI GCS 2.0 controller out of the box (E-873/C-867: RS-232 and USB at
/// 115200 baud, 8N1, per PI's manuals); `baud=` overrides it.
inline constexpr int kGcs2DefaultBaud = 115200;

struct Gcs2DriverParams {
  BusTiming timing;
  std::array<std::string, 3> axes = {"1", "2", "3"};  ///< the controller's axis ids for X, Y, Z
  std::string theta;                  ///< the controller's axis id of the rotary axis (deg); empty: none
  double radius_m = 5e-3;             ///< the rotary axis' contact radius: its arc [m] per rad
  bool reference = true;              ///< FRF the axes that FRF? reports unreferenced (else refuse them)
  double reference_timeout_s = 60.0;  ///< FRF's longest wait (a switch search on a long stage)
  double velocity_mm_s = 0.0;         ///< VEL sent at configure; 0 keeps the controller's
  /// The operator's fastest stage move (the platform's teleop.max_jog_m_s, in mm/s): an axis
  /// whose VEL? is slower lags the coupling's target, and a warning says so at configure.
  double operator_speed_mm_s = 0.0;
  void validate() const;
};

/// `connection` options: timeout_s, connect_timeout_s, poll_s, stale_s, axes (three ids joined by
/// '+', "1+2+3"), theta (the rotation stage's id), reference (0|1), reference_timeout_s,
/// velocity_mm_s.
Gcs2DriverParams gcs2_driver_params(const Connection& connection);

class Gcs2Controller final : public BusController {
 public:
  Gcs2Controller(Connection connection, Gcs2DriverParams params);
  ~Gcs2Controller() override { shutdown(); }
  const Gcs2DriverParams& params() const { return params_; }
  /// X, Y, Z, and the rotary axis with the option theta.
  int axis_count() const { return params_.theta.empty() ? 3 : 4; }
  /// TMN?/TMX? read at configure [m; the rotary axis: m of arc].
  double min_m(int axis) const { return min_m_[static_cast<std::size_t>(axis)]; }
  double max_m(int axis) const { return max_m_[static_cast<std::size_t>(axis)]; }
  /// MOV lines sent (tests, benchmarks).
  std::uint64_t moves_sent() const { return moves_.load(std::memory_order_relaxed); }

 protected:
  void handshake(LineClient& bus) override;
  void cycle(LineClient& bus) override;
  void safe_state(LineClient& bus) override;

 private:
  /// Sends `line` and returns its reply (queries) within the reply timeout. Throws BusFault.
  std::string query(LineClient& bus, const std::string& line, double timeout_s = 0.0);
  /// Sends a set command, then ERR?: throws BusFault naming the code unless it is 0 (or `also_ok`).
  void command(LineClient& bus, const std::string& line, int also_ok = 0);
  /// The reply of `mnemonic` on every axis, each in its unit on the wire (mm, deg).
  std::array<double, kMaxAxes> read_axes(LineClient& bus, const std::string& mnemonic);
  std::string axis_list() const;
  const std::string& axis_id(std::size_t i) const { return i < 3 ? params_.axes[i] : params_.theta; }
  /// The platform's unit (m; the rotary axis: m of arc) per the wire's (mm; deg).
  double si_per_wire(std::size_t i) const;

  Gcs2DriverParams params_;
  std::array<double, kMaxAxes> min_m_{}, max_m_{}, sent_m_{};
  std::array<bool, kMaxAxes> sent_{};
  std::atomic<std::uint64_t> moves_{0};
};

/// The driver set `pi-gcs2`: the three axes (and the rotary axis, option theta, when the
/// configuration has one: stage.rotary.enabled) on one Gcs2Controller (`config.devices.connection`),
/// the gripper and the masters simulated (drivers/sim_companions.h). Builds, opens nothing.
devices::DeviceSet make_gcs2_devices(const platform::PlatformConfig& config);

}  // namespace mc::drivers
