// Quasi-static Newton over a load path: a rigid plane pressed step by step into a
// corotational block on rollers (13 % compression). The integrator starts each step from
// the previous increment extrapolated (the predictor); it must reach the same equilibria as
// starting from the previous one, in fewer iterations, and must not extrapolate from a state
// set from outside. The consistent corotational tangent reaches the same equilibria in fewer
// iterations, and an indefinite tangent falls back to the definite one.

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

// A Jacobian that is indefinite (a large negative diagonal on node 0) unless asked for a
// definite one; no force. Stands in for the consistent corotational tangent at its worst.
class IndefiniteJacobianTerm final : public ForceTerm {
 public:
  std::string name() const override { return "indefinite_jacobian"; }
  void BindMatrix(const SystemMatrix& matrix) override { slot_ = matrix.DiagonalSlot(0); }
  void AddForce(const SystemState&, Eigen::VectorXd&, JacobianSink* sink) override {
    if (sink && !definite_) sink->Add(slot_, 0, 0, -1e12 * Eigen::Matrix3d::Identity());
  }
  bool UseDefiniteJacobian(bool definite) override {
    definite_ = definite;
    ++calls;
    return true;
  }
  int calls = 0;

 private:
  int slot_ = -1;
  bool definite_ = false;
};

struct PressOptions {
  CorotationalTangent tangent = CorotationalTangent::kWarped;
  double tilt_rad = 0.0;  // plane tilted about x: shear, so elements rotate
  std::string solver = "ldlt";
  bool indefinite_term = false;
};

std::unique_ptr<Simulation> MakePress(const TetMesh& mesh, const PressOptions& o = {}) {
  std::vector<std::unique_ptr<ForceTerm>> terms;
  auto elastic = std::make_unique<ElasticTetForce>(mesh, ElasticFormulation::kCorotational);
  elastic->set_corotational_tangent(o.tangent);
  terms.push_back(std::move(elastic));
  if (o.indefinite_term) terms.push_back(std::make_unique<IndefiniteJacobianTerm>());
  testing::AddRollerSupport(mesh, terms);
  const auto top = testing::NodesWhere(mesh, 2, kHeight);
  // Plane with normal -z, solid above it: touching the top face at t = 0, kDepth into it
  // at t = 1.
  const Eigen::Quaterniond flip(Eigen::AngleAxisd(M_PI + o.tilt_rad, Eigen::Vector3d::UnitX()));
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
  return std::make_unique<Simulation>(mesh, std::move(terms), s, MakeLinearSolver(o.solver, {}));
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

double DisplacementScale(const Simulation& sim, const TetMesh& mesh) {
  return (sim.positions_m() - Eigen::VectorXd(mesh.rest_positions_m.reshaped())).cwiseAbs().maxCoeff();
}

TEST(QuasiStaticNewtonIntegrator, ConsistentTangentReachesTheSameEquilibriaInFewerIterations) {
  // A tilted plane shears the block, so its elements rotate: the warped tangent converges
  // linearly there, the consistent one quadratically.
  const TetMesh mesh = MakeBoxMesh({kSide, kSide, kHeight}, {4, 4, 3}, testing::Skin());
  PressOptions warped_options{CorotationalTangent::kWarped, 0.2, "cholmod"};
  PressOptions consistent_options = warped_options;
  consistent_options.tangent = CorotationalTangent::kConsistent;
  auto warped = MakePress(mesh, warped_options);
  auto consistent = MakePress(mesh, consistent_options);
  int warped_iterations = 0, consistent_iterations = 0;
  for (int step = 0; step < kSteps; ++step) {
    const StepReport a = warped->Step(1.0 / kSteps);
    const StepReport b = consistent->Step(1.0 / kSteps);
    ASSERT_TRUE(a.converged && b.converged) << "step " << step;
    EXPECT_EQ(b.tangent_fallbacks, 0) << "step " << step;
    warped_iterations += a.newton_iterations;
    consistent_iterations += b.newton_iterations;
    EXPECT_LT((warped->positions_m() - consistent->positions_m()).cwiseAbs().maxCoeff(),
              1e-8 * DisplacementScale(*warped, mesh))
        << "step " << step;
  }
  EXPECT_LT(3 * consistent_iterations, 2 * warped_iterations);  // 27 against 61 when written
}

TEST(QuasiStaticNewtonIntegrator, IndefiniteTangentFallsBackToTheDefiniteOne) {
  // CHOLMOD refuses the indefinite matrix; the step is solved with the definite one, is
  // counted, reaches the same equilibrium, and the next step tries the exact one again.
  const TetMesh mesh = MakeBoxMesh({kSide, kSide, kHeight}, {4, 4, 3}, testing::Skin());
  auto reference = MakePress(mesh, {CorotationalTangent::kWarped, 0.0, "cholmod", false});
  auto fallback = MakePress(mesh, {CorotationalTangent::kWarped, 0.0, "cholmod", true});
  for (int step = 0; step < 3; ++step) {
    const StepReport a = reference->Step(1.0 / kSteps);
    const StepReport b = fallback->Step(1.0 / kSteps);
    ASSERT_TRUE(a.converged && b.converged) << "step " << step;
    EXPECT_EQ(b.tangent_fallbacks, 1) << "step " << step;
    EXPECT_EQ(a.tangent_fallbacks, 0);
    EXPECT_LT((reference->positions_m() - fallback->positions_m()).cwiseAbs().maxCoeff(),
              1e-8 * DisplacementScale(*reference, mesh))
        << "step " << step;
  }
}

}  // namespace
}  // namespace sedbridge::fem
