#pragma once
/// @file
/// The master of model-mediated teleoperation (Mitra and Niemeyer, "Model-mediated
/// telemanipulation", SPIE 6906, 2008): the handle feels a local model of the remote
/// contact, rendered without delay at the haptic rate, instead of the slave's delayed force. The
/// slave estimates the model (contact_estimator.h) and sends it back; the master moves its model
/// towards each new estimate with a first-order lag
///   theta <- theta + dt / (tau + dt) (theta_received - theta),   theta = (x_w, k)        (1)
/// and renders the wall as the coupling presents it: the contact behind the slave's position
/// servo (stiffness k_p), i.e. the two springs in series,
///   f = k_r max(0, x - x_w),   k_r = k k_p / (k + k_p)                                   (2)
/// which is the undelayed coupling's static force (position forward, force back) for the same
/// handle position: the model is transparent at rest.
///
/// Passivity: a wall (2) with fixed parameters is a lossless spring, but every update (1) made
/// while the handle is in the wall changes its stored energy, and one that raises it can hand the
/// operator energy nobody put in. The model's port therefore runs the passivity observer and
/// controller of Hannaford and Ryu ("Time-domain passivity control of haptic interfaces", IEEE
/// Trans. Robotics and Automation 18(1), 2002):
///   PO(n) = sum_{i<=n} f_i v_i dt >= 0                                                  (3)
/// (power into the model f v, the handle's force opposing +x) enforced at each step by a
/// variable damper f' = f + alpha v, alpha = -PO / (v^2 dt), which dissipates exactly the
/// excess. Nothing crosses the network as power: the delay cannot generate energy in this loop,
/// only the model updates can, and (3) bounds what they give. Plain arithmetic per step.

#include "microcobot/teleop/contact_estimator.h"
#include "microcobot/teleop/passivity.h"

namespace mc::teleop {

struct ModelMediatedMasterParams {
  double time_constant_s = 0.005;  ///< tau of (1); chosen on the tuning set (docs/concepts/teleoperation.md)
  double servo_stiffness_N_m = 5000;  ///< the slave's position servo k_p, for (2)
  double max_force_N = 20.0;          ///< the master's actuator saturates here
  bool passivity = true;              ///< false: observe (3) only
  void validate() const;
};

class ModelMediatedMaster {
 public:
  /// Throws InvalidParams. `prior`: the model before the slave reports (the microworld's geometry).
  ModelMediatedMaster(const ModelMediatedMasterParams& p, const ContactModel& prior);
  /// The latest model the slave reported (held until a newer one arrives). Never allocates.
  void receive(const ContactModel& m) noexcept { target_ = m; }
  /// The force opposing +x for one haptic step of `dt_s` at handle position `x`, velocity `v`
  /// (eq. 1-3). Never allocates.
  double force(double x, double v, double dt_s) noexcept;
  /// PO of (3) after the last step [J] (>= 0 when enabled, up to rounding and saturation).
  double observed_J() const { return e_.in_J - e_.out_J; }
  double dissipated_J() const { return dissipated_J_; }
  /// The model being rendered now.
  const ContactModel& model() const { return model_; }
  double rendered_stiffness_N_m() const;

 private:
  ModelMediatedMasterParams p_;
  ContactModel model_, target_;
  PortEnergy e_;  // of the model's port: f v > 0 is input
  double dissipated_J_ = 0.0;
};

}  // namespace mc::teleop
