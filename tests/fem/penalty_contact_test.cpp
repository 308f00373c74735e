// A rigid plane pressed into a block on rollers: uniaxial compression with reaction
// F = E A d / h in the limit of a rigid contact. The penalty force must converge to it
// as k_contact grows.

#include <gtest/gtest.h>

#include "fem/box_mesh.h"
#include "fem/elastic_tet_force.h"
#include "fem/mesh_topology.h"
#include "fem/penalty_contact_force.h"
#include "fem/pseudo_friction_force.h"
#include "fem/simulation.h"
#include "fem_test_util.h"

namespace sedbridge::fem {
namespace {

constexpr double kE = 1e5, kSide = 0.008, kHeight = 0.006, kDepth = 1e-5;

geometry::RigidObject PlaneFromAbove(double z) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::Vector3d(1, -1, -1).asDiagonal();  // normal -z, occupying z > plane
  pose.translation() = Eigen::Vector3d(0, 0, z);
  return {"plane", std::make_shared<geometry::PlaneSdf>(), geometry::Trajectory(pose)};
}

double PressForce(const TetMesh& mesh, double k_contact, int* contacts = nullptr) {
  std::vector<std::unique_ptr<ForceTerm>> terms;
  terms.push_back(std::make_unique<ElasticTetForce>(mesh, ElasticFormulation::kLinear));
  testing::AddRollerSupport(mesh, terms);
  const auto top = testing::NodesWhere(mesh, 2, kHeight);
  terms.push_back(std::make_unique<PenaltyContactForce>(top, std::vector<geometry::RigidObject>{PlaneFromAbove(kHeight - kDepth)},
                                                        ContactParams{k_contact, 0.0}));
  auto* contact = static_cast<PenaltyContactForce*>(terms.back().get());
  IntegratorSettings s;
  s.kind = IntegratorKind::kQuasiStatic;
  s.newton_iterations = 30;
  s.newton_tolerance_m = 1e-14;
  Simulation sim(mesh, std::move(terms), s, MakeLinearSolver("ldlt", {}));
  const StepReport r = sim.Step(1.0);
  EXPECT_TRUE(r.converged);
  sim.TotalForce();  // re-evaluate contact at the converged state
  if (contacts) *contacts = int(contact->active_contacts().size());
  return contact->TotalSpringForceMagnitude();
}

TEST(PenaltyContact, ForceConvergesToRigidLimitAsStiffnessGrows) {
  const TetMesh mesh = MakeBoxMesh({kSide, kSide, kHeight}, {4, 4, 3}, testing::Skin(kE, 0.3));
  const double exact = kE * kSide * kSide * kDepth / kHeight;
  double previous_error = 1e9;
  for (double k : {1e1, 1e2, 1e3, 1e4, 1e5, 1e6}) {
    int contacts = 0;
    const double error = std::abs(PressForce(mesh, k, &contacts) - exact) / exact;
    EXPECT_EQ(contacts, 25) << "k = " << k;
    EXPECT_LT(error, previous_error) << "k = " << k;
    previous_error = error;
  }
  EXPECT_LT(previous_error, 1e-3);
}

TEST(PenaltyContact, NoForceWithoutPenetration) {
  const TetMesh mesh = MakeBoxMesh({kSide, kSide, kHeight}, {2, 2, 2}, testing::Skin());
  const auto top = testing::NodesWhere(mesh, 2, kHeight);
  PenaltyContactForce contact(top, {PlaneFromAbove(kHeight + 1e-4)}, {});
  Eigen::VectorXd x(3 * mesh.num_nodes()), v = Eigen::VectorXd::Zero(3 * mesh.num_nodes());
  for (int i = 0; i < mesh.num_nodes(); ++i) x.segment<3>(3 * i) = mesh.rest_positions_m.col(i);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(x.size());
  contact.AddForce({x, v, 0.0, true}, f, nullptr);
  EXPECT_EQ(f.norm(), 0.0);
  EXPECT_TRUE(contact.active_contacts().empty());
}

TEST(PenaltyContact, DamperNeverPullsSkinTowardObject) {
  const TetMesh mesh = MakeBoxMesh({kSide, kSide, kHeight}, {1, 1, 1}, testing::Skin());
  const auto top = testing::NodesWhere(mesh, 2, kHeight);
  PenaltyContactForce contact(top, {PlaneFromAbove(kHeight - 1e-6)}, ContactParams{1e4, 10.0});
  Eigen::VectorXd x(3 * mesh.num_nodes()), v = Eigen::VectorXd::Zero(3 * mesh.num_nodes());
  for (int i = 0; i < mesh.num_nodes(); ++i) {
    x.segment<3>(3 * i) = mesh.rest_positions_m.col(i);
    v.segment<3>(3 * i) = Eigen::Vector3d(0, 0, -1.0);  // separating fast
  }
  Eigen::VectorXd f = Eigen::VectorXd::Zero(x.size());
  contact.AddForce({x, v, 0.0, true}, f, nullptr);
  for (int i : top) EXPECT_GE(-f[3 * i + 2], 0.0);  // force on skin points away from the plane (-z) or is zero
}

TEST(PseudoFriction, TangentialSpringResistsSlidingUpToCoulombLimit) {
  const TetMesh mesh = MakeBoxMesh({kSide, kSide, kHeight}, {1, 1, 1}, testing::Skin());
  const auto top = testing::NodesWhere(mesh, 2, kHeight);
  PenaltyContactForce contact(top, {PlaneFromAbove(kHeight - 1e-4)}, ContactParams{1e4, 0.0});
  PseudoFrictionForce friction(contact, 0.5, 0.3);
  SystemMatrix A;
  A.Build(mesh.num_nodes(), {});
  contact.BindMatrix(A);
  friction.BindMatrix(A);
  Eigen::VectorXd x(3 * mesh.num_nodes()), v = Eigen::VectorXd::Zero(3 * mesh.num_nodes());
  for (int i = 0; i < mesh.num_nodes(); ++i) x.segment<3>(3 * i) = mesh.rest_positions_m.col(i);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(x.size());
  contact.AddForce({x, v, 0.0, false}, f, nullptr);
  friction.AddForce({x, v, 0.0, false}, f, nullptr);
  friction.EndStep({x, v, 0.0, false});
  EXPECT_EQ(friction.num_anchors(), top.size());
  // Slide the skin 10 um in x: tangential force = -a k dx, below mu * f_n = 0.3 N.
  for (int i : top) x[3 * i] += 1e-5;
  f.setZero();
  contact.AddForce({x, v, 0.0, false}, f, nullptr);
  friction.AddForce({x, v, 0.0, false}, f, nullptr);
  for (int i : top) EXPECT_NEAR(f[3 * i], -0.5 * 1e4 * 1e-5, 1e-9);
  // Slide 1 mm: capped at mu * f_n = 0.3 * 1 N.
  for (int i : top) x[3 * i] += 1e-3;
  f.setZero();
  contact.AddForce({x, v, 0.0, false}, f, nullptr);
  friction.AddForce({x, v, 0.0, false}, f, nullptr);
  for (int i : top) EXPECT_NEAR(f[3 * i], -0.3 * 1e4 * 1e-4, 1e-9);
}

}  // namespace
}  // namespace sedbridge::fem
