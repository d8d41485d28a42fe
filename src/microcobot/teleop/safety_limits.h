#pragma once
/// @file
/// The force and workspace limits the teleoperation coupling enforces on the slave whatever its
/// input (a cobot puts a person's hands and a customer's parts next to the machine):
///
///  - **grip force**: a force-controlled close. A PiezoGripper finger is a spring of stiffness
///    k at its tip (microworld/piezo_gripper.h), so a part of width w squeezed by fingers
///    commanded to an opening o carries F = k (w - o) / 2. Once the fingers touch the part (a
///    grip force is measured and the measured opening is the part's width), the opening
///    command is kept at or above
///        o_min = w - 2 F_max / k,
///    where the force reaches its limit and stops: the bender's first-order response approaches
///    its command without overshoot, so the force never passes F_max. Should the measured
///    force pass the limit anyway (a stiffness that is not the model's), the command opens by
///    2 (F - F_max) / k beyond its last value at each tick until it is back under it;
///  - **contact force**: above its limit the tool may not go further into the contact. The
///    force on the gripper pushes it out of the contact, so the target's component along
///    -F/|F| ahead of the measured position is removed (the stage holds; moving away is free);
///  - **floor**: the tool point's target never goes below `floor_m` (stage coordinates: the
///    substrate plus a clearance), so the finger tips cannot be driven into the substrate.
///
/// Every function is real-time safe (no allocation, lock, exception or I/O).

#include <limits>

#include <Eigen/Core>

namespace mc::teleop {

struct SafetyLimitParams {
  double grip_force_limit_N = 1e-3;     ///< the part's scene sets it (microworld keys)
  double contact_force_limit_N = 2e-3;  ///< force on the gripper above which the stage holds
  double finger_stiffness_N_m = 50.0;   ///< the gripper's finger-tip stiffness (its model)
  /// Lowest tool-point z target (stage coordinates); -inf: none.
  double floor_m = -std::numeric_limits<double>::infinity();
  void validate() const;
};

class SafetyLimits {
 public:
  /// Validates. Throws mc::InvalidParams naming the field.
  explicit SafetyLimits(const SafetyLimitParams& params);
  const SafetyLimitParams& params() const noexcept { return p_; }

  /// The opening to command given the one requested, the gripper's measured opening and grip
  /// force, and the last opening commanded (the force-controlled close above).
  double limit_opening_m(double requested_m, double measured_opening_m, double grip_force_N,
                         double last_command_m) const noexcept;
  /// True when the contact force exceeds its limit.
  bool contact_over_limit(const Eigen::Vector3d& contact_force_N) const noexcept;
  /// Limits a new slave target (and its velocity feedforward) for the measured contact force and
  /// position: nothing further into an over-limit contact, nothing below the floor.
  void limit_target(Eigen::Vector3d& target_m, Eigen::Vector3d& velocity_m_s,
                    const Eigen::Vector3d& measured_m, const Eigen::Vector3d& contact_force_N) const noexcept;

 private:
  SafetyLimitParams p_;
};

}  // namespace mc::teleop
