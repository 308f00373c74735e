// The warped PCG's stiff-node update (fem/stiff_node_update.h): contact springs on a few
// nodes, added to the rest factor by a Woodbury update, make the preconditioner exact again
// (one PCG iteration), also when the factor is warped by node rotations; nodes beyond the
// memory budget are left out, which costs iterations, not the answer.

#include "fem/stiff_node_update.h"

#include <gtest/gtest.h>

#include <cmath>

#include "fem/box_mesh.h"
#include "fem/elastic_tet_force.h"
#include "fem/linear_solver.h"
#include "fem/lumped_mass.h"
#include "fem_test_util.h"

namespace sedbridge::fem {
namespace {

class FixedStiffNodes final : public StiffNodeSource {
 public:
  explicit FixedStiffNodes(std::vector<int> nodes) : nodes_(std::move(nodes)) {}
  void AppendStiffNodes(std::vector<int>& nodes) const override { nodes.insert(nodes.end(), nodes_.begin(), nodes_.end()); }

 private:
  std::vector<int> nodes_;
};

class UniformRotation final : public NodeRotationSource {
 public:
  UniformRotation(int num_nodes, const Eigen::Matrix3d& q) : num_nodes_(num_nodes), q_(q) {}
  void ComputeNodeRotations(std::vector<Eigen::Matrix3d>& r) const override { r.assign(size_t(num_nodes_), q_); }

 private:
  int num_nodes_;
  Eigen::Matrix3d q_;
};

const TetMesh& Box() {
  static const TetMesh mesh = MakeBoxMesh({0.01, 0.01, 0.01}, {4, 4, 4}, testing::Skin(1e5, 0.48));
  return mesh;
}

// Backward Euler M + h^2 K of the box at rest, every block turned by q (q A0_ij q^T: the
// matrix a uniformly rotated corotational body has), into A.
void BuildRotatedStepMatrix(const Eigen::Matrix3d& q, SystemMatrix& A) {
  const TetMesh& mesh = Box();
  ElasticTetForce elastic(mesh, ElasticFormulation::kLinear);
  std::vector<std::pair<int, int>> pairs;
  elastic.AppendCoupledNodes(pairs);
  A.Build(mesh.num_nodes(), pairs);
  elastic.BindMatrix(A);
  Eigen::VectorXd x(3 * mesh.num_nodes());
  for (int i = 0; i < mesh.num_nodes(); ++i) x.segment<3>(3 * i) = mesh.rest_positions_m.col(i);
  const double h = 1e-3;
  JacobianSink sink{&A, h * h, h};
  Eigen::VectorXd f = Eigen::VectorXd::Zero(x.size()), v = Eigen::VectorXd::Zero(x.size());
  elastic.AddForce({x, v, 0.0, true}, f, &sink);
  const Eigen::VectorXd m = LumpedNodeMass(mesh);
  for (int i = 0; i < mesh.num_nodes(); ++i) A.AddScaledIdentity(A.DiagonalSlot(i), m[i]);
  for (int s = 0; s < A.num_blocks(); ++s) {
    const Eigen::Matrix3d b = A.Block(s);
    A.AddBlock(s, q * b * q.transpose() - b);
  }
}

// Penalty springs k n n^T (k = 100x the largest diagonal entry, as a 1e4 N/m contact at a
// 1 ms step is) on the top face's nodes, n tilted a little from node to node.
std::vector<int> AddContactSprings(SystemMatrix& A) {
  const TetMesh& mesh = Box();
  double max_diagonal = 0;
  for (int i = 0; i < mesh.num_nodes(); ++i) max_diagonal = std::max(max_diagonal, A.Block(A.DiagonalSlot(i)).maxCoeff());
  std::vector<int> nodes;
  for (int i = 0; i < mesh.num_nodes(); ++i)
    if (mesh.rest_positions_m(2, i) > 0.01 - 1e-9 && mesh.rest_positions_m(0, i) > 0.004) {
      const Eigen::Vector3d n = Eigen::Vector3d(0.1 * std::sin(i), 0.1 * std::cos(i), 1.0).normalized();
      A.AddBlock(A.DiagonalSlot(i), 100.0 * max_diagonal * n * n.transpose());
      nodes.push_back(i);
    }
  return nodes;
}

struct Solved {
  Eigen::VectorXd x;
  LinearSolveReport report;
  int rank = 0;
};

Solved SolveWithPcg(const SystemMatrix& A0, const SystemMatrix& A, const NodeRotationSource* rotations,
                    const StiffNodeSource* stiff, PcgSettings settings) {
  PcgSolver pcg(settings, rotations, stiff);
  pcg.SetReferenceMatrix(A0);
  pcg.Prepare(A);
  Solved out;
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(A.csr().rows(), -1.0, 1.0);
  out.x = Eigen::VectorXd::Zero(b.size());
  out.report = pcg.Solve(A, b, out.x);
  out.rank = pcg.stiff_node_rank();
  return out;
}

Eigen::VectorXd DirectSolve(const SystemMatrix& A) {
  DirectLdltSolver ldlt;
  ldlt.Prepare(A);
  Eigen::VectorXd x;
  ldlt.Solve(A, Eigen::VectorXd::LinSpaced(A.csr().rows(), -1.0, 1.0), x);
  return x;
}

// Exactness is checked in double precision: a float copy of the factor (the default) is
// exact to ~1e-7 only, so it needs a second iteration at this tolerance.
PcgSettings Tight() {
  PcgSettings s;
  s.relative_tolerance = 1e-10;
  s.max_iterations = 500;
  s.fallback_to_direct = false;
  s.single_precision_factor = false;
  return s;
}

TEST(StiffNodeUpdate, ContactSpringsMakeTheWarpedRestFactorExactAgain) {
  for (const double angle : {0.0, 0.6}) {
    const Eigen::Matrix3d q = Eigen::AngleAxisd(angle, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    SystemMatrix A0, A;
    BuildRotatedStepMatrix(Eigen::Matrix3d::Identity(), A0);
    BuildRotatedStepMatrix(q, A);
    const FixedStiffNodes stiff(AddContactSprings(A));
    const UniformRotation rotation(Box().num_nodes(), q);
    const Eigen::VectorXd reference = DirectSolve(A);

    const Solved updated = SolveWithPcg(A0, A, &rotation, &stiff, Tight());
    EXPECT_TRUE(updated.report.converged) << angle;
    EXPECT_LE(updated.report.iterations, 1) << angle;
    EXPECT_GE(updated.rank, 5) << angle;  // one direction per spring
    EXPECT_LT((updated.x - reference).norm(), 1e-8 * reference.norm()) << angle;

    PcgSettings rest_only = Tight();
    rest_only.stiff_node_update = false;
    const Solved plain = SolveWithPcg(A0, A, &rotation, &stiff, rest_only);
    EXPECT_TRUE(plain.report.converged) << angle;
    EXPECT_GT(plain.report.iterations, 5) << angle;  // what the update saves
    EXPECT_EQ(plain.rank, 0);
  }
}

TEST(StiffNodeUpdate, NodesBeyondTheMemoryBudgetAreLeftOutNotWrong) {
  SystemMatrix A0, A;
  BuildRotatedStepMatrix(Eigen::Matrix3d::Identity(), A0);
  BuildRotatedStepMatrix(Eigen::Matrix3d::Identity(), A);
  const std::vector<int> nodes = AddContactSprings(A);
  ASSERT_GE(nodes.size(), 5u);
  const FixedStiffNodes stiff(nodes);
  PcgSettings two_nodes = Tight();
  two_nodes.stiff_node_budget_MB = 2.5 * 3 * double(A.csr().rows()) * sizeof(double) / 1e6;
  const Solved s = SolveWithPcg(A0, A, nullptr, &stiff, two_nodes);
  EXPECT_EQ(s.rank, 2);
  EXPECT_TRUE(s.report.converged);
  EXPECT_GT(s.report.iterations, 1);
  const Eigen::VectorXd reference = DirectSolve(A);
  EXPECT_LT((s.x - reference).norm(), 1e-8 * reference.norm());
}

// The cached columns are reused while a node stays stiff and solved once for a new one.
TEST(StiffNodeUpdate, SolvesThreeColumnsPerNewNodeOnly) {
  SystemMatrix A0, A;
  BuildRotatedStepMatrix(Eigen::Matrix3d::Identity(), A0);
  BuildRotatedStepMatrix(Eigen::Matrix3d::Identity(), A);
  const std::vector<int> nodes = AddContactSprings(A);
  DirectLdltSolver rest;
  rest.Prepare(A0);
  const StiffNodeUpdate::RestSolve solve = [&](const Eigen::VectorXd& b, Eigen::VectorXd& x) { rest.Solve(A0, b, x); };
  StiffNodeUpdate update;
  update.SetRestMatrix(A0);
  const std::vector<int> first(nodes.begin(), nodes.begin() + 2);
  update.Prepare(A, first, {}, solve);
  EXPECT_EQ(update.column_solves(), 6);
  update.Prepare(A, nodes, {}, solve);
  EXPECT_EQ(update.column_solves(), 3 * long(nodes.size()));
  update.Prepare(A, nodes, {}, solve);
  EXPECT_EQ(update.column_solves(), 3 * long(nodes.size()));
  // A node without extra stiffness adds nothing (and costs no solve).
  update.Prepare(A0, nodes, {}, solve);
  EXPECT_EQ(update.rank(), 0);
  EXPECT_EQ(update.column_solves(), 3 * long(nodes.size()));
}

}  // namespace
}  // namespace sedbridge::fem
