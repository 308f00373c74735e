// CHOLMOD's supernodal Cholesky on a fingertip model (B_coarse): the same solutions as
// Eigen's LDL^T on its step and stiffness matrices, and the same simulated press.

#include "fem/cholmod_solver.h"

#include <gtest/gtest.h>
#include <omp.h>

#include "fem/lumped_mass.h"
#include "scene/fingertip_scene.h"

namespace sedbridge::scene {
namespace {

const model::FingertipModel& Model() {
  static const model::FingertipModel m = model::LoadFingertipModel("B_coarse");
  return m;
}

// Corotational, bone fixed, slightly deformed; stiffness_scale 1 and no mass: the
// quasi-static K (worst conditioned); h^2 with the mass: the backward Euler step matrix.
// Built into A (a SystemMatrix is neither copied nor moved).
void BuildModelMatrix(bool with_mass, fem::SystemMatrix& A) {
  const std::string yaml = "model: B_coarse\nelasticity: corotational\nbone: {mode: fixed}\n";
  FingertipScene s(ParseSceneDescription(yaml, "test"), Model());
  auto& sim = s.simulation();
  std::vector<std::pair<int, int>> pairs;
  for (const auto& t : sim.terms()) t->AppendCoupledNodes(pairs);
  A.Build(Model().num_soft_nodes(), pairs);
  for (const auto& t : sim.terms()) t->BindMatrix(A);
  Eigen::VectorXd x = sim.positions_m();
  for (Eigen::Index i = 0; i < x.size() / 3; ++i) x[3 * i] += 0.1 * (x[3 * i + 2] - x[2]);  // a shear
  const double h = 1e-3;
  fem::JacobianSink sink{&A, with_mass ? h * h : 1.0, with_mass ? h : 0.0};
  Eigen::VectorXd f = Eigen::VectorXd::Zero(x.size());
  const Eigen::VectorXd v = Eigen::VectorXd::Zero(x.size());
  for (const auto& t : sim.terms()) t->AddForce({x, v, 0.0, with_mass}, f, &sink);
  if (with_mass) {
    const Eigen::VectorXd m = fem::LumpedNodeMass(Model().soft);
    for (int i = 0; i < Model().num_soft_nodes(); ++i) A.AddScaledIdentity(A.DiagonalSlot(i), m[i]);
  }
}

TEST(CholmodOnFingertip, SameSolutionAsLdltOnStepAndStiffnessMatrices) {
  for (bool with_mass : {true, false}) {
    fem::SystemMatrix A;
    BuildModelMatrix(with_mass, A);
    const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(A.csr().rows(), -1.0, 2.0);
    fem::DirectLdltSolver ldlt;
    fem::CholmodSolver cholmod;
    ldlt.Prepare(A);
    cholmod.Prepare(A);
    Eigen::VectorXd reference, x;
    ASSERT_TRUE(ldlt.Solve(A, b, reference).converged);
    ASSERT_TRUE(cholmod.Solve(A, b, x).converged);
    EXPECT_LT((x - reference).norm(), 1e-10 * reference.norm()) << "with mass " << with_mass;
    // A nested-dissection or AMD ordering: L stays far from dense.
    const double n = double(A.csr().rows());
    EXPECT_LT(cholmod.factor_nonzeros(), 0.2 * n * n);
  }
}

// The dynamic corotational press: contact changes the matrix every step, so each step
// refactorizes; both direct solvers give the same trajectory, and the PCG preconditioned
// by either rest factor gives it to its tolerance.
TEST(CholmodOnFingertip, SamePressAsLdlt) {
  auto run = [](const std::string& solver) {
    const std::string yaml = "model: B_coarse\nelasticity: corotational\nsolver: {type: " + solver +
                             ", tolerance: 1.0e-10, max_iterations: 500}\n"
                             "dynamics: {integrator: backward_euler, dt_s: 0.001, newton_iterations: 2}\n"
                             "bone: {mode: fixed}\ncontact:\n  objects:\n    - {shape: plane, rpy_deg: [180, 0, 0], "
                             "position_mm: [0, 0, -0.5], motion: {keyframes: [{t_s: 0, offset_mm: [0, 0, 0]}, "
                             "{t_s: 0.01, offset_mm: [0, 0, -1.0]}]}}\n";
    FingertipScene s(ParseSceneDescription(yaml, "test"), Model());
    for (int k = 0; k < 10; ++k) EXPECT_TRUE(s.Step().converged) << solver << " step " << k;
    EXPECT_GT(s.contact()->active_contacts().size(), 0u);
    return Eigen::VectorXd(s.simulation().positions_m());
  };
  const model::FingertipModel& m = Model();
  Eigen::VectorXd rest(3 * m.num_soft_nodes());
  for (int i = 0; i < m.num_soft_nodes(); ++i) rest.segment<3>(3 * i) = m.soft.rest_positions_m.col(i);
  const Eigen::VectorXd u_ldlt = run("ldlt") - rest;
  const Eigen::VectorXd u_cholmod = run("cholmod") - rest;
  ASSERT_GT(u_ldlt.norm(), 0.0);
  EXPECT_LT((u_cholmod - u_ldlt).norm(), 1e-9 * u_ldlt.norm());
  for (const char* pcg : {"pcg_warp", "pcg_warp_ldlt"}) {
    const Eigen::VectorXd u = run(pcg) - rest;
    EXPECT_LT((u - u_ldlt).norm(), 1e-6 * u_ldlt.norm()) << pcg;
  }
}

// The subtree-parallel triangular solves give CHOLMOD's own answer on any team size, also
// after a refactorization with new values (the schedule depends on the pattern only), and
// leave only the top separators serial.
TEST(CholmodOnFingertip, SubtreeParallelSolveEqualsCholmodsOwn) {
  fem::SystemMatrix A;
  BuildModelMatrix(/*with_mass=*/true, A);
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(A.csr().rows(), -1.0, 2.0);
  fem::CholmodSolver own, subtrees;
  own.set_solve_path(fem::CholmodSolvePath::kCholmod);
  subtrees.set_solve_path(fem::CholmodSolvePath::kSubtrees);
  const int caller = omp_get_max_threads();
  for (int pass = 0; pass < 2; ++pass) {
    if (pass == 1) BuildModelMatrix(/*with_mass=*/false, A);  // same pattern, new values
    own.Prepare(A);
    subtrees.Prepare(A);
    Eigen::VectorXd reference;
    ASSERT_TRUE(own.Solve(A, b, reference).converged);
    for (int threads : {1, 2, 3, 4}) {
      omp_set_num_threads(threads);
      Eigen::VectorXd x;
      ASSERT_TRUE(subtrees.Solve(A, b, x).converged);
      EXPECT_LT((x - reference).norm(), 1e-12 * reference.norm()) << "pass " << pass << ", " << threads << " threads";
      if (threads == 2) {
        EXPECT_LT(subtrees.solve_serial_fraction(), 0.5);
      }
    }
    omp_set_num_threads(caller);
  }
  // kAuto on one thread is CHOLMOD's own solve: bit for bit.
  fem::CholmodSolver automatic;
  automatic.Prepare(A);
  omp_set_num_threads(1);
  Eigen::VectorXd x, reference;
  ASSERT_TRUE(automatic.Solve(A, b, x).converged);
  ASSERT_TRUE(own.Solve(A, b, reference).converged);
  omp_set_num_threads(caller);
  EXPECT_EQ((x - reference).norm(), 0.0);
}

// The single-precision copy of the factor: the double answer to float accuracy (and not
// to round-off: it really is a float solve), on one and two threads.
TEST(CholmodOnFingertip, SinglePrecisionSolveIsCloseToTheDoubleOne) {
  fem::SystemMatrix A;
  BuildModelMatrix(/*with_mass=*/true, A);
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(A.csr().rows(), -1.0, 2.0);
  fem::CholmodSolver dbl, single;
  single.set_single_precision(true);
  dbl.Prepare(A);
  single.Prepare(A);
  Eigen::VectorXd reference;
  ASSERT_TRUE(dbl.Solve(A, b, reference).converged);
  const int caller = omp_get_max_threads();
  for (int threads : {1, 2}) {
    omp_set_num_threads(threads);
    Eigen::VectorXd x;
    ASSERT_TRUE(single.Solve(A, b, x).converged);
    const double error = (x - reference).norm() / reference.norm();
    EXPECT_LT(error, 1e-4) << threads << " threads";
    EXPECT_GT(error, 1e-12) << threads << " threads";
  }
  omp_set_num_threads(caller);
}

}  // namespace
}  // namespace sedbridge::scene
