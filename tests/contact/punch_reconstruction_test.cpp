// The flat-faced punches (rectangular and round) as primitives of the reconstruction: their
// parameters recovered from their own forward prediction in noise, a sphere not read as a
// punch, and the rig's punches.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <cmath>
#include <random>

#include "common/resource_path.h"
#include "contact/contact_reconstruction.h"
#include "sensors/calibration_press.h"
#include "tests/contact/reconstruction_test_support.h"

namespace sedbridge::contact {
namespace {

using sensors::ContactPrimitive;
using sensors::ContactShape;
using test_support::HeldFor;
using test_support::ReadingsOf;
using test_support::Uskin;

ContactPrimitive PunchAt(double x_mm, double y_mm, double a_mm, double b_mm, double yaw_deg, double force_N) {
  ContactPrimitive c;
  c.shape = ContactShape::kPunch;
  c.x_mm = x_mm, c.y_mm = y_mm, c.yaw_deg = yaw_deg, c.normal_force_N = force_N;
  c.half_size_mm[0] = a_mm, c.half_size_mm[1] = b_mm;
  c.radius_mm = 0;
  return c;
}

TEST(PunchReconstruction, PunchReadingsMoveSmoothlyWithItsPoseAndSize) {
  // The fit differences the readings: a punch's must not jump as it moves or grows by a
  // fraction of a load cell (0.235 mm).
  ContactPrimitive p = PunchAt(0.3, -0.2, 2.0, 1.2, 25, 0.8);
  const Eigen::VectorXd r0 = ReadingsOf({p});
  for (double* u : {&p.x_mm, &p.half_size_mm[0], &p.yaw_deg}) {
    double last = 0;
    for (int k = 1; k <= 20; ++k) {
      const double saved = *u;
      *u += 0.005 * k;
      const double d = (ReadingsOf({p}) - r0).norm();
      *u = saved;
      // Near-linear in the step: each step of 5 um adds about the same change.
      if (k > 1) {
        EXPECT_NEAR(d - last, d / k, 0.5 * d / k + 1e-9) << k;
      }
      last = d;
    }
  }
}

TEST(PunchReconstruction, PunchParametersAreRecoveredFromItsOwnPredictionInNoise) {
  std::mt19937_64 rng(51);
  // Faces a sphere does not explain within noise (a small square one it does, and the
  // selection settles on the sphere before the punch's turn: rig press_21, a 3 x 3 mm punch
  // read as a 10 mm sphere, its SED within the targets).
  for (const ContactPrimitive& truth : {PunchAt(1.0, -0.5, 2.0, 1.25, 30, 0.8), PunchAt(-1.5, 2.0, 3.0, 3.0, 45, 1.0),
                                        PunchAt(0.5, 2.0, 3.0, 1.0, -60, 1.0)}) {
    ContactReconstructor r(Uskin());
    const ContactEstimate e = HeldFor(&r, ReadingsOf({truth}), &rng, 60);
    ASSERT_TRUE(e.ok) << e.problem;
    ASSERT_EQ(e.primitive.shape, ContactShape::kPunch) << ContactShapeName(e.primitive.shape);
    EXPECT_FALSE(e.model_inadequate);
    EXPECT_LT(std::hypot(e.primitive.x_mm - truth.x_mm, e.primitive.y_mm - truth.y_mm), 0.3);
    EXPECT_NEAR(e.primitive.normal_force_N, truth.normal_force_N, 0.05 * truth.normal_force_N);
    // The sides in either order (a rectangle turned by 90 deg is its transpose).
    const bool swapped = std::abs(e.primitive.half_size_mm[0] - truth.half_size_mm[1]) <
                         std::abs(e.primitive.half_size_mm[0] - truth.half_size_mm[0]);
    const double a = e.primitive.half_size_mm[swapped ? 1 : 0], b = e.primitive.half_size_mm[swapped ? 0 : 1];
    EXPECT_NEAR(a, truth.half_size_mm[0], 0.25 * truth.half_size_mm[0]);
    EXPECT_NEAR(b, truth.half_size_mm[1], 0.25 * truth.half_size_mm[1]);
    if (std::abs(truth.half_size_mm[0] - truth.half_size_mm[1]) > 0.5) {
      EXPECT_LT(std::abs(std::remainder(e.primitive.yaw_deg + (swapped ? 90 : 0) - truth.yaw_deg, 180.0)), 10);
    }
  }
}

ContactPrimitive RoundPunchAt(double x_mm, double y_mm, double a_mm, double force_N) {
  ContactPrimitive c;
  c.shape = ContactShape::kRoundPunch;
  c.x_mm = x_mm, c.y_mm = y_mm, c.radius_mm = a_mm, c.normal_force_N = force_N;
  return c;
}

// A round punch pressed through the forward model (2-count noise, a 60-scan hold) is read as a
// round punch: its radius within 10 %, its centre within 0.3 mm, its force within 5 %, and
// adequate, where the rotation's shapes leave its hold inadequate (4 mm at 1.2 N: a 50 mm
// sphere; a 2.5 mm face at 0.9 N sits at the flag's edge as a 15 mm sphere, at 1.5 N past it).
// A small face at a light load is a sphere within noise (1.5 mm at 0.6 N: a 4.6 mm sphere at
// 0.26 sigma over the hold) and stays one: the round punch's check replaces only an
// inadequate answer (CheckRoundPunch).
TEST(PunchReconstruction, ARoundPunchIsReadAsARoundPunchOfItsRadius) {
  std::mt19937_64 rng(53);
  for (const ContactPrimitive& truth : {RoundPunchAt(-1.0, 1.5, 2.5, 1.5), RoundPunchAt(1.2, 0.4, 4.0, 1.2),
                                        RoundPunchAt(0.3, -1.2, 3.0, 1.2)}) {
    ContactReconstructor r(Uskin());
    const ContactEstimate e = HeldFor(&r, ReadingsOf({truth}), &rng, 60);
    ASSERT_TRUE(e.ok) << e.problem;
    EXPECT_EQ(e.primitive.shape, ContactShape::kRoundPunch)
        << truth.radius_mm << " mm read as " << ContactShapeName(e.primitive.shape);
    EXPECT_FALSE(e.model_inadequate);
    EXPECT_NEAR(e.primitive.radius_mm, truth.radius_mm, 0.1 * truth.radius_mm);
    EXPECT_LT(std::hypot(e.primitive.x_mm - truth.x_mm, e.primitive.y_mm - truth.y_mm), 0.3);
    EXPECT_NEAR(e.primitive.normal_force_N, truth.normal_force_N, 0.05 * truth.normal_force_N);
  }
  ContactReconstructor r(Uskin());
  const ContactEstimate e = HeldFor(&r, ReadingsOf({RoundPunchAt(0.5, -0.8, 1.5, 0.6)}), &rng, 60);
  EXPECT_EQ(e.primitive.shape, ContactShape::kSphere) << ContactShapeName(e.primitive.shape);
  EXPECT_FALSE(e.model_inadequate);
}

TEST(PunchReconstruction, ASpherePressIsNotReadAsAPunch) {
  std::mt19937_64 rng(52);
  for (double radius_mm : {2.5, 6.0, 12.0}) {
    ContactPrimitive sphere;
    sphere.x_mm = 0.8, sphere.y_mm = -0.6, sphere.radius_mm = radius_mm, sphere.normal_force_N = 0.7;
    ContactReconstructor r(Uskin());
    const ContactEstimate e = HeldFor(&r, ReadingsOf({sphere}), &rng, 60);
    ASSERT_TRUE(e.ok) << e.problem;
    EXPECT_EQ(e.primitive.shape, ContactShape::kSphere) << radius_mm << " mm read as " << ContactShapeName(e.primitive.shape);
  }
}

TEST(PunchReconstruction, OneEvaluationOfAPunchIsCheap) {
  // The per-scan budget: a punch's evaluation is a patch and its response, like a sphere's.
  const sensors::TactileForwardModel model(Uskin(), Uskin().forward_model);
  const ContactPrimitive p = PunchAt(0.3, -0.2, 3.0, 3.0, 45, 1.0);  // rig punch 22's size
  Eigen::VectorXd n, x, y;
  const int repeats = 200;
  const auto t0 = std::chrono::steady_clock::now();
  for (int k = 0; k < repeats; ++k) model.PredictLinearInShear(p, &n, &x, &y);
  const double us = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count() / repeats;
  RecordProperty("punch_evaluation_us", std::to_string(us));
  std::printf("one evaluation of a 6 x 6 mm punch: %.1f us\n", us);
  EXPECT_LT(us, 500);  // about 40 us on the development VM; generous for loaded CI machines
}

}  // namespace
}  // namespace sedbridge::contact
