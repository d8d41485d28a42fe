#include "microcobot/ident/nnls.h"

#include <cmath>
#include <limits>
#include <vector>

#include "microcobot/core/error.h"

namespace mc::ident {

NnlsResult nnls(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, int max_iterations) {
  require(A.rows() == b.size(), "b", "must have one value per row of A", static_cast<double>(b.size()));
  require(A.allFinite() && b.allFinite(), "A", "values must be finite");
  const Eigen::Index n = A.cols();
  if (max_iterations <= 0) max_iterations = static_cast<int>(3 * std::max<Eigen::Index>(n, 10));
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  std::vector<bool> passive(static_cast<std::size_t>(n), false);
  const double tol = 10.0 * std::numeric_limits<double>::epsilon() * A.cwiseAbs().maxCoeff() *
                     static_cast<double>(std::max(A.rows(), n));
  auto solve_passive = [&](Eigen::VectorXd& z) {
    std::vector<Eigen::Index> idx;
    for (Eigen::Index j = 0; j < n; ++j) {
      if (passive[static_cast<std::size_t>(j)]) idx.push_back(j);
    }
    Eigen::MatrixXd ap(A.rows(), static_cast<Eigen::Index>(idx.size()));
    for (std::size_t k = 0; k < idx.size(); ++k) ap.col(static_cast<Eigen::Index>(k)) = A.col(idx[k]);
    const Eigen::VectorXd zp = ap.colPivHouseholderQr().solve(b);
    z = Eigen::VectorXd::Zero(n);
    for (std::size_t k = 0; k < idx.size(); ++k) z(idx[k]) = zp(static_cast<Eigen::Index>(k));
  };
  int iter = 0;
  Eigen::VectorXd w = A.transpose() * (b - A * x);
  while (true) {
    // Outer loop: move the most promising active variable into the passive set.
    Eigen::Index best = -1;
    double best_w = tol;
    for (Eigen::Index j = 0; j < n; ++j) {
      if (!passive[static_cast<std::size_t>(j)] && w(j) > best_w) {
        best_w = w(j);
        best = j;
      }
    }
    if (best < 0) break;
    passive[static_cast<std::size_t>(best)] = true;
    Eigen::VectorXd z;
    while (true) {
      if (++iter > max_iterations)
        throw ComputationFailed("nnls: no convergence in " + std::to_string(max_iterations) + " iterations");
      solve_passive(z);
      bool feasible = true;
      for (Eigen::Index j = 0; j < n; ++j) {
        if (passive[static_cast<std::size_t>(j)] && z(j) <= 0.0) feasible = false;
      }
      if (feasible) break;
      // Inner loop: step towards z until the first passive variable hits zero, drop it.
      double alpha = std::numeric_limits<double>::infinity();
      for (Eigen::Index j = 0; j < n; ++j) {
        if (passive[static_cast<std::size_t>(j)] && z(j) <= 0.0)
          alpha = std::min(alpha, x(j) / (x(j) - z(j)));
      }
      x += alpha * (z - x);
      for (Eigen::Index j = 0; j < n; ++j) {
        if (passive[static_cast<std::size_t>(j)] && x(j) <= tol) {
          passive[static_cast<std::size_t>(j)] = false;
          x(j) = 0.0;
        }
      }
    }
    x = z;
    w = A.transpose() * (b - A * x);
  }
  return {x, (A * x - b).norm(), iter};
}

}  // namespace mc::ident
