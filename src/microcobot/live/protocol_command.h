#pragma once
/// @file
/// What a vendor-protocol client (the GCS 2.0 and ANC300 twins, vendor/) asks of the live
/// platform, checked and clamped by the protocol thread before it is pushed: plain
/// data copied into the loop through the live platform's protocol ring (one producer: the
/// protocol thread). The loop is the arbiter of who controls the stage: a protocol command counts
/// only while no console client holds control, and the protocol's heartbeat is its deadman.
/// A pose move of the parallel positioner (the hexapod twin's) travels planned and checked
/// (motion::check_move() on the protocol thread): the loop only starts it.

#include <array>
#include <cstdint>
#include <optional>

#include "microcobot/motion/pose_trajectory.h"

namespace mc::live {

struct ProtocolCommand {
  enum class Kind : std::uint8_t {
    kHeartbeat,  ///< the controlling client is still connected (sent every ~20 ms)
    kMoveTo,     ///< closed loop: every axis to goal_m at speed_m_s, theta to theta_goal_rad at
                 ///< theta_speed_rad_s (GCS MOV/MVR/FRF)
    kSteps,      ///< open loop: `periods` sawtooth periods on `axis` (ANC300 stepu/stepd)
    kStop,       ///< stop every motion at once, every axis holding (HLT, STP, #24, stop)
    kRelease,    ///< the controlling client is gone: stop, hold, control free
    kPoseMove,   ///< the parallel positioner along `pose` (checked), once the moves before it ended
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
  /// kPoseMove: a trajectory motion::check_move() passed, planned from the pose the legs will hold
  /// when it starts (the last queued move's goal, or the held pose).
  std::optional<motion::PoseTrajectory> pose;
};

/// What the loop publishes of the parallel positioner for the protocol thread (one snapshot, a
/// runtime::LatestValue: consistent as a whole).
struct PositionerView {
  motion::PlatformTransform measured;   ///< FK of the legs' sensors, {H}
  motion::PlatformTransform reference;  ///< the pose the legs are told to be at (held: the next start)
  bool moving = false;                  ///< a pose move runs or waits in the loop's queue
  bool at_rest = false;                 ///< no move, every leg holding in position
  bool halted = false;             ///< the platform's e-stop latched or a device faulted: every leg at 0 V
  std::uint64_t started_seq = 0;   ///< the last pose move started (its command's seq)
  std::uint64_t rejected_seq = 0;  ///< the last pose move dropped unstarted (halted, outranked, stale)
  std::uint64_t stop_seq = 0;      ///< the last stop applied
  /// The last pose move the loop ended short of its goal because the protocol lost control of the
  /// platform (its heartbeat stale, a console user took control): the legs hold where they were.
  std::uint64_t interrupted_seq = 0;
  double time_s = 0.0;  ///< loop time of the snapshot
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
