#pragma once
/// @file
/// The stage answering SmarAct's MCS2 ASCII interface: channels 0, 1, 2 are the platform's X, Y, Z
/// (linear positioners, positions in pm, velocities in pm/s) and, when the platform has the rotary
/// axis under the gripper, channel 3 is a rotary positioner (ndeg, ndeg/s), over the platform's own
/// position control and open-loop stepping (twins/twin_stage.h). Lines are split and parsed by
/// mcs2_codec.h; every value is checked (channel, number, range) before it reaches the stage.
///
/// As the controller does: an unreferenced channel says so in `STAT?` and refuses absolute moves
/// (error 274, not referenced; relative moves and steps go); `:REF<n>` drives it to its reference
/// mark (the stage's home) and marks it referenced; a channel without a sensor (Mcs2TwinParams::
/// no_sensor_channels, or `SENS:MODE 0`) answers position queries and closed-loop moves with
/// error 259 (no sensor present) or 260 (sensor disabled) and moves only in step mode (`MMOD 4`):
/// `:MOVE<n> <steps>` runs that many sawtooth periods at `STEP:FREQ` and `STEP:AMPL` (65535 = 100 V)
/// through the platform's stick-slip model. Commands (docs/hardware.md): `*IDN?`, `*CLS`,
/// `:DEV:SNUM?`, `:DEV:NOCH?`, `:DEV:NOBM?`, `:DEV:STAT?`, `:DEV:EST:MODE?`, `:MOD<m>:STAT?`,
/// `:MOD<m>:TEMP?`, `:SYST:ERR:COUN?`, `:SYST:ERR[:NEXT]?`, `:MOVE<n>`, `:REF<n>`, `:CAL<n>`,
/// `:STOP<n>` and the channel properties of mcs2_channel_properties.cc. The controller's state
/// (channels, the error queue) is shared by every connection, as one controller's is. Protocol
/// thread only.

#include <array>
#include <chrono>
#include <cstdint>
#include <deque>
#include <string>
#include <string_view>

#include "microcobot/drivers/mcs2_codec.h"
#include "microcobot/twins/twin_stage.h"

namespace mc::twins {

struct Mcs2TwinParams {
  std::string serial = "MCS2-00000001";  ///< `:DEV:SNUM?`
  /// Channels built without a position sensor (bit n: channel n): open-loop stepping only.
  unsigned no_sensor_channels = 0;
  double calibration_s = 0.5;                    ///< how long `:CAL<n>` reports calibrating
  std::int64_t velocity_pm_s = 100'000'000;      ///< each linear channel's VEL at power-up (0.1 mm/s)
  std::int64_t velocity_ndeg_s = 5'000'000'000;  ///< the rotary channel's VEL at power-up (5 deg/s)
  int step_frequency_Hz = 1000;                  ///< STEP:FREQ at power-up
  int step_amplitude = 39321;                    ///< STEP:AMPL at power-up (60 V)
  void validate() const;
};

/// One channel's settings and state, as the controller keeps them.
struct Mcs2Channel {
  int move_mode = drivers::mcs2::kAbsolute;
  int sensor_mode = drivers::mcs2::kSensorOn;
  bool sensor_present = true;
  bool amplifier = true;
  std::int64_t velocity = 0, acceleration = 0;  ///< per s, per s^2 (0: no control, as fast as allowed)
  std::int64_t hold_ms = 0;                     ///< -1: forever
  int step_frequency_Hz = 1000, step_amplitude = 39321, mclf_Hz = 5000, ref_options = 0;
  int safe_direction = 0, positioner_type = 300;
  bool calibrated = false, referenced = false, referencing = false;
  bool closed_loop = false;  ///< its last motion was closed-loop (it holds its target)
  bool range_limit = false, move_failed = false;
  std::chrono::steady_clock::time_point calibrating_until{};
  std::int64_t target = 0;  ///< pm or ndeg, in the channel's own (logical) scale
  std::int64_t offset = 0;  ///< the logical scale less the stage's (set by `POS <v>`, zeroed by REF)
};

class Mcs2Twin {
 public:
  Mcs2Twin(TwinStage& stage, Mcs2TwinParams params);
  /// The reply bytes to one line from `client`: one CR LF line per query answered, in order (empty
  /// when it held set commands only). A query that fails is not answered (its error is queued);
  /// after a failed command the line's later set commands and actions are skipped.
  std::string on_line(ClientId client, std::string_view line);
  /// A line longer than mcs2::kMaxLineLength arrived (its rest discarded): error -363.
  void on_overlong_line() { push_error(drivers::mcs2::kInputBufferOverrun); }
  void on_disconnect(ClientId client) { stage_.release(client); }
  std::size_t error_count() const { return errors_.size(); }
  int channel_count() const { return channels_; }

 private:
  /// One command; its reply line appended to `reply` for a query. Errors go to the queue.
  void execute(ClientId client, const drivers::mcs2::Command& c, std::string& reply);
  /// The `:CHAN<n>:...` properties (mcs2_channel_properties.cc).
  void channel_property(ClientId client, int n, const drivers::mcs2::Command& c, std::string& reply);
  void move(ClientId client, int n, const drivers::mcs2::Command& c);
  void reference(ClientId client, int n);
  void stop(ClientId client, int n);
  /// True unless another client's motion runs the stage (its moves are its own to stop).
  bool may_stop(ClientId client) const { return owner_ == 0 || stage_.controls(client); }
  /// Every channel's goal to the stage, closed loop: each channel that holds a target goes to it,
  /// the others stay; `speed_channel`'s VEL sets the pace. The error pushed on a refusal.
  bool send_goal(ClientId client, int speed_channel);
  /// The channel's STAT? bits.
  std::uint32_t state(int n) const;
  bool moving(int n) const;
  /// Referencing done, calibration over, a halt seen: the channels' flags follow the stage.
  void update();
  /// Pushes the error of a stage refusal; false for one.
  bool accepted(TwinStage::Refusal r);
  /// Checks the channel can run closed loop (sensor present and enabled, amplifier on).
  bool closed_loop_ready(int n);
  void push_error(int code);
  /// The stage's position of channel n in its unit (pm, ndeg), and back.
  std::int64_t stage_units(int n) const;
  double to_si(int n, std::int64_t units) const;
  std::int64_t from_si(int n, double si) const;
  bool rotary(int n) const { return n == TwinStage::kTheta; }
  /// The channel's travel in its logical scale.
  std::int64_t min_units(int n) const;
  std::int64_t max_units(int n) const;
  bool channel_ok(int n);

  TwinStage& stage_;
  Mcs2TwinParams params_;
  int channels_;  // 3, or 4 with the rotary positioner
  std::array<Mcs2Channel, TwinStage::kMaxAxes> ch_{};
  std::deque<int> errors_;
  ClientId owner_ = 0;        // the client whose motion the stage runs (0: none)
  std::uint64_t pushed_ = 0;  // errors pushed so far (a line's sets stop at its first)
};

}  // namespace mc::twins
