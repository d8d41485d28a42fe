#pragma once
/// @file
/// A bead in an optical trap (thesis §3.1 Fig. 3.3, §3.5.2): overdamped Langevin dynamics in
/// the plane, gamma dx = F_trap dt + F_c dt + sqrt(2 k_B T gamma) dW, with Stokes drag
/// gamma = 6 pi eta r, a probe (the trap centre) moved by the operator, and a large bead stuck
/// on the dish that the probe bead can touch (repulsive contact force F_c).
///
/// The trap is the linear spring of Fig. 3.3 near its centre and lets go beyond it: the
/// restoring force of a focused beam peaks near the bead's radius and falls off within about
/// another radius (Neuman & Block 2004, "Optical trapping", Rev. Sci. Instrum. 75, Fig. 5;
/// Ashkin 1992). A phenomenological profile with those features (a documented choice,
/// docs/concepts/dual-stage.md):
///     F_trap(d) = -k d g(d),   g(d) = exp(-(|d| / w)^4 / 4),   d = x - x_trap,
/// whose slope at the centre is k and whose peak, at |d| = w, is k w e^(-1/4): with the default
/// w = r e^(1/4) the escape force is k r (15 pN for the 3 um bead at 10 pN/um); at 2 w the
/// force is under 5 % of it. A bead pushed harder escapes the trap and stays behind (free
/// Brownian motion) until the trap comes back over it.

#include <Eigen/Dense>

#include "microcobot/core/params.h"
#include "microcobot/core/rng.h"

namespace mc::microworld {

/// Optical trap and scene. Defaults: a 3 um bead (radius 1.5 um, Fig. 3.14b) in water at
/// 300 K; trap stiffness 10 pN/um, typical of [Ni 2013b] setups (a documented choice).
struct OpticalTrapParams {
  double bead_radius_m = 1.5e-6;              ///< trapped probe bead radius (Fig. 3.14b: 3 um bead)
  double viscosity_Pa_s = 0.85e-3;            ///< water at 300 K
  double temperature_K = 300.0;               ///< the bath's temperature: the bead's Brownian motion
  double trap_stiffness_N_per_m = 1.0e-5;     ///< k (10 pN/um)
  double obstacle_radius_m = 5.0e-6;          ///< large bead stuck on the dish
  double contact_stiffness_N_per_m = 4.0e-4;  ///< linear repulsion once the beads overlap
  /// Distance from the trap's centre where its force peaks (w above); 0: r e^(1/4), which puts
  /// the escape force at k r.
  double escape_distance_m = 0.0;
  double dt_s = 1.0e-5;  ///< integration step (exact Ornstein-Uhlenbeck update)

  template <class V>
  void visit(V& v) {
    v("bead_radius_m", bead_radius_m);
    v("viscosity_Pa_s", viscosity_Pa_s);
    v("temperature_K", temperature_K);
    v("trap_stiffness_N_per_m", trap_stiffness_N_per_m);
    v("obstacle_radius_m", obstacle_radius_m);
    v("contact_stiffness_N_per_m", contact_stiffness_N_per_m);
    v("escape_distance_m", escape_distance_m);
    v("dt_s", dt_s);
  }
  void validate() const;
};

/// The optical-tweezers scene of the live platform (`microcobot serve --scene optical-trap`,
/// thesis §3.5.2 Fig. 3.16): the probe bead in a trap that the slave stage carries across the
/// dish, and a large bead stuck on the dish at a fixed offset from where the probe starts. The
/// operator feels the probe's force, Brownian motion and contact, through the dual-stage master.
struct OpticalTrapSceneParams {
  OpticalTrapParams trap;
  /// Centre of the stuck bead relative to where the probe starts (the tool point with the stage
  /// at home): 10 um along x, 3.5 um of free travel before the beads touch (1.5 + 5 um radii).
  double obstacle_offset_x_m = 10e-6;
  double obstacle_offset_y_m = 0.0;
  int seed = 1;  ///< of the thermal noise

  template <class V>
  void visit(V& v) {
    trap.visit(v);
    v("obstacle_offset_x_m", obstacle_offset_x_m);
    v("obstacle_offset_y_m", obstacle_offset_y_m);
    v("seed", seed);
  }
  void validate() const;
  /// The stuck bead's centre (world frame) when the probe starts at `start_m`.
  Eigen::Vector2d obstacle_m(const Eigen::Vector2d& start_m) const {
    return start_m + Eigen::Vector2d(obstacle_offset_x_m, obstacle_offset_y_m);
  }
};

/// State: bead and trap (probe) positions in the dish plane (m).
struct OpticalTrapState {
  Eigen::Vector2d bead_m = Eigen::Vector2d::Zero();
  Eigen::Vector2d trap_m = Eigen::Vector2d::Zero();
};

/// The trapped bead. step() never allocates.
class OpticalTrap {
 public:
  static constexpr double kBoltzmann = 1.380649e-23;

  explicit OpticalTrap(const OpticalTrapParams& params);
  const OpticalTrapParams& params() const { return params_; }

  /// Stokes drag coefficient gamma = 6 pi eta r (N s/m).
  double drag() const { return gamma_; }
  /// Corner frequency of the trap's position PSD, f_c = k / (2 pi gamma) (Hz).
  double corner_frequency_Hz() const;
  /// Equipartition variance of the bead position per axis, k_B T / k (m^2).
  double position_variance_m2() const;
  /// Where the trap's force peaks, w (m).
  double escape_distance_m() const { return w_; }
  /// The largest force the trap holds the bead with, k w e^(-1/4) (N): pushed harder, it escapes.
  double escape_force_N() const;

  /// Places the large stuck bead (centre) or removes it.
  void set_obstacle(const Eigen::Vector2d& centre_m) {
    obstacle_ = centre_m;
    has_obstacle_ = true;
  }
  void clear_obstacle() { has_obstacle_ = false; }

  /// Contact force on the probe bead from the stuck bead (N), zero when apart.
  Eigen::Vector2d contact_force(const Eigen::Vector2d& bead_m) const;
  /// Trap force on the bead, -k d g(d) (N). The measured force of optical tweezers (the spring
  /// model of Fig. 3.3 near the centre) is its opposite.
  Eigen::Vector2d trap_force(const OpticalTrapState& s) const;

  /// One step of dt_s with the trap held at s.trap_m: exact OU update towards the
  /// equilibrium x_trap + F_c/k (F_c frozen over the step). Throws ComputationFailed on NaN.
  void step(OpticalTrapState& s, Rng& rng) const;
  /// The same step for a real-time loop: returns false instead of throwing when the bead's
  /// position is no longer finite (the caller faults). Never allocates.
  bool try_step(OpticalTrapState& s, Rng& rng) const noexcept;

 private:
  /// g(d) above: 1 at the centre, e^(-1/4) at w, ~0 beyond 2 w.
  double hold_fraction(const Eigen::Vector2d& d) const noexcept;
  OpticalTrapParams params_;
  double gamma_ = 0.0;
  double decay_ = 0.0;  // exp(-k dt / gamma)
  double kick_ = 0.0;   // sqrt(kT/k (1 - decay^2))
  double w_ = 0.0;      // escape distance
  Eigen::Vector2d obstacle_ = Eigen::Vector2d::Zero();
  bool has_obstacle_ = false;
};

}  // namespace mc::microworld
