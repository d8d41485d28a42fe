#pragma once
/// @file
/// The dual-stage haptic interface as a plant (thesis §3.4.1, Fig. 3.9, eq. 3.4): the
/// 4-mass model in the handle's y axis driven by the Pantograph motors (f_m on the motor
/// windings m_2) and by the Haptuator (a force pair f_v between its moving magnet m_v and
/// the handle m_h), extended by two modes of the Pantograph's linkage that hang off the force
/// path (side branches on m_2 and m_1, which give Fig. 3.10 its antiresonances; docs/concepts/dual-stage.md),
/// with the Haptuator's coil dynamics and the end stops of its magnet (stroke saturation).
/// Output: the handle's acceleration, what the accelerometer measures.

#include <complex>

#include <Eigen/Dense>

#include "microcobot/core/params.h"

namespace mc::haptics {

/// Parameters of the dual-stage plant. The thesis gives no values; the
/// defaults are chosen (docs/parameters.md) so that the Pantograph channel is flat (+-1 dB)
/// from 40 to 200 Hz, has a damped antiresonance just above 200 Hz, a damped resonance near
/// 300 Hz and a sharp antiresonance/resonance pair near 800 Hz (Fig. 3.10), and the Haptuator
/// channel matches eq. 3.6 within +-1 dB on 100-1000 Hz (Fig. 3.11). Eq. 3.4 as printed has
/// no antiresonance on the Pantograph path besides the magnet's (docs/errata.md): the two
/// linkage modes m_p (on m_2) and m_d (on m_1) supply them; a zero mass removes a branch.
struct DualStagePlantParams {
  // Masses (Table 3.3).
  double m_h_kg = 0.250;    ///< terminal assembly: handle, Haptuator housing, accelerometer, finger pad
  double m_v_kg = 0.003;    ///< Haptuator moving magnet
  double m_1_kg = 2.19e-4;  ///< apparent mass of the distal links
  double m_2_kg = 3.70e-3;  ///< apparent mass of the motor windings
  // Stiffnesses and dampings (Table 3.3).
  double k_f_N_per_m = 228.0;   ///< finger stiffness [Wiertlewski 2012]
  double b_f_Ns_per_m = 35.7;   ///< finger damping
  double k_v_N_per_m = 537.5;   ///< Haptuator membrane (suspension) stiffness
  double b_v_Ns_per_m = 1.52;   ///< Haptuator membrane damping
  double k_1_N_per_m = 2.83e3;  ///< distal links and the terminal assembly's mount (viscous above ~22 Hz)
  double b_1_Ns_per_m = 20.2;   ///< their damping
  double k_2_N_per_m = 1.20e5;  ///< proximal links
  double b_2_Ns_per_m = 0.149;  ///< their damping
  // Linkage modes off the force path (extension of eq. 3.4, docs/concepts/dual-stage.md): each a modal mass
  // on a spring-damper hung from a node of the chain; it blocks that node at its own frequency (antiresonance
  // of f_m -> y_h'') and adds a resonance above it. 0 kg removes the branch.
  double m_p_kg = 3.26e-4;       ///< proximal links' mode, hung from the motor node m_2 (~233 Hz)
  double k_p_N_per_m = 699.0;    ///< its stiffness
  double b_p_Ns_per_m = 0.0503;  ///< its damping
  double m_d_kg = 1.27e-3;       ///< distal links' bending mode, hung from m_1 (light damping, ~764 Hz)
  double k_d_N_per_m = 2.93e4;   ///< its stiffness
  double b_d_Ns_per_m = 0.0196;  ///< its damping
  // Haptuator electrical dynamics: a current amplifier (transconductance g, PI current loop
  // k_p, k_i) drives the coil: L di/dt = v - R i - Bl (dy_v - dy_h),
  // v = k_p (g u - i) + k_i int (g u - i), f_v = Bl i. The loop's closed-loop response
  // (k_p s + k_i) / (L s^2 + (R + k_p) s + k_i) has the form of eq. 3.6.
  double amp_gain_A_per_V = 3.512e-2;  ///< transconductance g of the amplifier
  double coil_R_ohm = 6.0;             ///< coil resistance
  double coil_L_H = 16.9e-3;           ///< inductance seen by the amplifier (coil and output filter)
  double loop_kp_V_per_A = 30.07;      ///< current loop proportional gain
  double loop_ki_V_per_As = 7.705e4;   ///< current loop integral gain
  double bl_N_per_A = 1.0;             ///< force factor
  // Stroke saturation: end stops on the magnet's travel relative to the handle.
  double stroke_m = 0.3e-3;       ///< free travel of the magnet each side of rest
  double stop_k_N_per_m = 2.0e5;  ///< end-stop contact stiffness
  double stop_b_Ns_per_m = 2.0;   ///< end-stop contact damping
  // Time stepping.
  double dt_s = 1.0e-4;  ///< step of step() (the 10 kHz loop)
  int substeps = 8;      ///< internal substeps per step (end-stop contact resolution)

  template <class V>
  void visit(V& v) {
    v("m_h_kg", m_h_kg);
    v("m_v_kg", m_v_kg);
    v("m_1_kg", m_1_kg);
    v("m_2_kg", m_2_kg);
    v("k_f_N_per_m", k_f_N_per_m);
    v("b_f_Ns_per_m", b_f_Ns_per_m);
    v("k_v_N_per_m", k_v_N_per_m);
    v("b_v_Ns_per_m", b_v_Ns_per_m);
    v("k_1_N_per_m", k_1_N_per_m);
    v("b_1_Ns_per_m", b_1_Ns_per_m);
    v("k_2_N_per_m", k_2_N_per_m);
    v("b_2_Ns_per_m", b_2_Ns_per_m);
    v("m_p_kg", m_p_kg);
    v("k_p_N_per_m", k_p_N_per_m);
    v("b_p_Ns_per_m", b_p_Ns_per_m);
    v("m_d_kg", m_d_kg);
    v("k_d_N_per_m", k_d_N_per_m);
    v("b_d_Ns_per_m", b_d_Ns_per_m);
    v("amp_gain_A_per_V", amp_gain_A_per_V);
    v("coil_R_ohm", coil_R_ohm);
    v("coil_L_H", coil_L_H);
    v("loop_kp_V_per_A", loop_kp_V_per_A);
    v("loop_ki_V_per_As", loop_ki_V_per_As);
    v("bl_N_per_A", bl_N_per_A);
    v("stroke_m", stroke_m);
    v("stop_k_N_per_m", stop_k_N_per_m);
    v("stop_b_Ns_per_m", stop_b_Ns_per_m);
    v("dt_s", dt_s);
    v("substeps", substeps);
  }
  /// Throws InvalidParams naming the field if a value is out of range.
  void validate() const;
};

/// Inputs of the plant.
enum class Channel {
  kPantograph,  ///< f_m [N], the low-frequency channel
  kHaptuator,   ///< u [V], the high-frequency channel
};

/// State of the plant: x = [y_h, y_v, y_1, y_2, y_p, y_d, dy_h, dy_v, dy_1, dy_2, dy_p, dy_d, i_coil, q]
/// with y_p, y_d the linkage modes' masses and q the current loop integral of (g u - i) (SI).
struct DualStagePlantState {
  Eigen::Matrix<double, 14, 1> x = Eigen::Matrix<double, 14, 1>::Zero();
  double accel_m_s2 = 0.0;  ///< handle acceleration at the end of the last step
};

/// The dual-stage plant of eq. 3.4 with two linkage modes, the Haptuator coil and end stops.
///
/// Linear part (stops open): M Y'' + C Y' + K Y = [-f_v, f_v, 0, f_m, 0, 0]^T with Y = [y_h, y_v, y_1, y_2,
/// y_p, y_d]: eq. 3.4's M, C, K bordered by m_p (k_p, b_p to y_2) and m_d (k_d, b_d to y_1), f_v = -Bl i,
/// L i' = k_p (g u - i) + k_i q - R i + Bl (y_v' - y_h'), q' = g u - i. The end stops add a force pair
/// f_s = -k_s (z - sign(z) s) - b_s z' on the magnet (and its opposite on the handle) while
/// |z| = |y_v - y_h| exceeds the stroke s: the saturation that spoils the Haptuator's
/// response below about 100 Hz (Fig. 3.11).
class DualStagePlant {
 public:
  static constexpr int kMasses = 6;  ///< y_h, y_v, y_1, y_2 (eq. 3.4), y_p, y_d (linkage modes)
  static constexpr int kStates = 2 * kMasses + 2;
  // Indices into the state vector.
  static constexpr int kYh = 0, kYv = 1, kVh = kMasses, kVv = kMasses + 1, kVp = kMasses + 4,
                       kVd = kMasses + 5;
  static constexpr int kCoil = 2 * kMasses, kLoop = 2 * kMasses + 1;
  using StateVector = Eigen::Matrix<double, kStates, 1>;
  using StateMatrix = Eigen::Matrix<double, kStates, kStates>;
  /// Inputs: [f_m (N), u (V), f_s (N, end-stop pair)].
  using InputMatrix = Eigen::Matrix<double, kStates, 3>;

  /// Validates the parameters and discretises the linear part (ZOH over dt/substeps).
  explicit DualStagePlant(const DualStagePlantParams& params);

  const DualStagePlantParams& params() const { return params_; }

  /// Continuous-time matrices of the linear part (stops open): x' = A x + B [f_m, u, f_s].
  const StateMatrix& a() const { return a_; }
  const InputMatrix& b() const { return b_; }

  /// Frequency response of the linear part from `channel` to the handle's acceleration at
  /// `f_Hz`: (m/s^2)/N for the Pantograph, (m/s^2)/V for the Haptuator.
  std::complex<double> frf(Channel channel, double f_Hz) const;

  /// Total mass moving with the handle at low frequency (the Pantograph channel's flat
  /// gain is 1/total_mass above the finger mode), linkage modes included.
  double total_mass_kg() const;

  /// One step of dt_s with inputs held (zero-order hold): f_m [N], u [V]. Updates
  /// state.accel_m_s2. Never allocates. Throws ComputationFailed on divergence.
  void step(DualStagePlantState& state, double f_m_N, double u_V) const;
  /// step() for the real-time path: returns false (state untouched) instead of throwing.
  bool try_step(DualStagePlantState& state, double f_m_N, double u_V) const noexcept;

  /// Handle acceleration of `state` under inputs (the accelerometer's reading).
  double acceleration(const DualStagePlantState& state, double f_m_N, double u_V) const;

  /// Magnet travel relative to the handle, y_v - y_h [m].
  static double magnet_travel(const DualStagePlantState& state) { return state.x(kYv) - state.x(kYh); }

 private:
  double stop_force(const StateVector& x) const;

  DualStagePlantParams params_;
  StateMatrix a_;
  InputMatrix b_;
  StateMatrix ad_;  // exp(A h), h = dt/substeps
  InputMatrix bd_;  // int_0^h exp(A t) dt B
};

}  // namespace mc::haptics
