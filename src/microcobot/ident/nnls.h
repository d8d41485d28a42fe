#pragma once
/// @file
/// Nonnegative least squares: min ||A x - b||_2 subject to x >= 0, by the active-set
/// algorithm of Lawson and Hanson (1974, ch. 23), the method of scipy.optimize.nnls. Used
/// for the Prandtl-Ishlinskii weights of the stick-slip hysteresis (thesis §2.5.1), which
/// must be nonnegative for the operator to stay monotone.

#include <Eigen/Dense>

namespace mc::ident {

struct NnlsResult {
  Eigen::VectorXd x;         ///< the solution, all entries >= 0
  double residual_norm = 0;  ///< ||A x - b||_2
  int iterations = 0;
};

/// Solves min ||A x - b|| with x >= 0. Throws InvalidParams when the sizes disagree or a
/// value is not finite, ComputationFailed when the iteration limit (default 3 n) is reached.
NnlsResult nnls(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, int max_iterations = 0);

}  // namespace mc::ident
