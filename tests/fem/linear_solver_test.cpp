#include "fem/linear_solver.h"

#include "fem/cholmod_solver.h"

#include <gtest/gtest.h>

#include <type_traits>

#include "fem/box_mesh.h"
#include "fem/elastic_tet_force.h"
#include "fem/lumped_mass.h"
#include "fem_test_util.h"

namespace sedbridge::fem {
namespace {

// Solvers hold factorizations (and the PCG a pointer to its rotation source): no copies.
static_assert(!std::is_copy_constructible_v<DirectLdltSolver> && !std::is_move_constructible_v<DirectLdltSolver>);
static_assert(!std::is_copy_constructible_v<PcgSolver> && !std::is_move_constructible_v<PcgSolver>);
static_assert(!std::is_copy_constructible_v<CholmodSolver> && !std::is_move_constructible_v<CholmodSolver>);
static_assert(!std::is_copy_assignable_v<CholmodSolver> && !std::is_move_assignable_v<CholmodSolver>);

// M + h^2 K of a block, a typical backward Euler system, into A (built here; a
// SystemMatrix is neither copied nor moved).
void BuildStepMatrix(const TetMesh& mesh, ElasticTetForce& elastic, const Eigen::VectorXd& x, SystemMatrix& A) {
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
}

Eigen::VectorXd RestPositions(const TetMesh& mesh) {
  Eigen::VectorXd x(3 * mesh.num_nodes());
  for (int i = 0; i < mesh.num_nodes(); ++i) x.segment<3>(3 * i) = mesh.rest_positions_m.col(i);
  return x;
}

// A linear 1 cm box's step matrix, with the pieces it was built from.
struct BoxStepSystem {
  BoxStepSystem(int cells, double poisson_ratio)
      : mesh(MakeBoxMesh({0.01, 0.01, 0.01}, {cells, cells, cells}, testing::Skin(1e5, poisson_ratio))),
        elastic(mesh, ElasticFormulation::kLinear),
        x(RestPositions(mesh)) {
    BuildStepMatrix(mesh, elastic, x, A);
  }
  const TetMesh mesh;
  ElasticTetForce elastic;  // holds a reference to mesh (declared before it)
  const Eigen::VectorXd x;
  SystemMatrix A;
};

TEST(LinearSolver, AllSolversAgreeAndWarpIsNearlyExactForLinearFem) {
  const BoxStepSystem box(4, 0.48);
  const SystemMatrix& A = box.A;
  const Eigen::VectorXd& x = box.x;
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(x.size(), -1.0, 1.0);

  Eigen::VectorXd reference = Eigen::VectorXd::Zero(b.size());
  auto direct = MakeLinearSolver("ldlt", {});
  direct->Prepare(A);
  ASSERT_TRUE(direct->Solve(A, b, reference).converged);
  Eigen::VectorXd Ax;
  A.Multiply(reference, Ax);
  EXPECT_LT((Ax - b).norm(), 1e-9 * b.norm());

  for (const char* name : {"pcg_jacobi", "pcg_warp", "pcg_warp_ldlt", "pcg_warp_ichol"}) {
    auto solver = MakeLinearSolver(name, PcgSettings{1e-10, 5000});
    solver->SetReferenceMatrix(A);
    solver->Prepare(A);
    Eigen::VectorXd y = Eigen::VectorXd::Zero(b.size());
    const LinearSolveReport r = solver->Solve(A, b, y);
    EXPECT_TRUE(r.converged) << name;
    EXPECT_FALSE(r.used_fallback) << name;
    EXPECT_LT((y - reference).norm(), 1e-8 * reference.norm()) << name;
    if (std::string(name).rfind("pcg_warp", 0) == 0 && std::string(name) != "pcg_warp_ichol")
      EXPECT_LE(r.iterations, 2) << name;
  }
}

TEST(LinearSolver, PcgThatCannotConvergeFallsBackAndCountsIt) {
  const BoxStepSystem box(3, 0.49);
  const SystemMatrix& A = box.A;
  const Eigen::VectorXd& x = box.x;
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

// A PCG stopped by its cap (the capped backward-Euler steps, fallback off) applies the
// preconditioner once per iteration it takes: the application that would start the next
// direction is not paid for (it was, a second factor solve per one-iteration step); a
// converged solve likewise stops before preconditioning its final residual. The iterate is
// the same either way.
TEST(LinearSolver, CappedPcgPreconditionsOncePerIteration) {
  const BoxStepSystem box(3, 0.49);
  const SystemMatrix& A = box.A;
  const Eigen::VectorXd& x = box.x;
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(x.size(), -1.0, 1.0);
  Eigen::VectorXd previous;
  for (const int cap : {1, 2, 3, 500}) {
    PcgSolver pcg(PcgSettings{1e-12, cap, PreconditionerKind::kBlockJacobi, false});
    pcg.Prepare(A);
    Eigen::VectorXd y = Eigen::VectorXd::Zero(b.size());
    const LinearSolveReport r = pcg.Solve(A, b, y);
    EXPECT_FALSE(r.used_fallback);
    if (cap < 500) {
      EXPECT_EQ(r.iterations, cap);
      EXPECT_FALSE(r.converged);
    } else {
      EXPECT_TRUE(r.converged);
    }
    EXPECT_EQ(r.preconditioner_applications, r.iterations) << "cap " << cap;
    // Each iterate lowers the energy x.Ax/2 - b.x (CG), so the capped ones are descent steps.
    Eigen::VectorXd Ay;
    A.Multiply(y, Ay);
    const double energy = 0.5 * y.dot(Ay) - b.dot(y);
    EXPECT_LT(energy, 0.0);
    if (previous.size()) {
      Eigen::VectorXd Ap;
      A.Multiply(previous, Ap);
      EXPECT_LE(energy, 0.5 * previous.dot(Ap) - b.dot(previous));
    }
    previous = y;
  }
}

TEST(LinearSolver, UnknownNameIsAnError) { EXPECT_THROW(MakeLinearSolver("umfpack", {}), std::invalid_argument); }

// The supernodal Cholesky answers what the LDL^T answers, for every ordering, also after
// a refactorization with new values on the same pattern (the corotational case).
TEST(CholmodSolver, MatchesLdltOnABoxMesh) {
  const TetMesh mesh = MakeBoxMesh({0.01, 0.01, 0.01}, {6, 5, 4}, testing::Skin(1e5, 0.48));
  ElasticTetForce elastic(mesh, ElasticFormulation::kCorotational);
  const Eigen::VectorXd x = RestPositions(mesh);
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(x.size(), -1.0, 1.0);
  for (CholmodOrdering ordering : {CholmodOrdering::kBest, CholmodOrdering::kAmd, CholmodOrdering::kMetis}) {
    CholmodSolver cholmod(ordering);
    DirectLdltSolver ldlt;
    for (double shear : {0.0, 0.2}) {  // rest, then a sheared state: new values, same pattern
      Eigen::VectorXd xs = x;
      for (int i = 0; i < mesh.num_nodes(); ++i) xs[3 * i] += shear * mesh.rest_positions_m(2, i);
      SystemMatrix A;
      BuildStepMatrix(mesh, elastic, xs, A);
      ldlt.Prepare(A);
      cholmod.Prepare(A);
      ASSERT_TRUE(cholmod.factor_ok());
      Eigen::VectorXd reference, y = Eigen::VectorXd::Constant(b.size(), 7.0);  // x's entry value is ignored
      ASSERT_TRUE(ldlt.Solve(A, b, reference).converged);
      const LinearSolveReport r = cholmod.Solve(A, b, y);
      EXPECT_TRUE(r.converged);
      EXPECT_LT((y - reference).norm(), 1e-10 * reference.norm()) << cholmod.ordering_used() << " shear " << shear;
    }
    EXPECT_GT(cholmod.factor_nonzeros(), 0.0);
    EXPECT_GE(cholmod.factor_stored_entries(), cholmod.factor_nonzeros());
    EXPECT_FALSE(cholmod.ordering_used().empty());
  }
  auto by_name = MakeLinearSolver("cholmod", {});
  EXPECT_EQ(by_name->name(), "cholmod");
  EXPECT_EQ(MakeLinearSolver("pcg_warp", {})->name(), "pcg_warp");
  EXPECT_EQ(MakeLinearSolver("pcg_warp_ldlt", {})->name(), "pcg_warp_ldlt");
}

// A matrix that is not positive definite (a node with a zero, then a negative diagonal
// block) is reported as not converged; the solve never hands back NaN.
TEST(CholmodSolver, ReportsASingularOrIndefiniteMatrix) {
  const TetMesh mesh = MakeBoxMesh({0.01, 0.01, 0.01}, {3, 3, 3}, testing::Skin(1e5, 0.45));
  ElasticTetForce elastic(mesh, ElasticFormulation::kLinear);
  const Eigen::VectorXd x = RestPositions(mesh);
  for (double diagonal : {0.0, -1.0}) {
    SystemMatrix A;
    std::vector<std::pair<int, int>> pairs;
    elastic.AppendCoupledNodes(pairs);
    A.Build(mesh.num_nodes(), pairs);
    const int bad = mesh.num_nodes() / 2;
    for (int i = 0; i < mesh.num_nodes(); ++i) A.AddScaledIdentity(A.DiagonalSlot(i), i == bad ? diagonal : 1.0);
    CholmodSolver cholmod;
    cholmod.Prepare(A);
    EXPECT_FALSE(cholmod.factor_ok()) << diagonal;
    const Eigen::VectorXd b = Eigen::VectorXd::Ones(x.size());
    Eigen::VectorXd y = Eigen::VectorXd::Zero(b.size());
    const LinearSolveReport r = cholmod.Solve(A, b, y);
    EXPECT_FALSE(r.converged) << diagonal;
    EXPECT_TRUE(y.allFinite()) << diagonal;
    // The PCG with a CHOLMOD rest factor that failed preconditions by block Jacobi instead
    // (which solves this diagonal -1 case exactly); the zero block cannot be solved, and
    // its direct fallback reports that. No NaN either way.
    auto pcg = MakeLinearSolver("pcg_warp", PcgSettings{1e-10, 20});
    pcg->SetReferenceMatrix(A);
    pcg->Prepare(A);
    y.setZero();
    const LinearSolveReport rp = pcg->Solve(A, b, y);
    EXPECT_EQ(rp.converged, diagonal != 0.0) << diagonal;
    EXPECT_TRUE(y.allFinite()) << diagonal;
  }
}

}  // namespace
}  // namespace sedbridge::fem

namespace sedbridge::fem {
namespace {

// Counts the calls: the warped PCG asks its rotation source once per Prepare.
class CountingRotationSource final : public NodeRotationSource {
 public:
  explicit CountingRotationSource(int num_nodes) : num_nodes_(num_nodes) {}
  void ComputeNodeRotations(std::vector<Eigen::Matrix3d>& node_rotations) const override {
    ++calls;
    node_rotations.assign(size_t(num_nodes_), Eigen::Matrix3d::Identity());
  }
  mutable int calls = 0;

 private:
  int num_nodes_;
};

TEST(LinearSolver, WarpedPcgTakesRotationsFromTheSourceGivenAtConstruction) {
  const TetMesh mesh = MakeBoxMesh({0.01, 0.01, 0.01}, {3, 3, 3}, testing::Skin(1e5, 0.48));
  ElasticTetForce elastic(mesh, ElasticFormulation::kLinear);
  const Eigen::VectorXd x = RestPositions(mesh);
  SystemMatrix A;
  BuildStepMatrix(mesh, elastic, x, A);
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(x.size(), -1.0, 1.0);
  for (const char* name : {"pcg_warp", "pcg_jacobi"}) {
    CountingRotationSource source(mesh.num_nodes());
    auto solver = MakeLinearSolver(name, PcgSettings{1e-10, 5000}, &source);
    EXPECT_EQ(solver->wants_reference_matrix(), std::string(name) == "pcg_warp");
    if (solver->wants_reference_matrix()) solver->SetReferenceMatrix(A);
    solver->Prepare(A);
    solver->Prepare(A);
    EXPECT_EQ(source.calls, std::string(name) == "pcg_warp" ? 2 : 0) << name;
    Eigen::VectorXd y = Eigen::VectorXd::Zero(b.size());
    EXPECT_TRUE(solver->Solve(A, b, y).converged) << name;
  }
}

}  // namespace
}  // namespace sedbridge::fem
