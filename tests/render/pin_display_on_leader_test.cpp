#include "render/pin_display_on_leader.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <stdexcept>

#include "display/display_profile.h"
#include "model/fingertip_model.h"
#include "render/display_on_leader.h"
#include "render/display_rendering.h"
#include "render/inverse_renderer.h"
#include "leader_test_util.h"
#include "render/suction_display_on_leader.h"

namespace sedbridge::render {
namespace {

using testing::FaceContact;
using testing::Leader;
using testing::RelativeL2;

// The pin_6x4 display on B_coarse: what the linear influence (about the preloaded plate)
// says a command vector does against the full contact solve of the same pins.
TEST(PinDisplayOnLeader, LinearInfluenceAgreesWithTheFullContactWhereTheLoadIsLinear) {
  Leader leader;
  const display::DisplayProfile profile = display::LoadNamedDisplayProfile("pin_6x4");
  ASSERT_TRUE(profile.has_device_model());
  PinDisplayOnLeader display(leader.fingertip, profile.device);
  EXPECT_GT(display.preload_depth_mm(), 0.0);
  const double h_ref = 0.2;
  const DisplayInfluence influence(display.Influence(h_ref), /*prune_relative=*/0.0);
  const int n = display.num_actuators();

  // With every pin at rest the influence is the preloaded plate itself.
  Eigen::VectorXd full, linear;
  ASSERT_TRUE(display.Press(Eigen::VectorXd::Zero(n), full)) << display.error();
  EXPECT_LE(RelativeL2(influence.preload_sed_Pa(), full), 1e-9);

  struct Case {
    const char* name;
    Eigen::VectorXd heights_mm;
    double bound;
  };
  Eigen::VectorXd one = Eigen::VectorXd::Zero(n), two = one, all = one, tall = one;
  one[9] = display.gaps_mm()[9] + h_ref;  // a knot: the influence's own press
  two[9] = 0.3, two[14] = 0.15;
  all.setConstant(0.1);
  tall[9] = 0.8;
  // Bounds: the measured agreement (B_coarse, 2026-11-29) with a margin, so that a change
  // to the contact or the influence that moves it shows. Of the whole layer's SED, the
  // preload's share included; the SED the pins add differs far more (printed): the
  // linearization keeps each pin's own contact set at h_ref.
  // Measured with each pin's gap, five knots and pins pressed at least the sample spacing
  // wide, pin_6x4 centred on the pad (2026-11-29): rel L2 0.053, 0.023, 0.002 (the SED the
  // pins add: 0.58, 0.28, 0.003); at its former centre (0, 1 mm): 0.056, 0.048, 0.015
  // (added 0.29, 0.41, 0.025; one slope
  // at h_ref and the device's 0.5 mm pins gave 0.56-0.89 there). Several pins at once
  // interact through the plate's contact, which a sum of single-pin responses misses.
  for (const Case& c : {Case{"one pin at a knot", one, 1e-6}, Case{"two pins", two, 0.08},
                        Case{"every pin 0.1 mm", all, 0.07}, Case{"one pin 0.8 mm", tall, 0.03}}) {
    ASSERT_TRUE(display.Press(c.heights_mm, full)) << c.name << ": " << display.error();
    influence.Sed(c.heights_mm, linear);
    const double l2 = RelativeL2(linear, full);
    const double added_l2 = RelativeL2(linear - influence.preload_sed_Pa(), full - influence.preload_sed_Pa());
    std::printf("%-18s peak full %.1f Pa, linear %.1f Pa; added to the preload: %.1f / %.1f Pa (sum); rel L2 %.4f (added: %.3f)\n",
                c.name, full.maxCoeff(), linear.maxCoeff(), (full - influence.preload_sed_Pa()).sum(),
                (linear - influence.preload_sed_Pa()).sum(), l2, added_l2);
    EXPECT_LE(l2, c.bound) << c.name;
    if (c.bound < 1e-3) {  // the influence's own column
      EXPECT_LE(added_l2, 1e-6) << c.name;
    }
  }
}

// A pin outside the pad's contact patch on the plate touches nothing until it has risen by
// its gap: the influence starts it there, and the full contact agrees that just below the
// gap the pin adds nothing and just above it adds SED.
TEST(PinDisplayOnLeader, PinsOutsideThePlatesContactPatchRiseThroughTheirGapFirst) {
  Leader leader;
  const display::DisplayProfile profile = display::LoadNamedDisplayProfile("pin_6x4");
  PinDisplayOnLeader display(leader.fingertip, profile.device);
  const DisplayInfluence influence(display.Influence(0.2));
  const Eigen::VectorXd& gaps = display.gaps_mm();
  const int n = display.num_actuators();
  std::printf("sample spacing %.3f mm, pressed radius %.3f mm\n", display.sample_spacing_mm(), display.pressed_radius_mm());
  for (int i = 0; i < n; ++i) std::printf("pin %d gap %.3f mm\n", i, gaps[i]);
  EXPECT_LE(gaps.minCoeff(), 0.02);  // pins under the contact patch touch at once
  int gapped = 0;
  Eigen::VectorXd full, zero;
  ASSERT_TRUE(display.Press(Eigen::VectorXd::Zero(n), zero));
  for (int i = 0; i < n; ++i) {
    EXPECT_DOUBLE_EQ(influence.command_offset(i), gaps[i]);
    if (gaps[i] < 0.1 || gaps[i] >= profile.device.travel_mm) continue;
    ++gapped;
    Eigen::VectorXd h = Eigen::VectorXd::Zero(n);
    // The gap is found within one search step (a fifth of the pin radius, at most 0.1 mm:
    // extrapolated from two touching heights, which a curving contact bends), so "below"
    // is a step below it, or 0.9 of it where that is lower. (With pin_6x4 centred on the
    // pad, pins 7 and 10, gaps 0.34 and 0.26 mm on B_coarse, touch above 0.9 of them.)
    const double step_mm = std::min(0.1, 0.2 * profile.device.pin_radius_mm);
    h[i] = std::min(0.9 * gaps[i], gaps[i] - step_mm);
    ASSERT_TRUE(display.Press(h, full)) << display.error();
    EXPECT_LE((full - zero).cwiseAbs().maxCoeff(), 1e-6 * zero.maxCoeff()) << "pin " << i << " below its gap";
    h[i] = gaps[i] + 0.1;
    ASSERT_TRUE(display.Press(h, full)) << display.error();
    EXPECT_GT((full - zero).maxCoeff(), 1.0) << "pin " << i << " above its gap";
  }
  EXPECT_GE(gapped, 4);  // the pad is curved: the display's rim is off the skin
}

// The factory: a pin profile gets the pin display, a suction profile the suction display;
// a display with no mechanical load (electrotactile: no device model) is refused with a
// reason, not rendered as either.
TEST(DisplayOnLeader, FactoryBuildsPinAndSuctionDisplaysAndRefusesOneWithoutAMechanicalLoad) {
  Leader leader;
  const display::DisplayProfile pin = display::LoadNamedDisplayProfile("pin_6x4");
  const std::unique_ptr<DisplayOnLeader> display = MakeDisplayOnLeader(leader.fingertip, pin.device);
  ASSERT_NE(display, nullptr);
  EXPECT_EQ(display->num_actuators(), 24);
  EXPECT_GT(display->preload_force_N(), 0.0);
  EXPECT_GT(display->default_reference_command(), 0.0);
  EXPECT_LE(display->default_reference_command(), pin.device.travel_mm);
  EXPECT_NE(dynamic_cast<PinDisplayOnLeader*>(display.get()), nullptr);
  const display::DisplayProfile suction = display::LoadNamedDisplayProfile("suction_4x4");
  const std::unique_ptr<DisplayOnLeader> holes = MakeDisplayOnLeader(leader.fingertip, suction.device);
  ASSERT_NE(holes, nullptr);
  EXPECT_NE(dynamic_cast<SuctionDisplayOnLeader*>(holes.get()), nullptr);
  EXPECT_EQ(holes->num_actuators(), 16);
  EXPECT_GT(holes->preload_force_N(), 0.0);
  EXPECT_GT(holes->default_reference_command(), 0.0);
  EXPECT_LE(holes->default_reference_command(), suction.safety.max);
  const display::DisplayProfile electrotactile = display::LoadNamedDisplayProfile("electrotactile_4x4");
  EXPECT_THROW(MakeDisplayOnLeader(leader.fingertip, electrotactile.device), std::invalid_argument);
}

// The shared rendering object on the pin display: a target the display can render exactly
// (the influence's own SED of a command vector) comes back as those commands, within the
// box, and Deliver measures what the commands add to the preloaded pad by full contact.
TEST(DisplayRendering, RendersAnExactTargetAndDeliversByFullContact) {
  const model::FingertipModel model = model::LoadFingertipModel("B_coarse");
  const display::DisplayProfile profile = display::LoadNamedDisplayProfile("pin_6x4");
  DisplayRendering rendering(model, profile);
  const int n = rendering.num_actuators();
  ASSERT_EQ(n, 24);
  EXPECT_GT(rendering.precompute_s(), 0.0);
  Eigen::VectorXd u_true = Eigen::VectorXd::Zero(n), target;
  u_true[9] = 0.25, u_true[10] = 0.1, u_true[15] = 0.05;
  rendering.influence().Sed(u_true, target);
  target -= rendering.influence().preload_sed_Pa();
  const Eigen::VectorXd u = rendering.Render(target);
  Eigen::VectorXd rendered;
  rendering.influence().Sed(u, rendered);
  rendered -= rendering.influence().preload_sed_Pa();
  EXPECT_LE((rendered - target).norm(), 1e-3 * target.norm());
  EXPECT_TRUE((u.array() <= MaxCommands(profile).array()).all());
  Eigen::VectorXd delivered;
  ASSERT_TRUE(rendering.Deliver(Eigen::VectorXd::Zero(n), delivered)) << rendering.error();
  EXPECT_LE(delivered.cwiseAbs().maxCoeff(), 1e-9 * rendering.preload_sed_Pa().maxCoeff());
  ASSERT_TRUE(rendering.Deliver(u, delivered)) << rendering.error();
  EXPECT_GT(delivered.maxCoeff(), 0.0);
  const display::DisplayProfile electrotactile = display::LoadNamedDisplayProfile("electrotactile_4x4");
  EXPECT_THROW(DisplayRendering(model, electrotactile), std::invalid_argument);
}

}  // namespace
}  // namespace sedbridge::render
