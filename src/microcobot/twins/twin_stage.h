#pragma once
/// @file
/// What a protocol twin (GCS 2.0, ANC300) reads of the stage it emulates and asks of it.
/// Called from the protocol thread only. The live implementation (live_stage.h)
/// turns the asks into commands on the live platform's protocol ring; tests use a fake.
///
/// Control (docs/hardware.md, "Who controls the stage"): a protocol client is an operator
/// input like the console. It takes control with its first motion command, only while no console
/// client holds control, nobody else's protocol client holds it and the platform is not halted;
/// it keeps it while connected (its connection is its deadman: the protocol thread's heartbeat),
/// and loses it when it disconnects or a console client takes control (the stage then holds).
/// The parallel positioner (the hexapod twin's), when the platform has one, is controlled the
/// same way: one client at a time holds the stage and the positioner alike.

#include <array>
#include <cstdint>
#include <string>

#include "microcobot/live/protocol_command.h"
#include "microcobot/motion/parallel_kinematics.h"
#include "microcobot/motion/pose_trajectory.h"

namespace mc::twins {

using ClientId = std::uint64_t;

class TwinStage {
 public:
  /// Axes 0, 1, 2 are X, Y, Z (linear: m, stage coordinates, 0 at the home); axis 3, when the
  /// platform has it, is the rotary axis theta under the gripper (rad, 0 at its
  /// home, stage.rotary.home_rad: the console's theta, the gripper's yaw, less home_rad).
  static constexpr int kTheta = 3;
  static constexpr int kMaxAxes = 4;
  using Goal = std::array<double, kMaxAxes>;  ///< X, Y, Z [m], theta [rad]

  enum class Refusal {
    kNone,           ///< granted
    kHalted,         ///< the platform's e-stop latched (GCS error 10, ANC300 ERROR)
    kOtherOperator,  ///< a console client or another protocol client holds control
    kBusy,           ///< the command ring is full (try again)
    kUnreachable,    ///< a pose move motion::check_move() refuses (GCS error 7): nothing moves
  };
  struct Axis {
    double position = 0.0;   ///< measured (sensor): m (X, Y, Z) or rad (theta)
    bool on_target = false;  ///< settled on the last goal (false until the loop applied it)
    bool stepping = false;   ///< an open-loop run in progress (true from the ask on)
  };
  virtual ~TwinStage() = default;

  /// 3, or 4 with the rotary axis.
  virtual int axis_count() const = 0;
  virtual Axis axis(int i) const = 0;  ///< i < axis_count()
  /// Axis i's travel: the workspace [m], theta's [rad].
  virtual double min(int i) const = 0;
  virtual double max(int i) const = 0;
  /// Axis i's speed cap: the linear axes' [m/s] (one for the three), theta's [rad/s].
  virtual double max_speed(int i) const = 0;
  virtual double max_voltage_V() const = 0;
  virtual bool halted() const = 0;
  /// True while `client` holds control.
  virtual bool controls(ClientId client) const = 0;

  /// Every axis to `goal` (within the limits), closed loop: X, Y, Z together in a straight line
  /// at `speed_m_s`, theta at `theta_speed_rad_s` (both ignored without the rotary axis).
  virtual Refusal move_to(ClientId client, const Goal& goal, double speed_m_s, double theta_speed_rad_s) = 0;
  /// `periods` sawtooth periods on axis `i` (theta too; direction +1 up, -1 down), open loop.
  virtual Refusal step(ClientId client, int i, double amplitude_V, double frequency_Hz, int direction,
                       std::int64_t periods) = 0;
  /// Stops the protocol's motion at once, every axis holding. Never refused (a stop from a client
  /// that does not control the stage stops nothing of another operator's).
  virtual void stop(ClientId client) = 0;
  /// The client went away: stop and hold if it controlled, control free.
  virtual void release(ClientId client) = 0;
  /// Called every ~20 ms by the protocol thread: the controlling client's heartbeat.
  virtual void heartbeat() = 0;

  /// The parallel positioner's kinematics (immutable; its geometry), null without a positioner.
  virtual const motion::ParallelKinematics* positioner_kinematics() const { return nullptr; }
  /// Its moves' library limits (docs/parameters.md).
  virtual motion::PoseMoveLimits positioner_limits() const { return {}; }
  /// A pose move along `traj`, planned from where the legs will hold when it starts (the last
  /// move's goal, or the held pose: positioner_view().reference). Checked again here
  /// (motion::check_move()): kUnreachable with the one-line reason in `reason` and nothing moves.
  /// `seq` is its command's number (the view's started_seq / rejected_seq say what became of it).
  virtual Refusal move_pose(ClientId /*client*/, const motion::PoseTrajectory& /*traj*/,
                            std::uint64_t& /*seq*/, std::string& reason) {
    reason = "the platform has no parallel positioner";
    return Refusal::kUnreachable;
  }
  /// Stops the positioner's move and the queued ones (every leg holding), when `client` controls
  /// the stage: kNone with the stop's `seq` (the view's stop_seq reaches it once applied);
  /// kOtherOperator when nothing was sent (another operator's control or a halt: the positioner
  /// holds already); kBusy when the ring is full (send it again).
  virtual Refusal stop_pose(ClientId /*client*/, std::uint64_t& /*seq*/) { return Refusal::kOtherOperator; }
  /// The loop's newest snapshot of the positioner (protocol thread).
  virtual live::PositionerView positioner_view() { return {}; }
};

}  // namespace mc::twins
