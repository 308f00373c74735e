// The model-adequacy flag: raised when no primitive explains a contact within noise (three
// spheres at once, a cross), not on a clean sphere.
#include <gtest/gtest.h>

#include <random>

#include "contact/contact_reconstruction.h"
#include "tests/contact/reconstruction_test_support.h"

namespace sedbridge::contact {
namespace {

using sensors::ContactPrimitive;
using sensors::ContactShape;
using test_support::HeldFor;
using test_support::Noisy;
using test_support::ReadingsOf;
using test_support::SphereAt;
using test_support::Uskin;

ContactPrimitive Rod(double yaw_deg, double length_mm, double force_N) {
  ContactPrimitive c;
  c.shape = ContactShape::kCylinder;
  c.radius_mm = 1.0, c.yaw_deg = yaw_deg, c.length_mm = length_mm, c.normal_force_N = force_N;
  return c;
}

TEST(ModelAdequacy, ThreeSpheresAtOnceAreFlagged) {
  std::mt19937_64 rng(53);
  ContactReconstructor r(Uskin());
  const ContactEstimate e =
      HeldFor(&r, ReadingsOf({SphereAt(-5, -4, 3, 0.3), SphereAt(5, -4, 3, 0.3), SphereAt(0, 5, 3, 0.3)}), &rng);
  EXPECT_TRUE(e.model_inadequate) << "read as " << ContactShapeName(e.primitive.shape) << " at " << e.rms_sigma << " sigma";
  EXPECT_GT(r.counters().model_inadequate, 0);
}

TEST(ModelAdequacy, ACrossIsFlagged) {
  std::mt19937_64 rng(54);
  ContactReconstructor r(Uskin());
  const ContactEstimate e = HeldFor(&r, ReadingsOf({Rod(0, 10, 0.4), Rod(90, 10, 0.4)}), &rng);
  EXPECT_TRUE(e.model_inadequate) << "read as " << ContactShapeName(e.primitive.shape) << " at " << e.rms_sigma << " sigma";
}

TEST(ModelAdequacy, ACleanSphereIsNeverFlaggedThroughItsPress) {
  std::mt19937_64 rng(55);
  ContactReconstructor r(Uskin());
  const ContactPrimitive sphere = SphereAt(1, -1.5, 5, 0.8);
  // Ramp up, hold, release: every contact scan explained.
  for (int k = 1; k <= 80; ++k) {
    const double share = k <= 20 ? k / 20.0 : k <= 60 ? 1.0 : (80 - k) / 20.0 + 0.05;
    ContactPrimitive at = sphere;
    at.normal_force_N *= share;
    const ContactEstimate& e = r.Reconstruct(Noisy(ReadingsOf({at}), &rng), std::vector<uint8_t>(16, 1));
    EXPECT_FALSE(e.model_inadequate) << "scan " << k << ": " << e.rms_sigma << " sigma, " << e.problem;
  }
  EXPECT_EQ(r.counters().model_inadequate, 0);
}

}  // namespace
}  // namespace sedbridge::contact
