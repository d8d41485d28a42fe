#pragma once
/// @file
/// Separable nonlinear least squares (variable projection) for the modal fits of thesis
/// §2.5.2.1: the measured response is y ~ Phi(theta) c, where the columns of Phi are simulated
/// responses that depend nonlinearly on theta (frequencies, dampings) and c are amplitudes that
/// enter linearly. For each theta, c is the linear least-squares solution, and Levenberg-Marquardt
/// (Eigen unsupported, numerical Jacobian) minimises the projected residual over theta.

#include <functional>

#include <Eigen/Dense>

namespace mc::stickslip {

struct VarProResult {
  Eigen::VectorXd theta;   ///< nonlinear parameters at the optimum
  Eigen::VectorXd coef;    ///< linear coefficients at the optimum
  Eigen::VectorXd fitted;  ///< Phi(theta) coef
  double rms = 0.0;        ///< RMS residual
  int evaluations = 0;     ///< residual evaluations
};

/// The basis Phi(theta): one column per linear coefficient, one row per sample.
using BasisFn = std::function<Eigen::MatrixXd(const Eigen::VectorXd& theta)>;

/// Minimises |y - Phi(theta) c|^2 over theta (from theta0) and c. Throws mc::ComputationFailed
/// if the basis turns non-finite at the start.
VarProResult fit_varpro(const BasisFn& basis, const Eigen::VectorXd& y, const Eigen::VectorXd& theta0,
                        int max_evaluations = 400);

}  // namespace mc::stickslip
