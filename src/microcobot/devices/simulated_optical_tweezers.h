#pragma once
/// @file
/// The slave tool of the optical-tweezers scene (thesis §3.5.2, Fig. 3.3 and 3.16): a laser trap
/// carried over the dish by the XYZ stage, holding a probe bead (microworld::OpticalTrap) that
/// the operator brings against a large bead stuck on the dish. It stands where the gripper
/// stands in the pick-and-place (a Gripper behind the same interface), so the loop, the
/// coupling and the console are unchanged:
///  - the trap's centre is the tool point, the stage's true position plus the mount offset
///    `home_m` (x, y: the model is planar, as the application is, §3.2.1; the bead follows the
///    focal plane in z);
///  - contact_force_N() is what optical tweezers measure, the linear spring model of Fig. 3.3:
///    k (x_bead - x_trap). Pushing the probe into the stuck bead makes it lag behind the trap,
///    so the force opposes the motion, and at rest it carries the Brownian motion (the thermal
///    agitation the operator feels through the crossover's high band, Fig. 3.14b);
///  - the trap has no fingers: opening and grip force are 0 and opening commands are ignored.
/// The safe state keeps the laser on: a trap switched off on a fault would lose the bead.

#include <array>

#include "microcobot/core/rng.h"
#include "microcobot/devices/device.h"
#include "microcobot/devices/simulated_slave_axis.h"
#include "microcobot/microworld/optical_trap.h"

namespace mc::devices {

class SimulatedOpticalTweezers final : public Gripper {
 public:
  /// The axes must outlive the device. `loop_dt_s` (the update period) must be a whole number
  /// of the trap's integration steps. Throws mc::InvalidParams.
  SimulatedOpticalTweezers(std::string name, const microworld::OpticalTrapSceneParams& scene,
                           std::array<const SimulatedSlaveAxis*, 3> axes, const Vec3& home_m,
                           double loop_dt_s);

  void command_opening_m(double) noexcept override {}
  double opening_m() const override { return 0.0; }
  double grip_force_N() const override { return 0.0; }
  /// k (x_bead - x_trap), the force the trap measures [N] (z: 0).
  Vec3 contact_force_N() const override { return {force_N_.x(), force_N_.y(), 0.0}; }
  void update(double dt_s) noexcept override;
  void enter_safe_state() noexcept override {}

  /// The probe bead's centre (world frame; z: the focal plane, the tool point's z).
  Eigen::Vector3d bead_m() const { return {state_.bead_m.x(), state_.bead_m.y(), tool_m().z()}; }
  /// The stuck bead's centre (world frame, on the dish: z 0).
  Eigen::Vector2d obstacle_m() const { return obstacle_m_; }
  /// The beads overlap (the probe touches the stuck bead).
  bool in_contact() const;
  const microworld::OpticalTrap& trap() const { return trap_; }

 protected:
  void on_configure() override;

 private:
  Eigen::Vector3d tool_m() const;

  microworld::OpticalTrapSceneParams scene_;
  microworld::OpticalTrap trap_;
  std::array<const SimulatedSlaveAxis*, 3> axes_;
  Eigen::Vector3d home_m_;
  int substeps_ = 1;
  Eigen::Vector2d obstacle_m_ = Eigen::Vector2d::Zero();
  microworld::OpticalTrapState state_;
  Eigen::Vector2d force_N_ = Eigen::Vector2d::Zero();
  Rng rng_;
};

}  // namespace mc::devices
