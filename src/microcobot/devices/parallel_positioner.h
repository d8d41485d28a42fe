#pragma once
/// @file
/// The 6-DOF parallel stick-slip positioner as a device of the platform (thesis: T. Lu, PhD
/// thesis, UPMC 2016, §2.3, Fig. 2.4: the part on the parallel positioner, the gripper on the
/// Cartesian robot; docs/concepts/parallel-positioner.md). Its interface is the pose control's
/// real-time half: a move planned and checked off the loop (motion::PoseTrajectory,
/// motion::check_move) is started by start_move(), stop() holds every leg where it is, and the
/// pose comes back measured. A hardware driver implements it as the simulated one does
/// (simulated_parallel_positioner.h); its safe state holds every leg at 0 V.

#include "microcobot/devices/device.h"
#include "microcobot/motion/parallel_kinematics.h"
#include "microcobot/motion/pose_trajectory.h"

namespace mc::devices {

class ParallelPositioner : public Device {
 public:
  using Device::Device;
  /// The positioner's kinematics (immutable: the geometry it was configured with).
  virtual const motion::ParallelKinematics& kinematics() const noexcept = 0;
  /// Starts `checked` (a trajectory check_move() passed, starting at reference_pose()). False, and
  /// nothing moves, unless Active and at rest from any other move, or when it starts elsewhere.
  /// Never allocates.
  virtual bool start_move(const motion::PoseTrajectory& checked) noexcept = 0;
  /// Follows a streamed pose (motion::ParallelStage::follow: the reference pursues `target`
  /// within `limits`, the legs' speed limit and the workspace, whose edge stops it). False, and
  /// nothing moves, unless Active and free of a planned move. A device that takes planned moves
  /// only refuses it: the default (a PI C-887 plans each move from its MOV; it is not streamed a
  /// pose). Never allocates.
  virtual bool follow(const motion::PlatformTransform& /*target*/,
                      const motion::PoseMoveLimits& /*limits*/) noexcept {
    return false;
  }
  /// Whether a followed target drives it; stop() ends that.
  virtual bool following() const noexcept { return false; }
  /// Whether the followed reference stands at the workspace's edge (its next step not reachable).
  virtual bool follow_blocked() const noexcept { return false; }
  /// Ends any move: every leg holds where it is measured. Never allocates.
  virtual void stop() noexcept = 0;
  /// FK of the legs' sensors, {H}.
  virtual const motion::PlatformTransform& measured_pose() const noexcept = 0;
  /// The pose the legs are told to be at (a move's T(s(t)), or the held pose).
  virtual const motion::PlatformTransform& reference_pose() const noexcept = 0;
  virtual bool moving() const noexcept = 0;
  /// No move, every leg holding its pose in position.
  virtual bool at_rest() const noexcept = 0;
  /// The largest |drive voltage| over the six legs [V] (0 in the safe state).
  virtual double max_leg_voltage_V() const noexcept = 0;
};

}  // namespace mc::devices
