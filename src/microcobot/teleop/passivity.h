#pragma once
/// @file
/// Time-domain passivity of a delayed bilateral channel, after Ryu, Artigas and
/// Preusche, "A passive bilateral control scheme for a teleoperator with time-varying
/// communication delay" (Mechatronics 20, 2010), the time-delay form of Ryu and Hannaford's
/// passivity observer and controller. Why this and not wave variables: docs/concepts/teleoperation.md.
///
/// Each port of the channel books the power flowing into the channel, P = f v, as input energy
/// (P > 0) or output energy (P < 0), and sends its input energy to the other side with every
/// sample. A port may output only the energy the other side has put in and that has arrived:
///   master: PO_m(t) = E_in,s(t - T_b) - E_out,m(t) >= 0
///   slave:  PO_s(t) = E_in,m(t - T_f) - E_out,s(t) >= 0
/// which bounds the channel's energy below (it is passive) for any delay, jitter or loss (a
/// lost sample only delays the energy it carried). When a port would break its bound, its
/// passivity controller dissipates exactly the excess at that sample:
///  - master (impedance causality: velocity in, force out): a variable damper, f' = f + alpha v;
///  - slave (admittance causality: force in, velocity out): the commanded velocity is reduced,
///    v' = v - beta f, and the slave's desired position is the integral of v' (position drift,
///    recovered whenever the contact force lets the energy through).
/// Plain arithmetic per sample: no allocation, no branch on the delay.

namespace mc::teleop {

/// Energy through one port [J], both positive.
struct PortEnergy {
  double in_J = 0.0;
  double out_J = 0.0;
  void add(double power_into_channel_W, double dt_s) noexcept {
    if (power_into_channel_W > 0.0) {
      in_J += power_into_channel_W * dt_s;
    } else {
      out_J -= power_into_channel_W * dt_s;
    }
  }
};

/// The master side: the force `f` received from the slave opposes the handle's velocity `v`
/// (power into the channel f v). `enabled` false observes only (the unprotected channel).
class MasterPassivityController {
 public:
  explicit MasterPassivityController(bool enabled) : enabled_(enabled) {}
  /// The force to render for one sample of `dt_s`, given the slave's input energy that has
  /// arrived (`remote_in_J`). Never allocates.
  double force(double f, double v, double remote_in_J, double dt_s) noexcept;
  const PortEnergy& energy() const { return e_; }
  /// PO_m after the last sample (>= 0 when enabled, up to rounding).
  double observed_J() const { return observed_J_; }
  /// Energy the controller dissipated so far [J].
  double dissipated_J() const { return dissipated_J_; }

 private:
  bool enabled_;
  PortEnergy e_;
  double observed_J_ = 0.0, dissipated_J_ = 0.0;
};

/// The slave side: the commanded velocity `v` of the slave against the contact force `f` the
/// environment opposes to it (power out of the channel f v).
class SlavePassivityController {
 public:
  explicit SlavePassivityController(bool enabled) : enabled_(enabled) {}
  /// The velocity to command for one sample of `dt_s`, given the master's input energy that has
  /// arrived (`remote_in_J`). Never allocates.
  double velocity(double v, double f, double remote_in_J, double dt_s) noexcept;
  const PortEnergy& energy() const { return e_; }
  double observed_J() const { return observed_J_; }
  double dissipated_J() const { return dissipated_J_; }

 private:
  bool enabled_;
  PortEnergy e_;
  double observed_J_ = 0.0, dissipated_J_ = 0.0;
};

}  // namespace mc::teleop
