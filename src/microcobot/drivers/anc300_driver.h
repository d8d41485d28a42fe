#pragma once
/// @file
/// The `anc300` driver: the platform's three stage axes on an Attocube ANC300 over its
/// telnet console (TCP 7230, or `microcobot serve --emulate anc300`). The ANC300 is open loop:
/// it plays N sawtooth periods (`stepu/stepd AXIS N`) at the set amplitude (`setv`) and frequency
/// (`setf`) and knows nothing of where the slider is. So the driver closes the platform's
/// position loop itself, in its bus thread, at the step level (docs/hardware.md, "anc300"):
///
///   n periods toward the target as drivers/step_drive.h plans them (the step s of one period,
///   the dead band, at most frequency * max_run_s per command); every axis off its target is
///   started (`stepu|stepd AXIS n`, the controller plays the runs at once), then
///   each is waited for (`stepw AXIS` answers once its run is over)
///
/// The position is either counted (the default, all a real ANC300 without a sensor gives: the
/// sum of the periods sent times s, from 0 at the first configure; it drifts by the step's error,
/// which the model's s cannot know) or read from the twin's sensor (`position=getpos`: the twin's
/// own `getpos` command, which no ANC300 has). `s` comes from the platform's stick-slip model
/// (motion::measure_step at the set amplitude and frequency: the model identified for these
/// axes, `stickslip_params_file`) unless given (options step_up_nm, step_down_nm).
///
///   configure  login (password prompt), echo off, ver, getser N (each axis exists), setm N stp,
///              setf N f, setv N v; getpos N (position=getpos). Every reply must end in OK: the
///              ANC300 has no error register, an ERROR line is its error (the configuration
///              fails naming the command and the controller's message)
///   each cycle [getpos N x3], setm N stp (an axis armed again), stepu|stepd N n for each axis
///              off its target, then stepw N for each
///   safe state stop N, setm N gnd (every axis)
///
/// The rotary axis under the gripper, with the option `theta=N`: the
/// controller's rotary positioner on axis N, stepped like the three with the same step per period
/// (the same actuator, on the rotor's arc at stage.rotary.radius_m; the platform's rotary axis
/// position is that arc); its `getpos` is read in deg (the twin's), converted to the arc.

#include <array>
#include <memory>
#include <string>

#include "microcobot/devices/device_set.h"
#include "microcobot/drivers/bus_controller.h"
#include "microcobot/drivers/step_drive.h"
#include "microcobot/platform/platform_config.h"

namespace mc::drivers {

/// The ANC300's serial rate as lab scripts driving it over RS-232/USB set it (38400 baud, 8N1).
/// Attocube's manual was not at hand: the value is from those scripts (docs/parameters.md), not
/// from the vendor; `baud=` overrides it.
inline constexpr int kAnc300DefaultBaud = 38400;

struct Anc300DriverParams {
  BusTiming timing{2.0, 0.2, 0.005, 0.1};  ///< a step run blocks a cycle: slower than GCS's
  std::string password = "123456";         ///< the controller's factory password
  std::array<int, 3> axes = {1, 2, 3};     ///< the controller's axes for X, Y, Z
  int theta = 0;                           ///< the controller's axis of the rotary axis; 0: none
  double radius_m = 5e-3;                  ///< the rotary axis' contact radius: its arc per rad
  bool sensor = false;                     ///< position=getpos (the twin's sensor) instead of counted
  StepDriveParams step;                    ///< setv, setf, the runs and the counted step
  void validate() const;
};

/// `connection` options: timeout_s, connect_timeout_s, poll_s, stale_s, password, axes ("1+2+3"),
/// theta (the rotary positioner's axis), voltage_V, frequency_Hz, max_run_s, position
/// (counted|getpos), step_up_nm, step_down_nm, deadband_nm.
Anc300DriverParams anc300_driver_params(const Connection& connection);

class Anc300Controller final : public BusController {
 public:
  Anc300Controller(Connection connection, Anc300DriverParams params);
  ~Anc300Controller() override { shutdown(); }
  const Anc300DriverParams& params() const { return params_; }
  /// X, Y, Z, and the rotary axis with the option theta.
  int axis_count() const { return params_.theta == 0 ? 3 : 4; }
  /// Periods commanded since the start, per axis, signed (tests).
  long long periods_sent(int axis) const { return periods_[static_cast<std::size_t>(axis)].load(); }

 protected:
  void handshake(LineClient& bus) override;
  void cycle(LineClient& bus) override;
  void safe_state(LineClient& bus) override;

 private:
  /// Sends `line`, returns the lines before its OK within `timeout_s` (0: the reply timeout).
  /// Throws BusFault on ERROR (with the controller's message), a timeout or a lost connection.
  std::vector<std::string> request(LineClient& bus, const std::string& line, double timeout_s = 0.0);
  double read_position(LineClient& bus, int i);
  int axis_id(std::size_t i) const { return i < 3 ? params_.axes[i] : params_.theta; }

  Anc300DriverParams params_;
  std::array<double, kMaxAxes> est_m_{};  // counted, or the sensor's last
  std::array<bool, kMaxAxes> stepping_mode_{};
  std::array<std::atomic<long long>, kMaxAxes> periods_{};
};

/// The driver set `anc300`: the three axes (and the rotary axis, option theta, when the
/// configuration has one) on one Anc300Controller, the gripper and the masters simulated
/// (drivers/sim_companions.h). Builds (the step from the model), opens nothing.
devices::DeviceSet make_anc300_devices(const platform::PlatformConfig& config);

}  // namespace mc::drivers
