// A surface pressure pressed on the leader as a traction field
// (contact/surface_pressure_on_leader.h): the force that lands is the force given, a load on
// the pad's middle makes SED there, nothing makes nothing, and bad input is refused.
#include "contact/surface_pressure_on_leader.h"

#include <gtest/gtest.h>

#include "contact/contact_object.h"
#include "model/fingertip_model.h"

namespace sedbridge::contact {
namespace {

TEST(SurfacePressureOnLeader, APatchOnThePadLandsWholeAndMakesSedUnderIt) {
  const model::FingertipModel model = model::LoadFingertipModel("B");
  scene::FingertipCompliance leader(model, LeaderComplianceOptions(""));
  // A 9 x 9 grid of 0.5 mm cells around (1, -0.5) mm.
  Eigen::Matrix2Xd cells(2, 81);
  for (int k = 0; k < 81; ++k) cells.col(k) = Eigen::Vector2d(1 + 0.5 * (k % 9 - 4), -0.5 + 0.5 * (k / 9 - 4));
  SurfacePressureOnLeader on_leader(leader, cells, 0.5);
  for (int k = 0; k < 81; ++k) EXPECT_NEAR(on_leader.coverage(k), 1.0, 1e-9) << "cell " << k;
  Eigen::VectorXd force = Eigen::VectorXd::Zero(81);
  force.segment(36, 9).setConstant(0.4 / 9);  // the middle row: 0.4 N
  ASSERT_TRUE(on_leader.Press(force, Eigen::Vector2d(0.02, 0))) << on_leader.error();
  EXPECT_NEAR(on_leader.applied_force_N(), 0.4, 1e-9);
  const Eigen::VectorXd& sed = leader.sed_Pa();
  Eigen::Index peak = 0;
  ASSERT_GT(sed.maxCoeff(&peak), 0.0);
  // The SED peaks within 2 mm of the loaded row (B's Merkel vertices are about 1.5 mm apart).
  const Eigen::Vector3d at = leader.merkel_rest_pad_mm().col(peak);
  EXPECT_LT(std::hypot(at.x() - 1, at.y() + 0.5), 2.0) << at.transpose();
  // No force: no SED.
  ASSERT_TRUE(on_leader.Press(Eigen::VectorXd::Zero(81), Eigen::Vector2d::Zero()));
  EXPECT_EQ(leader.sed_Pa().maxCoeff(), 0.0);
  // Negative or non-finite forces and a wrong size are refused.
  force[3] = -0.01;
  EXPECT_FALSE(on_leader.Press(force, Eigen::Vector2d::Zero()));
  force[3] = std::nan("");
  EXPECT_FALSE(on_leader.Press(force, Eigen::Vector2d::Zero()));
  EXPECT_FALSE(on_leader.Press(Eigen::VectorXd::Zero(80), Eigen::Vector2d::Zero()));
  EXPECT_FALSE(on_leader.error().empty());
}

}  // namespace
}  // namespace sedbridge::contact
