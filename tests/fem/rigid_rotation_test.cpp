// A rigid rotation must give zero corotational SED and zero elastic force; plain linear
// FEM does not have this property (it reports spurious strain).

#include <gtest/gtest.h>

#include "fem/box_mesh.h"
#include "fem/elastic_tet_force.h"
#include "fem/strain_energy_density.h"
#include "fem_test_util.h"

namespace sedbridge::fem {
namespace {

TEST(RigidRotation, CorotationalSedIsZeroLinearIsNot) {
  const TetMesh mesh = MakeBoxMesh({0.01, 0.01, 0.01}, {3, 3, 3}, testing::Skin());
  const Eigen::Matrix3d R = Eigen::AngleAxisd(1.1, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  Eigen::VectorXd x(3 * mesh.num_nodes()), v = Eigen::VectorXd::Zero(3 * mesh.num_nodes());
  for (int i = 0; i < mesh.num_nodes(); ++i) x.segment<3>(3 * i) = R * mesh.rest_positions_m.col(i) + Eigen::Vector3d(0.02, 0, -0.01);
  std::vector<int> all(size_t(mesh.num_nodes()));
  for (int i = 0; i < mesh.num_nodes(); ++i) all[size_t(i)] = i;

  ElasticTetForce corot(mesh, ElasticFormulation::kCorotational);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(x.size());
  corot.AddForce({x, v, 0.0, false}, f, nullptr);
  EXPECT_LT(f.cwiseAbs().maxCoeff(), 1e-9);
  VertexSedEvaluator sed(corot, all);
  Eigen::VectorXd vertex_sed;
  sed.Evaluate(x, vertex_sed);
  EXPECT_LT(vertex_sed.cwiseAbs().maxCoeff(), 1e-9);

  ElasticTetForce linear(mesh, ElasticFormulation::kLinear);
  VertexSedEvaluator sed_linear(linear, all);
  sed_linear.Evaluate(x, vertex_sed);
  EXPECT_GT(vertex_sed.minCoeff(), 100.0);  // spurious: ~E * (1 - cos 1.1)^2
}

}  // namespace
}  // namespace sedbridge::fem
