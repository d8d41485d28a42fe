#pragma once
/// @file
/// Linear time-invariant SISO systems: transfer functions and state-space models
/// (continuous when dt = 0, discrete with sample period dt otherwise), conversions,
/// discretisation (zero-order hold, Tustin with optional prewarping, matched z-transform),
/// frequency response and time responses (step, impulse, lsim). Conventions follow
/// scipy.signal: polynomials highest power first; tf2ss gives the controller canonical form;
/// cont2discrete, lsim, step and impulse compute the same numbers.

#include <complex>
#include <optional>
#include <span>
#include <vector>

#include <Eigen/Dense>

#include "microcobot/dsp/zpk.h"

namespace mc::dsp {

/// H(x) = num(x) / den(x), x = s (dt = 0) or z (dt > 0); coefficients highest power first.
class TransferFunction {
 public:
  TransferFunction() : TransferFunction({1.0}, {1.0}) {}
  /// Strips leading zeros. Throws InvalidParams if den is zero, a coefficient is not finite,
  /// the system is improper (deg num > deg den), or dt < 0.
  TransferFunction(std::vector<double> num, std::vector<double> den, double dt = 0.0);
  /// From zeros, poles and gain.
  static TransferFunction from_zpk(const Zpk& zpk, double dt = 0.0);

  const std::vector<double>& num() const { return num_; }
  const std::vector<double>& den() const { return den_; }
  double dt() const { return dt_; }
  bool is_discrete() const { return dt_ > 0.0; }
  std::size_t order() const { return den_.size() - 1; }

  /// H at a complex point x.
  std::complex<double> eval(std::complex<double> x) const;
  /// Frequency response at w (rad/s): H(j w), or H(exp(j w dt)) for a discrete system.
  std::complex<double> response(double w_rad_s) const;
  std::vector<std::complex<double>> poles() const;
  std::vector<std::complex<double>> zeros() const;
  /// H(0) (continuous) or H(1) (discrete); +-inf with a pole there.
  double dc_gain() const;
  /// All poles in the open left half plane (continuous) or inside the unit circle (discrete).
  bool is_stable() const;
  /// The same system with den monic (leading coefficient 1).
  TransferFunction normalized() const;

 private:
  std::vector<double> num_, den_;
  double dt_ = 0.0;
};

/// x' = A x + B u, y = C x + D u (or x[k+1] = A x[k] + B u[k] for dt > 0).
struct StateSpace {
  Eigen::MatrixXd A, B, C, D;
  double dt = 0.0;

  /// Throws InvalidParams if the dimensions do not agree or a value is not finite.
  void validate() const;
  std::size_t states() const { return static_cast<std::size_t>(A.rows()); }
  /// Response from input `in` to output `out` at w (rad/s): C (jwI - A)^-1 B + D.
  std::complex<double> response(double w_rad_s, int in = 0, int out = 0) const;
  std::vector<std::complex<double>> poles() const;
  bool is_stable() const;
};

/// Controller canonical form, as scipy.signal.tf2ss.
StateSpace tf2ss(const TransferFunction& tf);
/// Transfer function from input `in` to output `out` (scipy.signal.ss2tf).
TransferFunction ss2tf(const StateSpace& ss, int in = 0, int out = 0);

/// Roots of a polynomial (highest power first), by the eigenvalues of its companion matrix.
std::vector<std::complex<double>> roots(std::span<const double> poly);
/// Evaluates a polynomial (highest power first) at x (Horner).
std::complex<double> polyval(std::span<const double> poly, std::complex<double> x);

/// Zero-order-hold discretisation: Ad = e^{A dt}, Bd = int_0^dt e^{A t} dt B (the matrix
/// exponential of [[A, B], [0, 0]] dt), as scipy.signal.cont2discrete(method='zoh').
StateSpace c2d_zoh(const StateSpace& ss, double dt);
/// Tustin (bilinear) discretisation, scipy's cont2discrete(method='bilinear'). With
/// `prewarp_rad_s`, the map is exact at that frequency (s = w/tan(w dt/2) (z-1)/(z+1)).
StateSpace c2d_tustin(const StateSpace& ss, double dt, std::optional<double> prewarp_rad_s = {});
/// Matched z-transform: poles and zeros map by z = e^{s dt}, zeros at infinity to z = -1;
/// the gain matches the continuous one at DC, or at w = 0.01 pi/dt when H has a pole or zero
/// at s = 0.
TransferFunction c2d_matched(const TransferFunction& tf, double dt);
/// Inverse of c2d_zoh (matrix logarithm). Throws ComputationFailed when Ad has eigenvalues
/// on the negative real axis (no real logarithm).
StateSpace d2c_zoh(const StateSpace& ss);

enum class Discretization { kZoh, kTustin, kMatched };
/// Discretises a continuous transfer function (prewarp applies to Tustin only).
TransferFunction c2d(const TransferFunction& tf, double dt, Discretization method,
                     std::optional<double> prewarp_rad_s = {});

/// Frequency response at each w (rad/s).
std::vector<std::complex<double>> freqresp(const TransferFunction& tf, std::span<const double> w_rad_s);

/// Response to input samples u at uniformly spaced times t (t[0] = 0 or any start) from
/// state x0 (zero when empty), as scipy.signal.lsim: `interpolate` = true treats u as
/// piecewise linear between samples, false holds each sample (zero-order hold). Discrete
/// systems ignore t and step once per sample. Throws InvalidParams for non-uniform t or
/// sizes that differ; ComputationFailed if the response diverges to non-finite values.
std::vector<double> lsim(const StateSpace& ss, std::span<const double> u, std::span<const double> t,
                         bool interpolate = true, const Eigen::VectorXd& x0 = {});
std::vector<double> lsim(const TransferFunction& tf, std::span<const double> u, std::span<const double> t,
                         bool interpolate = true);
/// Unit step response at times t (scipy.signal.step).
std::vector<double> step(const TransferFunction& tf, std::span<const double> t);
/// Impulse response at times t (scipy.signal.impulse; the D u delta is not included).
std::vector<double> impulse(const TransferFunction& tf, std::span<const double> t);

}  // namespace mc::dsp
