#include <gtest/gtest.h>

#include <type_traits>

#include "fem/backward_euler_integrator.h"
#include "fem/box_mesh.h"
#include "fem/elastic_tet_force.h"
#include "fem/simulation.h"
#include "fem_test_util.h"

namespace sedbridge::fem {
namespace {

// They hold references to each other's members (terms, mass, Newton system).
static_assert(!std::is_copy_constructible_v<Simulation> && !std::is_move_constructible_v<Simulation>);
static_assert(!std::is_copy_constructible_v<NewtonSystem> && !std::is_move_constructible_v<NewtonSystem>);
static_assert(!std::is_copy_constructible_v<BackwardEulerIntegrator> &&
              !std::is_move_constructible_v<BackwardEulerIntegrator>);
static_assert(!std::is_copy_constructible_v<ElasticTetForce> && !std::is_move_constructible_v<ElasticTetForce>);

// A block on rollers released from a stretched state oscillates and, backward Euler being
// dissipative, its total energy never grows and the motion decays.
void ReleaseStretchedBlock(ElasticFormulation formulation, const char* solver) {
  const TetMesh mesh = MakeBoxMesh({0.008, 0.008, 0.006}, {3, 3, 3}, testing::Skin(1e5, 0.45, 1000));
  std::vector<std::unique_ptr<ForceTerm>> terms;
  auto elastic = std::make_unique<ElasticTetForce>(mesh, formulation);
  const ElasticTetForce* rotations = elastic.get();
  terms.push_back(std::move(elastic));
  testing::AddRollerSupport(mesh, terms, 1e5);
  IntegratorSettings s;
  s.kind = IntegratorKind::kBackwardEuler;
  Simulation sim(mesh, std::move(terms), s, MakeLinearSolver(solver, PcgSettings{1e-10, 500}, rotations));
  Eigen::VectorXd x = sim.positions_m();
  for (int i = 0; i < mesh.num_nodes(); ++i) x[3 * i + 2] *= 1.05;
  sim.SetPositions(x);
  double energy = sim.PotentialEnergy();
  const double initial = energy;
  ASSERT_GT(initial, 0);
  double early_peak = 0, late_peak = 0;
  for (int step = 0; step < 400; ++step) {
    const StepReport r = sim.Step(1e-4);
    ASSERT_TRUE(r.finite);
    ASSERT_TRUE(r.converged) << "step " << step;
    const double e = sim.PotentialEnergy() + sim.KineticEnergy();
    EXPECT_LE(e, energy * (1 + 1e-6) + 1e-15) << "energy grew at step " << step;
    energy = e;
    const double top = std::abs(sim.positions_m()[3 * BoxNodeIndex({3, 3, 3}, 1, 1, 3) + 2] - 0.006);
    if (step < 50) early_peak = std::max(early_peak, top);
    if (step >= 350) late_peak = std::max(late_peak, top);
  }
  EXPECT_LT(energy, 0.5 * initial);
  EXPECT_LT(late_peak, early_peak);
}

TEST(BackwardEuler, LinearDirectReleasedBlockDissipates) { ReleaseStretchedBlock(ElasticFormulation::kLinear, "ldlt"); }
TEST(BackwardEuler, CorotationalWarpReleasedBlockDissipates) {
  ReleaseStretchedBlock(ElasticFormulation::kCorotational, "pcg_warp");
}

TEST(BackwardEuler, ConstantMatrixPathMatchesFullAssembly) {
  // Linear FEM assembles once; corotational re-assembles every step. For tiny motion
  // they must agree.
  const TetMesh mesh = MakeBoxMesh({0.008, 0.008, 0.006}, {2, 2, 2}, testing::Skin());
  Eigen::VectorXd results[2];
  int k = 0;
  for (auto f : {ElasticFormulation::kLinear, ElasticFormulation::kCorotational}) {
    std::vector<std::unique_ptr<ForceTerm>> terms;
    terms.push_back(std::make_unique<ElasticTetForce>(mesh, f));
    testing::AddRollerSupport(mesh, terms, 1e5);
    Simulation sim(mesh, std::move(terms), IntegratorSettings{}, MakeLinearSolver("ldlt", {}));
    EXPECT_EQ(sim.constant_matrix(), f == ElasticFormulation::kLinear);
    Eigen::VectorXd x = sim.positions_m();
    for (int i = 0; i < mesh.num_nodes(); ++i) x[3 * i + 2] *= 1.0 + 1e-7;
    sim.SetPositions(x);
    for (int step = 0; step < 20; ++step) sim.Step(1e-4);
    results[k++] = sim.positions_m();
  }
  EXPECT_LT((results[0] - results[1]).cwiseAbs().maxCoeff(), 1e-12);
}

}  // namespace
}  // namespace sedbridge::fem

namespace sedbridge::fem {
namespace {

TEST(BackwardEuler, StepReportSaysWhereTheTimeWent) {
  const TetMesh mesh = MakeBoxMesh({0.008, 0.008, 0.006}, {2, 2, 2}, testing::Skin());
  std::vector<std::unique_ptr<ForceTerm>> terms;
  terms.push_back(std::make_unique<ElasticTetForce>(mesh, ElasticFormulation::kCorotational));
  testing::AddRollerSupport(mesh, terms, 1e5);
  Simulation sim(mesh, std::move(terms), IntegratorSettings{}, MakeLinearSolver("ldlt", {}));
  const StepReport r = sim.Step(1e-3);
  EXPECT_GT(r.stage_ms[Stage::kAssembly], 0.0);
  EXPECT_GT(r.stage_ms[Stage::kSolve], 0.0);
  EXPECT_EQ(r.stage_ms[Stage::kSed], 0.0);  // the simulation has no SED stage
  EXPECT_EQ(r.stage_ms[Stage::kConditioning], 0.0);
}

}  // namespace
}  // namespace sedbridge::fem
