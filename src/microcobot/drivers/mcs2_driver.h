#pragma once
/// @file
/// The `smaract-mcs2` driver: the platform's three stage axes on a SmarAct MCS2 over its ASCII
/// interface (TCP port 55551; or `microcobot serve --emulate mcs2`). The controller closes each
/// channel's position loop: the axes are position-controlled (devices/device.h), the platform
/// sends them the coupling's targets, the bus thread sends the latest as `:MOVE<n>` (absolute,
/// pm) and polls `:CHAN<n>:POS?` (bus_controller.h). Commands (docs/hardware.md, "smaract-mcs2"):
///
///   configure  *IDN? (must name an MCS2), the stale error queue drained, :DEV:NOCH? (every
///              configured channel present), per channel :CHAN<n>:STAT? (sensor present, else below),
///              :CHAN<n>:TUN:BASE:UNIT? (metre; the rotary channel degree), RLIM:MIN?/MAX? (the
///              targets are clamped to them), MMOD 0, HOLD -1, [VEL v], VEL?, and for an
///              unreferenced channel :REF<n> then STAT? until referenced; the error queue read
///              after the set commands (an error fails the configuration with its text); POS?
///   each cycle :MOVE<n> <pm> of the targets that changed, then the queries:
///              :SYST:ERR:COUN? (must read 0, else :SYST:ERR:NEXT? names the error) and each
///              channel's :CHAN<n>:POS?
///   safe state :STOP<n> on every channel, then :SYST:ERR:COUN? (the stops were read)
///
/// Every command is a line of its own (CR LF), nothing is assumed about several commands on one
/// line; the set commands go out in one write with the query that follows them, and each query is
/// a round trip: a cycle is 1 + one per channel. Positions are in pm on the wire (64-bit integers), m in the
/// platform; the controller's 0 (the reference mark) is the platform's stage zero (its home).
///
/// A channel without sensor (:CHAN<n>:STAT? without 0x20) is refused unless the option
/// `sensorless=step` is given; then its axis is an open-loop stepped axis as the anc300 driver's
/// (drivers/step_drive.h): its position counted (the periods sent times the model's step, from 0 at
/// the first configure), moved by runs of steps toward the target: at configure MMOD 4 (step mode),
/// STEP:FREQ, STEP:AMPL (no reference, VEL, HOLD or RLIM: they need the sensor); each cycle, once
/// the previous run is over (its periods' time gone and :CHAN<n>:STAT? without 0x1, the channel's
/// poll instead of POS?), :MOVE<n> <periods> (signed); the safe state's :STOP<n> as the others'.
///
/// The rotary axis under the gripper, with the option `theta=N`: the controller's rotary channel
/// N (base unit degree, positions in ndeg), checked, referenced, moved and polled with the three;
/// the platform's rotary axis position (the arc at stage.rotary.radius_m from its home) in the
/// platform.

#include <array>
#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "microcobot/devices/device_set.h"
#include "microcobot/drivers/bus_controller.h"
#include "microcobot/drivers/step_drive.h"
#include "microcobot/platform/platform_config.h"

namespace mc::drivers {

/// The largest channel index an MCS2 has (its 8 modules of 3 channels: 0..23).
inline constexpr int kMcs2MaxChannel = 23;

struct Mcs2DriverParams {
  BusTiming timing;
  std::array<int, 3> channels = {0, 1, 2};  ///< the controller's channels for X, Y, Z
  int theta = -1;                           ///< the rotary channel; -1: none
  double radius_m = 5e-3;                   ///< the rotary axis' contact radius: its arc [m] per rad
  bool reference = true;                    ///< :REF the unreferenced channels (else refuse them)
  double reference_timeout_s = 60.0;        ///< the reference's longest wait (a mark search)
  double velocity_mm_s = 0.0;               ///< VEL sent to X, Y, Z at configure; 0 keeps the controller's
  /// The operator's fastest stage move (teleop.max_jog_m_s, in mm/s): a channel whose VEL? is
  /// slower (and not 0, "as fast as allowed") lags the coupling's target: a warning at configure.
  double operator_speed_mm_s = 0.0;
  /// sensorless=step: a channel without sensor is stepped open loop, its position counted; else
  /// (sensorless=refuse) it is refused at configure.
  bool sensorless_step = false;
  /// The stepped channels' STEP:AMPL (voltage_V of 100 V full scale), STEP:FREQ, runs and step.
  StepDriveParams step;
  /// With sensorless_step the steps must be known (given, or from the model: make_mcs2_devices).
  void validate() const;
};

/// `connection` options: timeout_s, connect_timeout_s, poll_s, stale_s, channels (three indices
/// joined by '+', "0+1+2"), theta (the rotary channel), reference (auto|require),
/// reference_timeout_s, velocity_mm_s, sensorless (refuse|step) and, with sensorless=step only,
/// voltage_V, frequency_Hz, max_run_s, step_up_nm, step_down_nm, deadband_nm (step_drive.h).
Mcs2DriverParams mcs2_driver_params(const Connection& connection);

class Mcs2Controller final : public BusController {
 public:
  Mcs2Controller(Connection connection, Mcs2DriverParams params);
  ~Mcs2Controller() override { shutdown(); }
  const Mcs2DriverParams& params() const { return params_; }
  /// X, Y, Z, and the rotary axis with the option theta.
  int axis_count() const { return params_.theta < 0 ? 3 : 4; }
  /// RLIM:MIN?/MAX? read at configure [m; the rotary axis: m of arc]; +-inf when the controller
  /// has no range limit (both 0).
  double min_m(int axis) const { return min_m_[static_cast<std::size_t>(axis)]; }
  double max_m(int axis) const { return max_m_[static_cast<std::size_t>(axis)]; }
  /// Cycles that sent at least one :MOVE (tests, benchmarks).
  std::uint64_t moves_sent() const { return moves_.load(std::memory_order_relaxed); }
  /// True for an axis whose channel has no sensor (stepped open loop), once configured.
  bool stepped(int axis) const { return stepped_[static_cast<std::size_t>(axis)]; }
  /// Periods commanded since the start on a stepped axis, signed (tests).
  long long periods_sent(int axis) const { return periods_[static_cast<std::size_t>(axis)].load(); }

 protected:
  void handshake(LineClient& bus) override;
  void cycle(LineClient& bus) override;
  void safe_state(LineClient& bus) override;

 private:
  /// Sends `lines` in order, each ended by CR LF: the set commands before a query in one write
  /// with it, then the query's one reply line read before the next is sent (a round trip per
  /// query, one reply per request, as the controller's documented clients do), all within the
  /// reply timeout (or `timeout_s`). The replies in order. Throws BusFault naming the command on a
  /// timeout or a lost connection.
  std::vector<std::string> exchange(LineClient& bus, const std::vector<std::string>& lines,
                                    double timeout_s = 0.0);
  std::string query(LineClient& bus, const std::string& line, double timeout_s = 0.0);
  /// A query whose reply must be one integer; throws BusFault naming it and the reply otherwise.
  std::int64_t query_integer(LineClient& bus, const std::string& line);
  /// `count`, the reply of :SYST:ERR:COUN?: throws BusFault with the oldest error's code and text
  /// (:SYST:ERR:NEXT?) unless it is 0. `after` says what was sent before.
  void check_errors(LineClient& bus, std::int64_t count, const std::string& after);
  /// Sends `lines` (set commands, or none), then :SYST:ERR:COUN? (check_errors) and each
  /// channel's :CHAN<n>:POS?, and publishes the positions.
  void poll(LineClient& bus, std::vector<std::string> lines);
  /// Sends set commands, then :SYST:ERR:COUN? (check_errors; an error is said to follow the first
  /// line, or `after` when there is none).
  void command(LineClient& bus, const std::vector<std::string>& lines, const std::string& after = {});
  int channel(std::size_t i) const { return i < 3 ? params_.channels[i] : params_.theta; }
  std::string channel_list() const;
  /// The platform's unit (m; the rotary axis: m of arc) per the wire's (pm; ndeg).
  double si_per_wire(std::size_t i) const;
  /// A stepped axis' run toward its target, once the previous one is over: its :MOVE, if any.
  void step_toward(std::size_t i, double target_m, std::vector<std::string>& moves);
  /// Adds to the count what the run under way played: all of it once over, else (a stop) the
  /// periods its time allowed.
  void count_run(std::size_t i, bool stopped);

  Mcs2DriverParams params_;
  std::array<double, kMaxAxes> min_m_{}, max_m_{}, sent_m_{};
  std::array<bool, kMaxAxes> sent_{};
  std::vector<std::string> poll_lines_;  ///< the cycle's queries, built once at configure
  std::atomic<std::uint64_t> moves_{0};
  // Stepped axes (bus thread): the counted position, the run under way (signed periods) and when
  // it started.
  std::array<bool, kMaxAxes> stepped_{};
  std::array<double, kMaxAxes> est_m_{};
  std::array<long long, kMaxAxes> run_{};
  std::array<bool, kMaxAxes> run_seen_moving_{};
  std::array<Clock::time_point, kMaxAxes> run_start_{};
  std::array<std::atomic<long long>, kMaxAxes> periods_{};
};

/// The driver set `smaract-mcs2`: the three axes (and the rotary axis, option theta, which needs
/// stage.rotary.enabled) on one Mcs2Controller (`config.devices.connection`), the gripper and the
/// masters simulated (drivers/sim_companions.h). Builds, opens nothing.
devices::DeviceSet make_mcs2_devices(const platform::PlatformConfig& config);

}  // namespace mc::drivers
