#include "microcobot/stickslip/ident_varpro.h"

#include <cmath>

#include <unsupported/Eigen/NonLinearOptimization>
#include <unsupported/Eigen/NumericalDiff>

#include "microcobot/core/error.h"

namespace mc::stickslip {

namespace {

Eigen::VectorXd solve_coef(const Eigen::MatrixXd& phi, const Eigen::VectorXd& y) {
  return phi.colPivHouseholderQr().solve(y);
}

struct Projected {
  using Scalar = double;
  enum { InputsAtCompileTime = Eigen::Dynamic, ValuesAtCompileTime = Eigen::Dynamic };
  using InputType = Eigen::VectorXd;
  using ValueType = Eigen::VectorXd;
  using JacobianType = Eigen::MatrixXd;

  const BasisFn* basis;
  const Eigen::VectorXd* y;
  int n_theta;
  int* evaluations;

  int inputs() const { return n_theta; }
  int values() const { return static_cast<int>(y->size()); }
  int operator()(const Eigen::VectorXd& theta, Eigen::VectorXd& r) const {
    ++*evaluations;
    const Eigen::MatrixXd phi = (*basis)(theta);
    if (!phi.allFinite()) {
      // Outside the model's domain: a large, finite residual steers LM back.
      r = Eigen::VectorXd::Constant(y->size(), 1e3 * (y->cwiseAbs().maxCoeff() + 1.0));
      return 0;
    }
    r = *y - phi * solve_coef(phi, *y);
    return 0;
  }
};

}  // namespace

VarProResult fit_varpro(const BasisFn& basis, const Eigen::VectorXd& y, const Eigen::VectorXd& theta0,
                        int max_evaluations) {
  const Eigen::MatrixXd phi0 = basis(theta0);
  if (!phi0.allFinite()) throw ComputationFailed("modal fit: the initial model response is not finite");
  VarProResult out;
  Projected f{&basis, &y, static_cast<int>(theta0.size()), &out.evaluations};
  Eigen::NumericalDiff<Projected, Eigen::Central> nd(f, 1e-10);
  Eigen::LevenbergMarquardt<Eigen::NumericalDiff<Projected, Eigen::Central>> lm(nd);
  lm.parameters.maxfev = max_evaluations;
  lm.parameters.xtol = 1e-10;
  lm.parameters.ftol = 1e-12;
  Eigen::VectorXd theta = theta0;
  lm.minimize(theta);
  const Eigen::MatrixXd phi = basis(theta);
  if (!phi.allFinite()) throw ComputationFailed("modal fit diverged (non-finite model response)");
  out.theta = theta;
  out.coef = solve_coef(phi, y);
  out.fitted = phi * out.coef;
  out.rms = std::sqrt((y - out.fitted).squaredNorm() / static_cast<double>(y.size()));
  return out;
}

}  // namespace mc::stickslip
