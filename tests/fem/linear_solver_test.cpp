#include "fem/linear_solver.h"

#include <gtest/gtest.h>

#include "fem/box_mesh.h"
#include "fem/elastic_tet_force.h"
#include "fem/lumped_mass.h"
#include "fem_test_util.h"

namespace sedbridge::fem {
namespace {

// M + h^2 K of a block, a typical backward Euler system.
SystemMatrix StepMatrix(const TetMesh& mesh, ElasticTetForce& elastic, const Eigen::VectorXd& x) {
  SystemMatrix A;
  std::vector<std::pair<int, int>> pairs;
  elastic.AppendCoupledNodes(pairs);
  A.Build(mesh.num_nodes(), pairs);
  elastic.BindMatrix(A);
  const double h = 1e-3;
  JacobianSink sink{&A, h * h, h};
  Eigen::VectorXd f = Eigen::VectorXd::Zero(x.size()), v = Eigen::VectorXd::Zero(x.size());
  elastic.AddForce({x, v, 0.0, true}, f, &sink);
  const Eigen::VectorXd m = LumpedNodeMass(mesh);
  for (int i = 0; i < mesh.num_nodes(); ++i) A.AddScaledIdentity(A.DiagonalSlot(i), m[i] + 1e-3);
  return A;
}

TEST(LinearSolver, AllSolversAgreeAndWarpIsNearlyExactForLinearFem) {
  const TetMesh mesh = MakeBoxMesh({0.01, 0.01, 0.01}, {4, 4, 4}, testing::Skin(1e5, 0.48));
  ElasticTetForce elastic(mesh, ElasticFormulation::kLinear);
  Eigen::VectorXd x(3 * mesh.num_nodes());
  for (int i = 0; i < mesh.num_nodes(); ++i) x.segment<3>(3 * i) = mesh.rest_positions_m.col(i);
  SystemMatrix A = StepMatrix(mesh, elastic, x);
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(x.size(), -1.0, 1.0);

  Eigen::VectorXd reference = Eigen::VectorXd::Zero(b.size());
  auto direct = MakeLinearSolver("ldlt", {});
  direct->Prepare(A);
  ASSERT_TRUE(direct->Solve(A, b, reference).converged);
  Eigen::VectorXd Ax;
  A.Multiply(reference, Ax);
  EXPECT_LT((Ax - b).norm(), 1e-9 * b.norm());

  for (const char* name : {"pcg_jacobi", "pcg_warp", "pcg_warp_ichol"}) {
    auto solver = MakeLinearSolver(name, PcgSettings{1e-10, 5000});
    solver->SetReferenceMatrix(A);
    solver->Prepare(A);
    Eigen::VectorXd y = Eigen::VectorXd::Zero(b.size());
    const LinearSolveReport r = solver->Solve(A, b, y);
    EXPECT_TRUE(r.converged) << name;
    EXPECT_FALSE(r.used_fallback) << name;
    EXPECT_LT((y - reference).norm(), 1e-8 * reference.norm()) << name;
    if (std::string(name) == "pcg_warp") EXPECT_LE(r.iterations, 2);
  }
}

TEST(LinearSolver, PcgThatCannotConvergeFallsBackAndCountsIt) {
  const TetMesh mesh = MakeBoxMesh({0.01, 0.01, 0.01}, {3, 3, 3}, testing::Skin(1e5, 0.49));
  ElasticTetForce elastic(mesh, ElasticFormulation::kLinear);
  Eigen::VectorXd x(3 * mesh.num_nodes());
  for (int i = 0; i < mesh.num_nodes(); ++i) x.segment<3>(3 * i) = mesh.rest_positions_m.col(i);
  SystemMatrix A = StepMatrix(mesh, elastic, x);
  PcgSolver pcg(PcgSettings{1e-12, 2, PreconditionerKind::kBlockJacobi, true});
  pcg.Prepare(A);
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(x.size(), -1.0, 1.0);
  Eigen::VectorXd y = Eigen::VectorXd::Zero(b.size());
  const LinearSolveReport r = pcg.Solve(A, b, y);
  EXPECT_TRUE(r.used_fallback);
  EXPECT_TRUE(r.converged);
  EXPECT_LT(r.relative_residual, 1e-9);
  EXPECT_EQ(pcg.fallbacks(), 1);
}

TEST(LinearSolver, UnknownNameIsAnError) { EXPECT_THROW(MakeLinearSolver("cholmod", {}), std::invalid_argument); }

}  // namespace
}  // namespace sedbridge::fem
