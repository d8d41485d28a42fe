#pragma once
/// @file
/// The stage answering the Attocube ANC300's console: three open-loop stick-slip
/// axes 1, 2, 3 (X, Y, Z) and, when the platform has the rotary axis under the gripper, a rotary positioner
/// on axis 4 (theta), whose `stepu`/`stepd` run sawtooth periods of the set amplitude and frequency through
/// the platform's stick-slip model (Platform::start_open_loop_steps; theta turns by the arc its actuator
/// steps). Lines are parsed by anc300_codec.h; every value is checked before it reaches the stage. Commands
/// (docs/hardware.md): echo, ver, getcser, getser, setm/getm, setf/getf, setv/getv, stepu, stepd,
/// stepw, stop, getc, and `getpos` (the twin's sensor, m or deg; no ANC300 has it). The axes'
/// settings are the controller's (shared by every connection); echo and login are each
/// connection's. Protocol thread only.

#include <array>
#include <optional>
#include <string>
#include <string_view>

#include "microcobot/drivers/anc300_codec.h"
#include "microcobot/twins/twin_stage.h"

namespace mc::twins {

struct Anc300TwinParams {
  double frequency_Hz = 1000.0;  ///< each axis' setf at power-up
  double voltage_V = 30.0;       ///< each axis' setv at power-up
  /// What `getc` reports [nF]: the model has no electrical side, so this is a stated value, not
  /// a measurement (a documented choice; docs/hardware.md).
  double capacitance_nF = 1000.0;
  void validate() const;
};

/// One console connection's state.
struct Anc300Session {
  bool authorized = false;
  bool echo = true;  ///< the console echoes each line and prints a prompt until `echo off`
};

class Anc300Twin {
 public:
  Anc300Twin(TwinStage& stage, Anc300TwinParams params);
  /// What a new connection is sent: the banner and the password prompt.
  std::string greeting() const;
  /// The reply to the password line: success (and the prompt) or failure (and the password
  /// prompt again; the server closes after the third).
  std::string on_password(Anc300Session& s, std::string_view line, bool accepted);
  /// The reply bytes to one command line. A `stepw` on a stepping axis returns nullopt: the
  /// caller asks again with poll_wait() until it answers.
  std::optional<std::string> on_line(ClientId client, Anc300Session& s, std::string_view line);
  /// A pending `stepw`'s reply once the axis stopped (nullopt while it steps).
  std::optional<std::string> poll_wait(Anc300Session& s, int axis);
  /// The reply to a line longer than anc300::kMaxLineLength (its rest discarded).
  std::string on_overlong_line(const Anc300Session& s) const;
  void on_disconnect(ClientId client) { stage_.release(client); }
  /// The axis a pending `stepw` waits on (set by on_line when it returned nullopt).
  int waiting_axis() const { return waiting_axis_; }

 private:
  std::string finish(const Anc300Session& s, std::string_view echoed, const std::string& body) const;
  std::string execute(ClientId client, const drivers::anc300::Request& r);
  std::string refusal(TwinStage::Refusal r) const;
  /// The axis (0-based) a console axis id names ("1".."4"), -1 for none of this controller's.
  int axis_index(std::string_view id) const;

  TwinStage& stage_;
  Anc300TwinParams params_;
  int axes_;  // 3, or 4 with the rotary positioner
  std::array<drivers::anc300::Mode, TwinStage::kMaxAxes> mode_{};
  std::array<double, TwinStage::kMaxAxes> frequency_Hz_{}, voltage_V_{};
  std::string pending_echo_;
  int waiting_axis_ = -1;
};

}  // namespace mc::twins
