// Patch test: a uniform strain imposed on every node must give zero internal force at
// interior nodes and the analytic SED in every element.

#include <gtest/gtest.h>

#include "fem/box_mesh.h"
#include "fem/elastic_tet_force.h"
#include "fem/strain_energy_density.h"
#include "fem_test_util.h"

namespace sedbridge::fem {
namespace {

class PatchTest : public ::testing::TestWithParam<ElasticFormulation> {};

TEST_P(PatchTest, UniformStrainIsReproducedExactly) {
  const auto mat = testing::Skin(1.2e5, 0.45);
  const TetMesh mesh = MakeBoxMesh({0.004, 0.005, 0.006}, {4, 5, 3}, mat);
  Eigen::Matrix3d eps;
  eps << 0.010, 0.002, -0.001, 0.002, -0.004, 0.003, -0.001, 0.003, 0.006;
  const Eigen::Matrix3d F = Eigen::Matrix3d::Identity() + eps;  // symmetric: no rotation
  Eigen::VectorXd x(3 * mesh.num_nodes()), v = Eigen::VectorXd::Zero(3 * mesh.num_nodes());
  for (int i = 0; i < mesh.num_nodes(); ++i) x.segment<3>(3 * i) = F * mesh.rest_positions_m.col(i) + Eigen::Vector3d(1e-3, 0, 0);

  ElasticTetForce elastic(mesh, GetParam());
  Eigen::VectorXd f = Eigen::VectorXd::Zero(x.size());
  elastic.AddForce({x, v, 0.0, false}, f, nullptr);
  const Eigen::Vector3d lo = mesh.rest_positions_m.rowwise().minCoeff(), hi = mesh.rest_positions_m.rowwise().maxCoeff();
  double max_interior = 0, max_any = 0;
  for (int i = 0; i < mesh.num_nodes(); ++i) {
    const Eigen::Vector3d p = mesh.rest_positions_m.col(i);
    const bool boundary = ((p - lo).array().abs() < 1e-12).any() || ((p - hi).array().abs() < 1e-12).any();
    max_any = std::max(max_any, f.segment<3>(3 * i).norm());
    if (!boundary) max_interior = std::max(max_interior, f.segment<3>(3 * i).norm());
  }
  EXPECT_GT(max_any, 1e-4);                 // boundary nodes carry the traction
  EXPECT_LT(max_interior, 1e-10 * max_any);  // interior nodes are in equilibrium

  const double lambda = mat.lame_lambda_Pa(), mu = mat.lame_mu_Pa();
  const Eigen::Matrix3d sigma = lambda * eps.trace() * Eigen::Matrix3d::Identity() + 2 * mu * eps;
  const double sed = 0.5 * (sigma.array() * eps.array()).sum();
  std::vector<int> all(size_t(mesh.num_nodes()));
  for (int i = 0; i < mesh.num_nodes(); ++i) all[size_t(i)] = i;
  VertexSedEvaluator evaluator(elastic, all);
  Eigen::VectorXd vertex_sed;
  evaluator.Evaluate(x, vertex_sed);
  const double tol = GetParam() == ElasticFormulation::kLinear ? 1e-9 : 1e-6;  // corotational: R^T F vs F
  for (Eigen::Index k = 0; k < evaluator.element_sed_Pa().size(); ++k)
    EXPECT_NEAR(evaluator.element_sed_Pa()[k], sed, tol * sed);
  EXPECT_NEAR(vertex_sed.maxCoeff(), sed, tol * sed);
}

INSTANTIATE_TEST_SUITE_P(Formulations, PatchTest,
                         ::testing::Values(ElasticFormulation::kLinear, ElasticFormulation::kCorotational),
                         [](const auto& info) {
                           return info.param == ElasticFormulation::kLinear ? "Linear" : "Corotational";
                         });

}  // namespace
}  // namespace sedbridge::fem
