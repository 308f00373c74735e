// Uniaxial compression of a block by a pressure p on its top face, bottom on rollers:
// sigma_zz = -p, epsilon_zz = -p/E, SED = p^2 / (2E) in every element.

#include <gtest/gtest.h>

#include "fem/box_mesh.h"
#include "fem/elastic_tet_force.h"
#include "fem/mesh_topology.h"
#include "fem/simulation.h"
#include "fem/strain_energy_density.h"
#include "fem/surface_traction_force.h"
#include "fem_test_util.h"

namespace sedbridge::fem {
namespace {

struct Case {
  ElasticFormulation formulation;
  const char* solver;
};

class UniaxialCompression : public ::testing::TestWithParam<Case> {};

TEST_P(UniaxialCompression, SedMatchesAnalyticValue) {
  const double E = 1.36e5, nu = 0.48, p = 500.0, h = 0.006;
  const TetMesh mesh = MakeBoxMesh({0.008, 0.008, h}, {4, 4, 3}, testing::Skin(E, nu));
  std::vector<std::unique_ptr<ForceTerm>> terms;
  terms.push_back(std::make_unique<ElasticTetForce>(mesh, GetParam().formulation));
  auto* elastic = static_cast<ElasticTetForce*>(terms.back().get());
  testing::AddRollerSupport(mesh, terms);
  std::vector<Triangle> top;
  for (const Triangle& f : BoundaryFaces(mesh.tets, mesh.rest_positions_m)) {
    bool on_top = true;
    for (int v : f) on_top = on_top && std::abs(mesh.rest_positions_m(2, v) - h) < 1e-12;
    if (on_top) top.push_back(f);
  }
  ASSERT_EQ(top.size(), 32u);
  auto traction = std::make_unique<SurfaceTractionForce>(mesh.rest_positions_m, top);
  Eigen::Matrix3Xd t = Eigen::Matrix3Xd::Zero(3, Eigen::Index(traction->nodes().size()));
  t.row(2).setConstant(-p);
  traction->SetNodalTraction(t);
  EXPECT_NEAR(traction->TotalForce().z(), -p * 0.008 * 0.008, 1e-12);
  terms.push_back(std::move(traction));

  IntegratorSettings settings;
  settings.kind = IntegratorKind::kQuasiStatic;
  settings.newton_iterations = 20;
  Simulation sim(mesh, std::move(terms), settings, MakeLinearSolver(GetParam().solver, PcgSettings{1e-12, 2000}, elastic));
  const StepReport r = sim.Step(1.0);
  EXPECT_TRUE(r.converged);

  std::vector<int> all(size_t(mesh.num_nodes()));
  for (int i = 0; i < mesh.num_nodes(); ++i) all[size_t(i)] = i;
  VertexSedEvaluator sed(*elastic, all);
  Eigen::VectorXd vertex_sed;
  sed.Evaluate(sim.positions_m(), vertex_sed);
  const double expected = p * p / (2 * E);
  // Corotational solves the geometrically nonlinear problem: O(strain) = 0.4 % deviation.
  const double tol = GetParam().formulation == ElasticFormulation::kLinear ? 1e-6 : 1e-2;
  for (Eigen::Index k = 0; k < sed.element_sed_Pa().size(); ++k)
    ASSERT_NEAR(sed.element_sed_Pa()[k], expected, tol * expected) << "element " << k;
  // Top displacement = -p h / E.
  const int top_node = BoxNodeIndex({4, 4, 3}, 2, 2, 3);
  EXPECT_NEAR(sim.positions_m()[3 * top_node + 2] - h, -p * h / E, tol * p * h / E);
}

INSTANTIATE_TEST_SUITE_P(Solvers, UniaxialCompression,
                         ::testing::Values(Case{ElasticFormulation::kLinear, "ldlt"},
                                           Case{ElasticFormulation::kLinear, "pcg_jacobi"},
                                           Case{ElasticFormulation::kCorotational, "ldlt"},
                                           Case{ElasticFormulation::kCorotational, "pcg_warp"}),
                         [](const auto& info) {
                           return std::string(info.param.formulation == ElasticFormulation::kLinear ? "Linear_"
                                                                                                   : "Corotational_") +
                                  info.param.solver;
                         });

}  // namespace
}  // namespace sedbridge::fem
