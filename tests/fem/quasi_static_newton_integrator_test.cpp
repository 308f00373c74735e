// Quasi-static Newton over a load path: a rigid plane pressed step by step into a
// corotational block on rollers (13 % compression). The integrator starts each step from the previous increment extrapolated (the
// predictor); it must reach the same equilibria as starting from the previous one, in
// fewer iterations, and must not extrapolate from a state set from outside.

#include <gtest/gtest.h>

#include <cmath>

#include "fem/box_mesh.h"
#include "fem/elastic_tet_force.h"
#include "fem/penalty_contact_force.h"
#include "fem/simulation.h"
#include "fem_test_util.h"

namespace sedbridge::fem {
namespace {

constexpr double kSide = 0.008, kHeight = 0.006, kDepth = 0.8e-3;
constexpr int kSteps = 8;

std::unique_ptr<Simulation> MakePress(const TetMesh& mesh) {
  std::vector<std::unique_ptr<ForceTerm>> terms;
  terms.push_back(std::make_unique<ElasticTetForce>(mesh, ElasticFormulation::kCorotational));
  testing::AddRollerSupport(mesh, terms);
  const auto top = testing::NodesWhere(mesh, 2, kHeight);
  // Plane with normal -z, solid above it: touching the top face at t = 0, kDepth into it
  // at t = 1.
  const Eigen::Quaterniond flip(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()));
  geometry::PoseKeyframe k0, k1;
  k0.t_s = 0.0;
  k0.position_m = Eigen::Vector3d(0, 0, kHeight);
  k0.orientation = flip;
  k1 = k0;
  k1.t_s = 1.0;
  k1.position_m.z() -= kDepth;
  terms.push_back(std::make_unique<PenaltyContactForce>(
      top,
      std::vector<geometry::RigidObject>{
          {"plane", std::make_shared<geometry::PlaneSdf>(), geometry::Trajectory({k0, k1})}},
      ContactParams{1e5, 0.0}));
  IntegratorSettings s;
  s.kind = IntegratorKind::kQuasiStatic;
  s.newton_iterations = 40;
  s.newton_tolerance_m = 1e-12;
  return std::make_unique<Simulation>(mesh, std::move(terms), s, MakeLinearSolver("ldlt", {}));
}

TEST(QuasiStaticNewtonIntegrator, PredictorReachesTheSameEquilibriaInFewerIterations) {
  const TetMesh mesh = MakeBoxMesh({kSide, kSide, kHeight}, {4, 4, 3}, testing::Skin());
  auto predicted = MakePress(mesh);
  auto plain = MakePress(mesh);
  int predicted_iterations = 0, plain_iterations = 0;
  for (int step = 0; step < kSteps; ++step) {
    const StepReport a = predicted->Step(1.0 / kSteps);
    // Setting the state from outside (here: to itself, nudged by far less than the
    // tolerance) turns the predictor off: each step starts from the last equilibrium.
    Eigen::VectorXd x = plain->positions_m();
    x[0] += 1e-15;
    plain->SetPositions(x);
    const StepReport b = plain->Step(1.0 / kSteps);
    ASSERT_TRUE(a.converged && b.converged) << "step " << step;
    predicted_iterations += a.newton_iterations;
    plain_iterations += b.newton_iterations;
    const double scale = (plain->positions_m() - Eigen::VectorXd(mesh.rest_positions_m.reshaped())).cwiseAbs().maxCoeff();
    EXPECT_LT((predicted->positions_m() - plain->positions_m()).cwiseAbs().maxCoeff(), 1e-8 * scale)
        << "step " << step;
  }
  EXPECT_LT(predicted_iterations, plain_iterations);
}

}  // namespace
}  // namespace sedbridge::fem
