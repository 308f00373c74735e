// Display fidelity end to end (fidelity/display_fidelity.h): the bridge's SED of a few rig
// presses rendered by the curve and the inverse renderer on a pin display, delivered by full
// contact on the leader, scored against the truth; a suction display listed, not rendered
// (until its load on the leader is built); wrong names refused before any precompute.
#include "fidelity/display_fidelity.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/resource_path.h"
#include "display/display_profile.h"
#include "fidelity/fidelity_benchmark.h"
#include "fidelity/fidelity_case.h"

namespace sedbridge::fidelity {
namespace {

// The benchmark's model. (On B_coarse, 16 skin nodes touch the plate, and a pin raised
// 1.5 mm fails the contact solve's convergence: no row to score.)
constexpr const char* kModel = "B";

TEST(DisplayFidelity, PinDisplayRowsAreFilledWithinTheLimitsForBothRenderings) {
  const sensors::SensorProfile profile = sensors::LoadNamedSensorProfile("uskin_4x4");
  const auto presses =
      sensors::LoadCalibrationPresses(config::ResolveResource("config/sensors/rig_uskin_4x4/cases.json"), profile);
  FidelityBenchmark bench(kModel, profile, display::LoadNamedDisplayProfile("suction_4x4"), "");
  DisplayFidelityOptions options;
  options.displays = {"pin_6x4", "suction_4x4"};
  DisplayFidelity fidelity(kModel, options);
  ASSERT_EQ(fidelity.displays().size(), 2u);
  EXPECT_TRUE(fidelity.displays()[0].has_load);
  EXPECT_GT(fidelity.displays()[0].precompute_s, 0.0);
  std::vector<DisplayFidelityRow> all;
  for (int i : {3, 6}) {  // spheres of 5 and 8 mm
    FidelityMaps maps;
    const FidelityRow row = bench.Run(FromCalibrationPress(presses[size_t(i)]), &maps);
    ASSERT_TRUE(row.truth_valid) << row.truth_press;
    const std::vector<DisplayFidelityRow> rows = fidelity.Score(row, maps);
    ASSERT_EQ(rows.size(), 4u);  // two displays x (curve, inverse)
    for (const DisplayFidelityRow& r : rows) {
      SCOPED_TRACE(r.case_name + " " + r.display + " " + r.rendering);
      EXPECT_EQ(r.case_name, row.name);
      // No suction load on the leader yet: listed, never rendered. Once it is built, its
      // rows are held to what the pin's are.
      if (r.display == "suction_4x4" && !fidelity.displays()[1].has_load) {
        EXPECT_EQ(r.status, "no device load yet");
        EXPECT_EQ(r.render_ms, 0.0);
        continue;
      }
      EXPECT_EQ(r.status, "ok");
      EXPECT_TRUE(r.scored);
      EXPECT_EQ(r.actuators, r.display == "pin_6x4" ? 24 : 16);
      for (double v : {r.delivered.peak_ratio, r.delivered.rel_l2, r.delivered.peak_offset_mm, r.vs_asked_rel_l2,
                       r.render_ms, r.delivered_max_sed_Pa})
        EXPECT_TRUE(std::isfinite(v));
      EXPECT_GT(r.delivered_max_sed_Pa, 0.0);
      EXPECT_GT(r.delivered.peak_ratio, 0.0);
      EXPECT_GT(r.render_ms, 0.0);
      // Within the physical bounds: no command above the profile's maximum.
      EXPECT_LE(r.max_command_share, 1.0);
      EXPECT_GT(r.max_command_share, 0.0);
      EXPECT_LE(r.commands_at_max, r.actuators);
      EXPECT_DOUBLE_EQ(r.truth_max_sed_Pa, row.truth_max_sed_Pa);
      EXPECT_DOUBLE_EQ(r.asked_max_sed_Pa, maps.recon.maxCoeff());
    }
    all.insert(all.end(), rows.begin(), rows.end());
  }
  const std::vector<DisplayFidelitySummary> summary = SummarizeDisplayFidelity(all);
  ASSERT_EQ(summary.size(), 4u);
  EXPECT_EQ(summary[0].display, "pin_6x4");
  EXPECT_EQ(summary[0].rendering, "curve");
  EXPECT_EQ(summary[1].rendering, "inverse");
  for (int k : {0, 1}) {
    EXPECT_EQ(summary[size_t(k)].scored, 2);
    EXPECT_EQ(summary[size_t(k)].deliver_failed, 0);
    EXPECT_GT(summary[size_t(k)].peak_ratio, 0.0);
  }
  if (!fidelity.displays()[1].has_load) {
    EXPECT_EQ(summary[2].scored, 0);
    EXPECT_EQ(summary[2].status, "no device load yet");
  }
}

// Listed, never rendered: electrotactile (no mechanical load, not "yet") and a display
// whose footprints leave the leader's pad (pin_16x16 on B: refused naming its `actuators`
// key's file:line:column, before its precompute).
TEST(DisplayFidelity, ElectrotactileAndADisplayOffThePadAreListedWithWhy) {
  DisplayFidelityOptions options;
  options.displays = {"electrotactile_4x4", "pin_16x16"};
  DisplayFidelity fidelity(kModel, options);
  ASSERT_EQ(fidelity.displays().size(), 2u);
  const auto& electro = fidelity.displays()[0];
  EXPECT_FALSE(electro.has_load);
  EXPECT_EQ(electro.no_load_status, "no mechanical load");
  EXPECT_NE(electro.no_load_reason.find("SA1 rate estimate"), std::string::npos) << electro.no_load_reason;
  const auto& wide = fidelity.displays()[1];
  EXPECT_FALSE(wide.has_load);
  EXPECT_EQ(wide.no_load_status, "does not fit the pad");
  const display::DisplayProfile p = display::LoadNamedDisplayProfile("pin_16x16");
  EXPECT_EQ(wide.no_load_reason.rfind(p.actuators_at.str() + ": actuator 0 at (-7.5, 7.5) mm", 0), 0u)
      << wide.no_load_reason;
}

TEST(DisplayFidelity, UnknownDisplayIsRefusedBeforeAnyPrecompute) {
  DisplayFidelityOptions options;
  options.displays = {"pin_6x4", "pin_7x7"};
  try {
    DisplayFidelity fidelity(kModel, options);
    FAIL() << "an unknown display was accepted";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("unknown display 'pin_7x7'"), std::string::npos) << what;
    EXPECT_NE(what.find("pin_8x8"), std::string::npos) << what;  // the shipped names are listed
  }
  options.displays = {};
  EXPECT_THROW(DisplayFidelity(kModel, options), std::invalid_argument);
}

TEST(DisplayFidelity, NameListsAndRenderingsAreParsedStrictly) {
  EXPECT_EQ(SplitNameList("pin_6x4,pin_8x8", "--display-fidelity"), (std::vector<std::string>{"pin_6x4", "pin_8x8"}));
  EXPECT_THROW(SplitNameList("pin_6x4,,pin_8x8", "--display-fidelity"), std::invalid_argument);
  EXPECT_THROW(SplitNameList("pin_6x4,pin_6x4", "--display-fidelity"), std::invalid_argument);
  EXPECT_THROW(SplitNameList("", "--display-fidelity"), std::invalid_argument);
  const auto both = ParseRenderings("inverse,curve");
  ASSERT_EQ(both.size(), 2u);
  EXPECT_EQ(both[0], DisplayRenderingMethod::kInverse);
  EXPECT_EQ(both[1], DisplayRenderingMethod::kCurve);
  EXPECT_THROW(ParseRenderings("curve,lut"), std::invalid_argument);
}

}  // namespace
}  // namespace sedbridge::fidelity
