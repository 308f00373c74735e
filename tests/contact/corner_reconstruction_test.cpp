// The box corner as a primitive of the reconstruction: its tip and force recovered from its own
// forward prediction in noise over a hold, and spheres the rig and the synthetic sets hold not
// read as corners. (On the leader: contact.ContactObject.ACornerIsACubeStandingOnItsTip.)
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "contact/contact_object.h"
#include "contact/contact_reconstruction.h"
#include "tests/contact/reconstruction_test_support.h"

namespace sedbridge::contact {
namespace {

using sensors::ContactPrimitive;
using sensors::ContactShape;
using test_support::HeldFor;
using test_support::ReadingsOf;
using test_support::SphereAt;
using test_support::Uskin;

ContactPrimitive CornerAt(double x_mm, double y_mm, double force_N) {
  ContactPrimitive c;
  c.shape = ContactShape::kCorner;
  c.x_mm = x_mm, c.y_mm = y_mm, c.radius_mm = 0, c.normal_force_N = force_N;
  return c;
}

// A corner pressed through the forward model (2-count noise, a 60-scan hold) at 0.2-1.5 N,
// on a taxel, between taxels and off centre: read as a corner (the rotation reads a sphere
// under 1.5 mm, which the corner's check replaces), its tip within 0.2 mm, its force within
// 5 %, adequate.
TEST(CornerReconstruction, ACornersTipAndForceAreRecoveredOverAHold) {
  std::mt19937_64 rng(57);
  for (const ContactPrimitive& truth : {CornerAt(1.0, -1.0, 0.2), CornerAt(-2.35, 0.4, 0.6), CornerAt(0.3, 2.1, 1.5)}) {
    ContactReconstructor r(Uskin());
    const ContactEstimate e = HeldFor(&r, ReadingsOf({truth}), &rng, 60);
    ASSERT_TRUE(e.ok) << e.problem;
    EXPECT_EQ(e.primitive.shape, ContactShape::kCorner)
        << truth.normal_force_N << " N read as " << ContactShapeName(e.primitive.shape) << " R" << e.primitive.radius_mm;
    EXPECT_FALSE(e.model_inadequate);
    EXPECT_LT(std::hypot(e.primitive.x_mm - truth.x_mm, e.primitive.y_mm - truth.y_mm), 0.2);
    EXPECT_NEAR(e.primitive.normal_force_N, truth.normal_force_N, 0.05 * truth.normal_force_N);
  }
}

// Spheres of the sizes the rig and the synthetic sets press stay spheres, their radius as read
// without the corner.
TEST(CornerReconstruction, SpheresAreNotReadAsCorners) {
  for (const ContactPrimitive& truth : {SphereAt(0.5, -0.8, 2.0, 0.5), SphereAt(-1.0, 1.0, 5.0, 0.5)}) {
    std::mt19937_64 rng(58), rng_without(58);
    ContactReconstructor r(Uskin());
    ReconstructionOptions without_corners;
    without_corners.fit_corners = false;
    ContactReconstructor r_without(Uskin(), without_corners);
    const ContactEstimate e = HeldFor(&r, ReadingsOf({truth}), &rng, 60);
    const ContactEstimate e_without = HeldFor(&r_without, ReadingsOf({truth}), &rng_without, 60);
    EXPECT_EQ(e.primitive.shape, ContactShape::kSphere) << ContactShapeName(e.primitive.shape);
    EXPECT_EQ(e.primitive.radius_mm, e_without.primitive.radius_mm);
  }
}

// The leader presses a corner as the scene's cube: a sharp 10 mm cube whose lowest point is
// the tip at (x, y) on the pad, its body diagonal vertical.
TEST(CornerReconstruction, ACornerIsPressedAsACubeStandingOnItsTip) {
  const geometry::RigidObject o = ToRigidObject(CornerAt(1.0, -1.0, 0.2));
  const Eigen::Vector3d tip(1e-3, -1e-3, 0), up(0, 0, 1e-4);
  // The tip is on the box's surface, 0.1 mm below it outside and 0.1 mm above it inside.
  EXPECT_NEAR(o.Evaluate(tip, 0).distance_m, 0, 1e-9);
  EXPECT_GT(o.Evaluate(tip - up, 0).distance_m, 0);
  EXPECT_LT(o.Evaluate(tip + up, 0).distance_m, 0);
  // Nothing else reaches the pad: 1 mm beside the tip the box is 0.58 mm away or more (its
  // edges rise at 35.3 deg).
  for (int k = 0; k < 12; ++k) {
    const double t = k * M_PI / 6;
    EXPECT_GT(o.Evaluate(tip + Eigen::Vector3d(1e-3 * std::cos(t), 1e-3 * std::sin(t), 0), 0).distance_m, 3e-4) << k;
  }
  const Eigen::Isometry3d pose = o.trajectory.Pose(0);
  // The centre sits half the body diagonal (8.66 mm) straight above the tip.
  EXPECT_NEAR((pose.translation() - tip - Eigen::Vector3d(0, 0, 5e-3 * std::sqrt(3.0))).norm(), 0, 1e-9);
}

}  // namespace
}  // namespace sedbridge::contact
