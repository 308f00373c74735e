#include "render/boxed_damped_step.h"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>

namespace sedbridge::render {
namespace {

double Model(const Eigen::MatrixXd& H, const Eigen::VectorXd& g, const Eigen::VectorXd& d) {
  return g.dot(d) + 0.5 * d.dot(H * d);
}

TEST(BoxedDampedStep, InsideTheBoxItIsTheNewtonStep) {
  Eigen::MatrixXd H(2, 2);
  H << 2, 0.5, 0.5, 1;
  const Eigen::VectorXd g = Eigen::Vector2d(-0.2, 0.1), u = Eigen::Vector2d(1, 1), box = Eigen::Vector2d(2, 2);
  const Eigen::VectorXd newton = H.ldlt().solve(-g);
  EXPECT_LE((BoxedDampedStep(H, g, u, box) - newton).norm(), 1e-12);
}

// Two coupled variables; the unconstrained step takes the first below 0. Held at 0, the
// second solves H22 d2 = -(g2 + H21 d1) (1-D, by hand), and the model there is lower than at
// the clipped unconstrained step, which here even raises it.
TEST(BoxedDampedStep, AVariableLeavingTheBoxIsHeldAndTheRestSolvedAgain) {
  Eigen::MatrixXd H(2, 2);
  H << 1, 0.9, 0.9, 1;
  const Eigen::VectorXd g = Eigen::Vector2d(1.0, 0.5), u = Eigen::Vector2d(0.1, 1.0), box = Eigen::Vector2d(5, 5);
  const Eigen::VectorXd newton = H.ldlt().solve(-g);
  ASSERT_LT(u[0] + newton[0], 0);  // the case: the first leaves through 0
  const Eigen::VectorXd d = BoxedDampedStep(H, g, u, box);
  EXPECT_DOUBLE_EQ(u[0] + d[0], 0.0);
  EXPECT_NEAR(d[1], -(g[1] + H(1, 0) * d[0]) / H(1, 1), 1e-12);
  const Eigen::VectorXd clipped = (u + newton).cwiseMax(0.0).cwiseMin(box) - u;
  EXPECT_LT(Model(H, g, d), Model(H, g, clipped));
  EXPECT_LT(Model(H, g, d), 0.0);   // a decrease, as a trial should promise
  EXPECT_GT(Model(H, g, clipped), 0.0);  // the clipped step promised a rise
}

// The box's minimizer (the convex QP's KKT conditions): inside the box the model's gradient
// g + H d vanishes, at 0 it points outward (>= 0), at the upper bound inward (<= 0).
TEST(BoxedDampedStep, ItIsTheMinimizerOnTheBoxWithUpperBoundsToo) {
  Eigen::MatrixXd A = Eigen::MatrixXd::Random(6, 6);
  const Eigen::MatrixXd H = A.transpose() * A + 0.1 * Eigen::MatrixXd::Identity(6, 6);
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::VectorXd g = 10 * Eigen::VectorXd::Random(6);
    const Eigen::VectorXd box = Eigen::VectorXd::Constant(6, 1.0);
    const Eigen::VectorXd u = 0.5 * (Eigen::VectorXd::Random(6).array() + 1).matrix();
    const Eigen::VectorXd d = BoxedDampedStep(H, g, u, box);
    EXPECT_GE((u + d).minCoeff(), -1e-15) << trial;
    EXPECT_LE((u + d).maxCoeff(), 1 + 1e-15) << trial;
    EXPECT_LE(Model(H, g, d), 1e-12) << trial;  // never promises a rise
    const Eigen::VectorXd q = g + H * d, x = u + d;
    for (int a = 0; a < 6; ++a) {
      if (x[a] <= 1e-12) EXPECT_GE(q[a], -1e-9) << trial << " " << a;
      else if (x[a] >= 1 - 1e-12) EXPECT_LE(q[a], 1e-9) << trial << " " << a;
      else EXPECT_NEAR(q[a], 0.0, 1e-9) << trial << " " << a;
    }
  }
}

}  // namespace
}  // namespace sedbridge::render
