#include "microcobot/ident/nnls.h"

#include <gtest/gtest.h>

#include "microcobot/core/error.h"
#include "microcobot/core/rng.h"

namespace mc::ident {
namespace {

TEST(Nnls, EqualsLeastSquaresWhenTheSolutionIsPositive) {
  mc::Rng rng(3);
  Eigen::MatrixXd a(30, 5);
  for (Eigen::Index i = 0; i < a.size(); ++i) a.data()[i] = rng.normal();
  const Eigen::VectorXd x_true = (Eigen::VectorXd(5) << 1.0, 2.0, 0.5, 3.0, 0.1).finished();
  const Eigen::VectorXd b = a * x_true;
  const auto r = nnls(a, b);
  EXPECT_LT((r.x - x_true).norm(), 1e-10);
  EXPECT_LT(r.residual_norm, 1e-10);
}

TEST(Nnls, SatisfiesTheKktConditions) {
  mc::Rng rng(8);
  Eigen::MatrixXd a(20, 8);
  Eigen::VectorXd b(20);
  for (Eigen::Index i = 0; i < a.size(); ++i) a.data()[i] = rng.normal();
  for (Eigen::Index i = 0; i < b.size(); ++i) b(i) = rng.normal();
  const auto r = nnls(a, b);
  const Eigen::VectorXd grad = a.transpose() * (b - a * r.x);  // negative gradient / 2
  int zeros = 0;
  for (Eigen::Index j = 0; j < 8; ++j) {
    EXPECT_GE(r.x(j), 0.0);
    if (r.x(j) > 0) {
      EXPECT_NEAR(grad(j), 0.0, 1e-10);  // free variables: stationary
    } else {
      EXPECT_LE(grad(j), 1e-10);  // bound variables: pushing up would not help
      ++zeros;
    }
  }
  EXPECT_GT(zeros, 0);  // random data: some constraints are active
}

TEST(Nnls, KnownSmallProblemAndErrors) {
  // min ||[1 0; 0 1] x - (-1, 2)|| with x >= 0 is x = (0, 2).
  const auto r = nnls(Eigen::Matrix2d::Identity(), Eigen::Vector2d(-1.0, 2.0));
  EXPECT_DOUBLE_EQ(r.x(0), 0.0);
  EXPECT_NEAR(r.x(1), 2.0, 1e-15);
  EXPECT_NEAR(r.residual_norm, 1.0, 1e-15);
  EXPECT_THROW(nnls(Eigen::Matrix2d::Identity(), Eigen::Vector3d::Ones()), InvalidParams);
}

}  // namespace
}  // namespace mc::ident
