// The leader's pad as a display meets it (render/leader_pad.h): the candidate contact
// patch's extent on B and B_coarse, the shipped displays against it, and a display that does
// not fit refused naming its profile's file:line:column before any precompute.

#include "render/leader_pad.h"

#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "display/display_profile.h"
#include "model/fingertip_model.h"
#include "render/display_on_leader.h"
#include "render/display_rendering.h"
#include "scene/fingertip_compliance.h"
#include "tests/common/file_lines.h"

namespace sedbridge::render {
namespace {

using test_util::LineOf;

// Measured 2026-11-29 (docs/display-rendering.md): B's skin facing the pad within 6 mm of
// its apex spans x -6.90..7.03 mm, y -15.79..6.42 mm; B_coarse's x -5.86..7.97, y -15.77..5.97.
TEST(LeaderPad, TheExtentIsTheCandidateContactPatchOfEachModel) {
  struct Expected {
    const char* model;
    display::PadExtent pad;
  };
  for (const Expected& e : {Expected{"B", {-6.897, 7.030, -15.789, 6.421}}, Expected{"B_coarse", {-5.858, 7.974, -15.771, 5.966}}}) {
    SCOPED_TRACE(e.model);
    const model::FingertipModel model = model::LoadFingertipModel(e.model);
    const scene::FingertipCompliance leader(model, DisplayLeaderOptions());
    const display::PadExtent pad = LeaderPadExtent(leader);
    EXPECT_NEAR(pad.x_min_mm, e.pad.x_min_mm, 1e-3);
    EXPECT_NEAR(pad.x_max_mm, e.pad.x_max_mm, 1e-3);
    EXPECT_NEAR(pad.y_min_mm, e.pad.y_min_mm, 1e-3);
    EXPECT_NEAR(pad.y_max_mm, e.pad.y_max_mm, 1e-3);
  }
}

// Every shipped display with a device model fits both leaders but pin_16x16 (16 mm wide at
// 1 mm pitch: its outer columns and tip rows lie beyond the pad), which is refused at its
// `actuators` key.
TEST(LeaderPad, TheShippedDisplaysFitButTheSixteenMillimetrePinArrayIsRefused) {
  for (const char* model_name : {"B", "B_coarse"}) {
    SCOPED_TRACE(model_name);
    const model::FingertipModel model = model::LoadFingertipModel(model_name);
    const scene::FingertipCompliance leader(model, DisplayLeaderOptions());
    for (const char* name : {"suction_4x4", "pin_6x4", "suction_8x8", "pin_8x8", "electrotactile_4x4"}) {
      SCOPED_TRACE(name);
      EXPECT_NO_THROW(CheckDisplayFitsLeaderPad(display::LoadNamedDisplayProfile(name), leader));
    }
    const display::DisplayProfile wide = display::LoadNamedDisplayProfile("pin_16x16");
    try {
      CheckDisplayFitsLeaderPad(wide, leader);
      FAIL() << "pin_16x16 accepted";
    } catch (const DisplayDoesNotFitPad& e) {
      const std::string m = e.what();
      const std::string at = wide.file + ":" + std::to_string(LineOf(wide.file, "actuators:")) + ":1";
      EXPECT_EQ(m.rfind(at + ": actuator 0 at (-7.5, 7.5) mm with its 0.4 mm pin (device at " + wide.file + ":" +
                            std::to_string(LineOf(wide.file, "device:")) + ":1) is not on the finger's pad",
                        0),
                0u)
          << m;
      EXPECT_NE(m.find("candidate contact patch of model " + std::string(model_name)), std::string::npos) << m;
      if (std::string(model_name) == "B") {
        EXPECT_NE(m.find("spans x -6.9..7.03 mm, y -15.79..6.42 mm (pad frame)"), std::string::npos) << m;
      }
    }
  }
}

// The rendering checks before its precompute (n + 1 contact solves): refused at once.
TEST(LeaderPad, DisplayRenderingRefusesADisplayOffThePadBeforeItsPrecompute) {
  const model::FingertipModel model = model::LoadFingertipModel("B_coarse");
  EXPECT_THROW(DisplayRendering(model, display::LoadNamedDisplayProfile("pin_16x16")), DisplayDoesNotFitPad);
}

}  // namespace
}  // namespace sedbridge::render
