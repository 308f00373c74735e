// Corotational stiffness (fem/elastic_tet_force.h, CorotationalTangent): the consistent
// tangent is the derivative of the corotational force, symmetric, in tension and in
// compression; the warped one is not the derivative; the definite fallback is the warped one.

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "fem/box_mesh.h"
#include "fem/elastic_tet_force.h"
#include "fem_test_util.h"

namespace sedbridge::fem {
namespace {

struct Assembled {
  Eigen::VectorXd force_N;
  Eigen::SparseMatrix<double> stiffness;
};

class CorotationalTangentTest : public ::testing::Test {
 protected:
  CorotationalTangentTest() : mesh_(MakeBoxMesh({0.004, 0.004, 0.006}, {2, 2, 3}, testing::Skin(1e5, 0.45))) {
    rest_.resize(3 * mesh_.num_nodes());
    for (int i = 0; i < mesh_.num_nodes(); ++i) rest_.segment<3>(3 * i) = mesh_.rest_positions_m.col(i);
  }

  // Positions F0 X plus noise of `noise_m` per coordinate.
  Eigen::VectorXd Deformed(const Eigen::Matrix3d& F0, double noise_m, unsigned seed) const {
    std::mt19937 rng(seed);
    std::normal_distribution<double> n(0.0, noise_m);
    Eigen::VectorXd x(rest_.size());
    for (int i = 0; i < mesh_.num_nodes(); ++i) {
      x.segment<3>(3 * i) = F0 * mesh_.rest_positions_m.col(i);
      for (int k = 0; k < 3; ++k) x[3 * i + k] += n(rng);
    }
    return x;
  }

  Assembled Assemble(CorotationalTangent tangent, const Eigen::VectorXd& x) {
    ElasticTetForce elastic(mesh_, ElasticFormulation::kCorotational);
    elastic.set_corotational_tangent(tangent);
    std::vector<std::pair<int, int>> pairs;
    elastic.AppendCoupledNodes(pairs);
    SystemMatrix matrix;
    matrix.Build(mesh_.num_nodes(), pairs);
    elastic.BindMatrix(matrix);
    matrix.SetZero();
    JacobianSink sink{&matrix, 1.0, 0.0};
    const Eigen::VectorXd v = Eigen::VectorXd::Zero(x.size());
    Assembled out{Eigen::VectorXd::Zero(x.size()), {}};
    // Two evaluations: the second starts each element's rotation from a converged one.
    elastic.AddForce({x, v, 0.0, false}, out.force_N, nullptr);
    out.force_N.setZero();
    elastic.AddForce({x, v, 0.0, false}, out.force_N, &sink);
    out.stiffness = matrix.csr();
    return out;
  }

  Eigen::VectorXd Force(const Eigen::VectorXd& x) { return Assemble(CorotationalTangent::kWarped, x).force_N; }

  // Relative error of K u against the central difference -(f(x+u) - f(x-u)) / 2.
  double TangentError(CorotationalTangent tangent, const Eigen::VectorXd& x, const Eigen::VectorXd& u) {
    const Eigen::VectorXd df = -(Force(x + u) - Force(x - u)) / 2.0;
    const Eigen::VectorXd ku = Assemble(tangent, x).stiffness * u;
    return (ku - df).norm() / df.norm();
  }

  TetMesh mesh_;
  Eigen::VectorXd rest_;
};

Eigen::Matrix3d Rotation(double angle_rad, const Eigen::Vector3d& axis) {
  return Eigen::AngleAxisd(angle_rad, axis.normalized()).toRotationMatrix();
}

TEST_F(CorotationalTangentTest, ConsistentTangentIsTheForceDerivativeUnderTension) {
  // Rotated 0.6 rad and stretched in every direction: every twist stiffness is positive, so
  // nothing is clamped and the consistent tangent is exact.
  const Eigen::Matrix3d F0 = Rotation(0.6, {1, 2, 3}) * Eigen::Vector3d(1.10, 1.05, 1.08).asDiagonal();
  const Eigen::VectorXd x = Deformed(F0, 2e-5, 1);
  std::mt19937 rng(2);
  std::normal_distribution<double> n(0.0, 1e-8);
  Eigen::VectorXd u(x.size());
  for (int k = 0; k < u.size(); ++k) u[k] = n(rng);
  const double consistent = TangentError(CorotationalTangent::kConsistent, x, u);
  const double warped = TangentError(CorotationalTangent::kWarped, x, u);
  EXPECT_LT(consistent, 1e-6) << "warped " << warped;
  EXPECT_GT(warped, 1e-3);  // the warped tangent misses the rotation's derivative
}

TEST_F(CorotationalTangentTest, ConsistentTangentIsSymmetric) {
  const Eigen::Matrix3d F0 = Rotation(0.4, {0, 1, 1}) * Eigen::Vector3d(1.2, 0.9, 1.05).asDiagonal();
  const Eigen::SparseMatrix<double> K = Assemble(CorotationalTangent::kConsistent, Deformed(F0, 1e-4, 3)).stiffness;
  const Eigen::SparseMatrix<double> Kt = K.transpose();
  EXPECT_LT((K - Kt).norm(), 1e-12 * K.norm());
}

TEST_F(CorotationalTangentTest, CompressionGivesNegativeTwistsAndTheDefiniteFallbackIsTheWarpedTangent) {
  // Stretched 15 % along x, compressed 15 % along z (volume kept), rotated, noisy: the
  // (x, y) twist stiffness is positive, the (y, z) one negative. The consistent tangent is
  // still the force derivative, and can lower the warped stiffness in some direction;
  // UseDefiniteJacobian(true) gives back exactly the warped matrix.
  const Eigen::Matrix3d F0 = Rotation(0.5, {1, 0, 1}) * Eigen::Vector3d(1.15, 1.0, 0.85).asDiagonal();
  const Eigen::VectorXd x = Deformed(F0, 1e-5, 4);
  std::mt19937 rng(5);
  std::normal_distribution<double> n(0.0, 1e-8);
  Eigen::VectorXd u(x.size());
  for (int k = 0; k < u.size(); ++k) u[k] = n(rng);
  EXPECT_LT(TangentError(CorotationalTangent::kConsistent, x, u), 1e-6);

  const Eigen::SparseMatrix<double> warped = Assemble(CorotationalTangent::kWarped, x).stiffness;
  const Eigen::SparseMatrix<double> diff = Assemble(CorotationalTangent::kConsistent, x).stiffness - warped;
  double lowest = 0, highest = 0;
  std::normal_distribution<double> m;
  for (int trial = 0; trial < 50; ++trial) {
    for (int k = 0; k < u.size(); ++k) u[k] = m(rng);
    const double q = u.dot(diff * u) / u.squaredNorm();
    lowest = std::min(lowest, q);
    highest = std::max(highest, q);
  }
  EXPECT_LT(lowest, 0.0);
  EXPECT_GT(highest, 0.0);

  ElasticTetForce elastic(mesh_, ElasticFormulation::kCorotational);
  EXPECT_FALSE(elastic.UseDefiniteJacobian(true));  // warped: nothing to switch
  elastic.set_corotational_tangent(CorotationalTangent::kConsistent);
  EXPECT_TRUE(elastic.UseDefiniteJacobian(true));
  std::vector<std::pair<int, int>> pairs;
  elastic.AppendCoupledNodes(pairs);
  SystemMatrix matrix;
  matrix.Build(mesh_.num_nodes(), pairs);
  elastic.BindMatrix(matrix);
  matrix.SetZero();
  JacobianSink sink{&matrix, 1.0, 0.0};
  const Eigen::VectorXd v = Eigen::VectorXd::Zero(x.size());
  Eigen::VectorXd f = Eigen::VectorXd::Zero(x.size());
  elastic.AddForce({x, v, 0.0, false}, f, nullptr);
  elastic.AddForce({x, v, 0.0, false}, f, &sink);
  const Eigen::SparseMatrix<double> definite = matrix.csr();
  EXPECT_LT((definite - warped).norm(), 1e-12 * warped.norm());
}

}  // namespace
}  // namespace sedbridge::fem
