#include "microcobot/haptics/pantograph.h"

#include <gtest/gtest.h>

#include "microcobot/core/error.h"

namespace mc::haptics {
namespace {

TEST(Pantograph, ForwardInverseRoundTripOverWorkspace) {
  const Pantograph p{PantographParams{}};
  int checked = 0;
  for (double x = -0.06; x <= 0.06; x += 0.01) {
    for (double y = 0.06; y <= 0.20; y += 0.01) {
      const Eigen::Vector2d target(x, y);
      if (!p.in_workspace(target)) continue;
      Eigen::Vector2d q, back;
      ASSERT_TRUE(p.inverse(target, q));
      ASSERT_TRUE(p.forward(q, back));
      EXPECT_NEAR((back - target).norm(), 0.0, 1e-12) << x << "," << y;
      ++checked;
    }
  }
  EXPECT_GT(checked, 40);  // a real planar workspace, not a point
}

TEST(Pantograph, JacobianMatchesFiniteDifferences) {
  const Pantograph p{PantographParams{}};
  for (const Eigen::Vector2d& x :
       {p.workspace_centre(), Eigen::Vector2d(0.03, 0.12), Eigen::Vector2d(-0.04, 0.15)}) {
    Eigen::Vector2d q;
    ASSERT_TRUE(p.inverse(x, q));
    Eigen::Matrix2d j;
    ASSERT_TRUE(p.jacobian(q, j));
    const double h = 1e-7;
    for (int c = 0; c < 2; ++c) {
      Eigen::Vector2d qp = q, qm = q, xp, xm;
      qp(c) += h;
      qm(c) -= h;
      ASSERT_TRUE(p.forward(qp, xp));
      ASSERT_TRUE(p.forward(qm, xm));
      const Eigen::Vector2d fd = (xp - xm) / (2 * h);
      EXPECT_NEAR((j.col(c) - fd).norm(), 0.0, 1e-6 * j.norm());
    }
  }
}

TEST(Pantograph, TorquesDoTheSameVirtualWorkAsTheForce) {
  const Pantograph p{PantographParams{}};
  Eigen::Vector2d q;
  ASSERT_TRUE(p.inverse(Eigen::Vector2d(0.01, 0.14), q));
  const Eigen::Vector2d f(0.3, -1.2);
  Eigen::Vector2d tau;
  ASSERT_TRUE(p.torques(q, f, tau));
  Eigen::Matrix2d j;
  ASSERT_TRUE(p.jacobian(q, j));
  const Eigen::Vector2d dq(1e-3, -2e-3);
  EXPECT_NEAR(tau.dot(dq), f.dot(j * dq), 1e-12);
}

TEST(Pantograph, WorkspaceExcludesUnreachableAndSingularPoints) {
  const Pantograph p{PantographParams{}};
  EXPECT_TRUE(p.in_workspace(p.workspace_centre()));
  const double reach = p.params().proximal_m + p.params().distal_m;
  EXPECT_FALSE(p.in_workspace(Eigen::Vector2d(0.0, reach + 0.01)));  // beyond full stretch
  EXPECT_FALSE(p.in_workspace(Eigen::Vector2d(0.0, 0.0)));           // on the base
  Eigen::Vector2d q;
  EXPECT_FALSE(p.inverse(Eigen::Vector2d(0.0, reach + 0.01), q));
}

TEST(Pantograph, InvalidGeometryIsRejected) {
  PantographParams bad;
  bad.distal_m = -1.0;
  EXPECT_THROW(Pantograph{bad}, InvalidParams);
}

}  // namespace
}  // namespace mc::haptics
