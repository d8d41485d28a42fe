#pragma once
/// @file
/// The 7-DOF linear dynamic model of the TéléTweez (thesis section 4.5.1, Fig. 4.23, eq. 4.6),
/// derived from its kinetic, potential and dissipated energies (docs/errata.md, "Eq. 4.6") so that
/// M, C and K are symmetric positive (semi)definite and the model is passive.
///
/// Generalized coordinates X = [theta_m, theta_cp, theta_bs, x_bs, x_ss, x_l, x_cl]: motor,
/// elastic coupling, ball-screw rotation, ball-screw axial (nut + slider), support structure
/// (roller carrier), lever at the finger contact, cantilever tip. x_l and x_cl are the
/// displacement of EACH lever (closing positive); the two levers move symmetrically
/// (section 4.5.1's assumptions), so their energies count twice.
///
///   T = 1/2 (J_m th_m'^2 + J_cp th_cp'^2 + J_bs th_bs'^2 + m_bs x_bs'^2 + m_ss x_ss'^2)
///       + m_l x_l'^2 + m_cl x_cl'^2
///   V = 1/2 k_cp (th_m - th_cp)^2 + 1/2 k_rot (th_cp - th_bs)^2
///       + 1/2 k_ax (x_bs - R_bs th_bs)^2          (ball screw: x = R_bs theta, erratum 6 in docs/errata.md)
///       + 1/2 k_ss (x_ss - x_bs)^2 + k_l (x_l - R_ss x_ss)^2
///       + (k_clamp + k_f) x_l^2 + k_cl (x_cl - x_l)^2
///   D = the same with the dampings c_*, plus 1/2 c_m th_m'^2 (motor bearings).
///
/// Inputs u = [T_m, F_f, F_t]: motor torque [N m], operator force on each finger contact
/// [N], external force on each tip [N] (all closing positive). Every term of V and D is a
/// square, so K and C are sums of rank-one PSD matrices; M is diagonal positive.

#include <Eigen/Core>
#include <complex>

namespace mc::tweezers {

/// Parameters of the TéléTweez model. Thesis values: motor inertia (0.151 g cm^2), lead
/// (1 mm), clamping stiffness (190 N/m, Table 4.8), continuous torque (2.2 mN m), total mass
/// (39 g), static opening (10 mm, Table 4.8), contact angle (63 deg). The others are documented
/// choices (docs/parameters.md) tuned so that the torque -> finger-acceleration FRF shows the
/// dominant mode near 150 Hz, the antiresonance near 390 Hz and a flat band to 100 Hz (Fig. 4.25).
struct TeleTweezParams {
  double motor_inertia_kg_m2 = 0.151e-7;  ///< J_m, 0.151 g cm^2 (section 4.4.1.5)
  double motor_damping_N_m_s =
      1.5e-6;  ///< c_m: back-EMF through the driver + bearings (choice, < k_t^2/R = 3.4e-6)
  double coupling_inertia_kg_m2 = 0.005e-7;   ///< J_cp (choice)
  double coupling_stiffness_N_m = 0.5;        ///< k_cp [N m/rad] (choice: miniature bellows)
  double coupling_damping_N_m_s = 2e-6;       ///< c_cp [N m s/rad] (choice)
  double screw_inertia_kg_m2 = 0.05e-7;       ///< J_bs, 4 mm steel shaft (choice)
  double screw_torsion_stiffness_N_m = 60.0;  ///< k_rot [N m/rad], G J_p / L of the shaft (choice)
  double screw_torsion_damping_N_m_s = 1e-5;  ///< c_rot (choice)
  double lead_m = 1e-3;                       ///< ball-screw lead, R_bs = lead / 2 pi (Table 4.6)
  double screw_mass_kg = 4e-3;                ///< m_bs, nut and slider (choice)
  double axial_stiffness_N_per_m = 5e6;       ///< k_ax, ball-nut contact (choice)
  double axial_damping_N_s_per_m = 50.0;      ///< c_ax (choice)
  double support_mass_kg = 3e-3;              ///< m_ss, roller carrier and magnet (choice)
  double support_stiffness_N_per_m = 2e5;     ///< k_ss, 3D-printed support (choice)
  double support_damping_N_s_per_m = 10.0;    ///< c_ss (choice)
  double transmission_ratio =
      2.5;  ///< R_ss: finger-contact motion per slider motion (choice: 2.2 mN m -> 2.2 N, Table 4.8)
  double lever_mass_kg = 6e-3;  ///< m_l, each lever (choice)
  double lever_stiffness_N_per_m =
      1.15e4;  ///< k_l, each lever between roller and finger (choice, tuned: 150 Hz)
  double lever_damping_N_s_per_m = 3.0;       ///< c_l (choice)
  double clamping_stiffness_N_per_m = 190.0;  ///< flexure, at the fingers (Table 4.8)
  double clamping_damping_N_s_per_m = 0.05;   ///< flexure damping (choice)
  double tip_mass_kg = 2e-3;                  ///< m_cl, each cantilever tip (choice)
  double tip_stiffness_N_per_m = 1.2e4;       ///< k_cl (choice, tuned: 390 Hz antiresonance)
  double tip_damping_N_s_per_m = 0.2;         ///< c_cl (choice)
  double finger_stiffness_N_per_m =
      300.0;  ///< k_f, each finger holding steady (choice, [Wiertlewski 2012] order)
  double finger_damping_N_s_per_m = 1.0;  ///< c_f (choice)
  double max_torque_N_m = 2.2e-3;         ///< continuous motor torque (section 4.4.1.5)
  double static_opening_tip_m = 10e-3;    ///< Table 4.8
  double total_mass_kg = 39e-3;           ///< Table 4.8: the moving masses must fit in it

  template <class V>
  void visit(V& v) {
    v("motor_inertia_kg_m2", motor_inertia_kg_m2);
    v("motor_damping_N_m_s", motor_damping_N_m_s);
    v("coupling_inertia_kg_m2", coupling_inertia_kg_m2);
    v("coupling_stiffness_N_m", coupling_stiffness_N_m);
    v("coupling_damping_N_m_s", coupling_damping_N_m_s);
    v("screw_inertia_kg_m2", screw_inertia_kg_m2);
    v("screw_torsion_stiffness_N_m", screw_torsion_stiffness_N_m);
    v("screw_torsion_damping_N_m_s", screw_torsion_damping_N_m_s);
    v("lead_m", lead_m);
    v("screw_mass_kg", screw_mass_kg);
    v("axial_stiffness_N_per_m", axial_stiffness_N_per_m);
    v("axial_damping_N_s_per_m", axial_damping_N_s_per_m);
    v("support_mass_kg", support_mass_kg);
    v("support_stiffness_N_per_m", support_stiffness_N_per_m);
    v("support_damping_N_s_per_m", support_damping_N_s_per_m);
    v("transmission_ratio", transmission_ratio);
    v("lever_mass_kg", lever_mass_kg);
    v("lever_stiffness_N_per_m", lever_stiffness_N_per_m);
    v("lever_damping_N_s_per_m", lever_damping_N_s_per_m);
    v("clamping_stiffness_N_per_m", clamping_stiffness_N_per_m);
    v("clamping_damping_N_s_per_m", clamping_damping_N_s_per_m);
    v("tip_mass_kg", tip_mass_kg);
    v("tip_stiffness_N_per_m", tip_stiffness_N_per_m);
    v("tip_damping_N_s_per_m", tip_damping_N_s_per_m);
    v("finger_stiffness_N_per_m", finger_stiffness_N_per_m);
    v("finger_damping_N_s_per_m", finger_damping_N_s_per_m);
    v("max_torque_N_m", max_torque_N_m);
    v("static_opening_tip_m", static_opening_tip_m);
    v("total_mass_kg", total_mass_kg);
  }
  /// Throws InvalidParams: masses, inertias, stiffnesses, lead, ratio and torque > 0; dampings
  /// >= 0 (finger stiffness >= 0: the tweezers may lie free); moving masses within total_mass_kg.
  void validate() const;

  /// R_bs = lead / 2 pi [m/rad].
  double screw_ratio() const;
  /// Lever (finger-contact) displacement per motor angle at rest, R_ss R_bs [m/rad].
  double lever_per_motor_rad() const { return transmission_ratio * screw_ratio(); }
  /// Motor torque producing a force F on each finger (virtual work over both levers, lossless):
  /// T = 2 F R_ss R_bs.
  double torque_for_finger_force(double force_N) const { return 2.0 * force_N * lever_per_motor_rad(); }
};

constexpr int kDofs = 7;
constexpr int kStates = 2 * kDofs;
constexpr int kInputs = 3;
using Mat7 = Eigen::Matrix<double, kDofs, kDofs>;
using Vec7 = Eigen::Matrix<double, kDofs, 1>;
using Mat14 = Eigen::Matrix<double, kStates, kStates>;
using Vec14 = Eigen::Matrix<double, kStates, 1>;
using InputMat = Eigen::Matrix<double, kDofs, kInputs>;
using Input = Eigen::Matrix<double, kInputs, 1>;

/// Indices of the coordinates and inputs.
enum Dof : int { kThetaM = 0, kThetaCp, kThetaBs, kXBs, kXSs, kXL, kXCl };
enum InputIndex : int { kTorque = 0, kFingerForce, kTipForce };

/// M, C, K and the input matrix of eq. 4.6 as derived from the energies.
struct MechanicalMatrices {
  Mat7 M, C, K;
  InputMat B;  ///< generalized forces = B u
};
MechanicalMatrices assemble(const TeleTweezParams& p);

/// State of the model: positions and velocities of the 7 coordinates.
struct TeleTweezState {
  Vec7 q = Vec7::Zero();
  Vec7 v = Vec7::Zero();
};

/// Total mechanical energy T + V [J].
double energy(const MechanicalMatrices& m, const TeleTweezState& s);

/// The model discretized exactly (zero-order hold on the inputs) at a fixed step, for real-time
/// use: configure once, then step() costs one 14x14 and one 14x3 product and never allocates.
class TeleTweez {
 public:
  /// Validates `params` and discretizes at `dt_s` (matrix exponential).
  TeleTweez(const TeleTweezParams& params, double dt_s);

  const TeleTweezParams& params() const { return params_; }
  const MechanicalMatrices& matrices() const { return mech_; }
  double dt() const { return dt_; }
  /// Continuous state-space x' = A x + Bc u with x = [q; v].
  const Mat14& A() const { return a_; }
  const Eigen::Matrix<double, kStates, kInputs>& Bc() const { return bc_; }

  /// Advances `s` by dt with the input held constant. Allocation-free, noexcept.
  void step(TeleTweezState& s, const Input& u) const noexcept;
  /// Accelerations q'' for a state and input (M^-1 (B u - C v - K q)).
  Vec7 acceleration(const TeleTweezState& s, const Input& u) const noexcept;
  /// Finger-contact acceleration x_l'' [m/s^2] (what the accelerometer of Fig. 4.24 reads).
  double finger_acceleration(const TeleTweezState& s, const Input& u) const noexcept;
  /// Opening between the tips [m]: static opening minus twice the tip closing.
  double tip_opening(const TeleTweezState& s) const noexcept {
    return params_.static_opening_tip_m - 2.0 * s.q[kXCl];
  }

  /// Analytic frequency response from input `input` to the finger-contact acceleration, at f [Hz].
  std::complex<double> finger_acceleration_frf(double f_Hz, int input = kTorque) const;

 private:
  TeleTweezParams params_;
  double dt_;
  MechanicalMatrices mech_;
  Mat7 minv_;
  Mat14 a_, ad_;
  Eigen::Matrix<double, kStates, kInputs> bc_, bd_;
};

}  // namespace mc::tweezers
