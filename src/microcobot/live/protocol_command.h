#pragma once
/// @file
/// What a vendor-protocol client (the GCS 2.0 and ANC300 twins, vendor/) asks of the live
/// platform, checked and clamped by the protocol thread before it is pushed: plain
/// data copied into the loop through the live platform's protocol ring (one producer: the
/// protocol thread). The loop is the arbiter of who controls the stage: a protocol command counts
/// only while no console client holds control, and the protocol's heartbeat is its deadman.

#include <array>
#include <cstdint>

namespace mc::live {

struct ProtocolCommand {
  enum class Kind : std::uint8_t {
    kHeartbeat,  ///< the controlling client is still connected (sent every ~20 ms)
    kMoveTo,     ///< closed loop: every axis to goal_m at speed_m_s, theta to theta_goal_rad at
                 ///< theta_speed_rad_s (GCS MOV/MVR/FRF)
    kSteps,      ///< open loop: `periods` sawtooth periods on `axis` (ANC300 stepu/stepd)
    kStop,       ///< stop every motion at once, every axis holding (HLT, STP, #24, stop)
    kRelease,    ///< the controlling client is gone: stop, hold, control free
  };
  Kind kind = Kind::kHeartbeat;
  std::array<double, 3> goal_m{};  ///< stage coordinates (relative to home) [m]
  double speed_m_s = 0.0;
  /// The rotary axis: its goal, the gripper's yaw as the console's
  /// theta_goal_rad (world frame), within the platform's travel [rad], and its speed [rad/s].
  double theta_goal_rad = 0.0;
  double theta_speed_rad_s = 0.0;
  int axis = 0;  ///< 0..2; 3: the rotary axis
  double amplitude_V = 0.0;
  double frequency_Hz = 0.0;
  int direction = 1;  ///< +1 up (forward), -1 down
  std::int64_t periods = 0;
  std::uint64_t seq = 0;  ///< increasing per command: the view says which the loop applied
};

/// What the loop publishes for the protocol clients (atomics, any thread). Index 3 is the rotary
/// axis (its position the gripper's yaw [rad], as the console's theta; 0 without one).
struct ProtocolView {
  std::array<double, 4> position{};  ///< measured: stage coordinates [m]; theta [rad]
  std::array<bool, 4> on_target{};   ///< within the tolerance of the goal for the settle window
  std::array<bool, 4> stepping{};    ///< an open-loop run is in progress
  bool protocol_fresh = false;       ///< the protocol drives the coupling now
  bool console_in_control = false;   ///< a console client holds control
  bool halted = false;               ///< the e-stop latched (or a device faulted)
  std::uint64_t refused_steps = 0;   ///< open-loop runs the platform refused
  std::uint64_t applied_seq = 0;     ///< the last command the loop applied (its seq)
};

}  // namespace mc::live
