// The leader press of a reconstructed contact (contact_object.h): its relaxed force
// tolerance gives the tight press's answer to the tolerance it promises, for fewer solves.
#include "bridge/contact_object.h"

#include <gtest/gtest.h>

#include "model/fingertip_model.h"

namespace sedbridge::bridge {
namespace {

// A hold as the bridge sees it: one object, scan after scan, its force estimate wandering
// by the reconstruction's noise (about 1 %), warm-started from the last answer.
TEST(ContactObject, ReconstructedPressMatchesTheTightPressWithFewerSolves) {
  const model::FingertipModel model = model::LoadFingertipModel("B_coarse");
  scene::FingertipCompliance relaxed(model), tight(model);
  sensors::ContactPrimitive sphere;
  sphere.radius_mm = 5;
  sphere.x_mm = 0.3;
  sphere.y_mm = 1.0;
  const std::vector<geometry::RigidObject> objects{ToRigidObject(sphere)};
  const scene::PressToForceOptions options = ReconstructedPressOptions();
  int relaxed_solves = 0, tight_solves = 0;
  for (const double target_N : {0.40, 0.60, 0.80, 0.805, 0.797, 0.802, 0.799, 0.801, 0.796, 0.803}) {
    const scene::PressToForceResult r = relaxed.PressToForce(objects, target_N, options);
    const scene::PressToForceResult t = tight.PressToForce(objects, target_N);
    ASSERT_TRUE(r.reached) << target_N << ": " << r.message;
    ASSERT_TRUE(t.reached) << target_N << ": " << t.message;
    EXPECT_NEAR(r.force_N, target_N, options.relative_tolerance * target_N);
    // SED ~ force^(1..1.5) near the answer: a 1e-3 force error moves it by at most ~2e-3.
    EXPECT_LT((relaxed.sed_Pa() - tight.sed_Pa()).norm(), 2e-3 * tight.sed_Pa().norm()) << target_N;
    relaxed_solves += r.iterations;
    tight_solves += t.iterations;
  }
  EXPECT_LT(relaxed_solves, tight_solves) << "relaxed " << relaxed_solves << ", tight " << tight_solves;
}

}  // namespace
}  // namespace sedbridge::bridge
