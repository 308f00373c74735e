// The device model of a display profile (key `device`): shipped blocks, every refusal
// naming file:line:column, and the check that a display's actuators lie on the finger's pad.
#include "display/display_device.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <string>

#include "common/config_error.h"
#include "display/display_profile.h"
#include "display_test_util.h"
#include "tests/common/file_lines.h"

namespace sedbridge::display {
namespace {

using profile_text::Parse;
using profile_text::ParseMessage;

// The finger pad's contact face used for "fits the pad": half extents 8 mm across (x) and
// 10 mm along the finger (y), about model B's 16 mm width and the flat part of its 22 mm
// length (config/models/B.yaml).
constexpr double kPadHalfX_mm = 8.0, kPadHalfY_mm = 10.0;

// A suction profile with a device block (lines 6-9), 2 rows x 3 columns at 2 mm x 1 mm pitch
// centred on (0, 1): sites at x = -2, 0, 2 and y = 1.5, 0.5.
std::string Suction(const std::string& device = "  hole_radius_mm: 0.4\n"
                                                "  preload_kPa: 5.0\n"
                                                "  surface_half_size_mm: [3.0, 2.0]\n") {
  return "name: t\n"
         "kind: suction\n"
         "unit: kPa\n"
         "actuators:\n"
         "  grid: {rows: 2, cols: 3, pitch_mm: [2.0, 1.0], center_mm: [0.0, 1.0]}\n"
         "device:\n" +
         device +
         "range: [0.0, 40.0]\n"
         "safety: {max: 20.0, slew_rate_per_s: 100.0, watchdog_timeout_s: 0.1}\n"
         "mapping: {sampling: max_within_radius, radius_mm: 1.0, reference_Pa: 1000.0, gain: 5.0}\n";
}

// A pin profile (2 x 2 pins at 2 mm pitch, range [0, 2] mm, safety.max 1.5 mm) with the
// device block `device` from line 6.
std::string Pin(const std::string& device) {
  return "name: t\n"
         "kind: pin\n"
         "unit: mm\n"
         "actuators:\n"
         "  grid: {rows: 2, cols: 2, pitch_mm: [2.0, 2.0], center_mm: [0.0, 0.0]}\n"
         "device:\n" +
         device +
         "range: [0.0, 2.0]\n"
         "safety: {max: 1.5, slew_rate_per_s: 10.0, watchdog_timeout_s: 0.1}\n"
         "mapping: {sampling: interpolate, radius_mm: 1.0, reference_Pa: 1000.0, gain: 1.0}\n";
}

const std::string kRoundedPin =
    "  pin_radius_mm: 0.5\n"
    "  tip: rounded\n"
    "  tip_radius_mm: 0.5\n"
    "  travel_mm: 2.0\n"
    "  preload_kPa: 5.0\n"
    "  surface_half_size_mm: [3.0, 3.0]\n";

// `block` with the line that starts with `key` replaced by `line` ("" drops it).
std::string With(std::string block, const std::string& key, const std::string& line) {
  const std::size_t at = block.find("  " + key + ":");
  EXPECT_NE(at, std::string::npos) << key;
  block.replace(at, block.find('\n', at) + 1 - at, line.empty() ? "" : line + "\n");
  return block;
}

TEST(DisplayDevice, ShippedProfilesParseWithTheirDeviceBlocks) {
  const DisplayProfile suction = LoadNamedDisplayProfile("suction_4x4");
  ASSERT_TRUE(suction.has_device_model());
  EXPECT_EQ(suction.device.kind, DisplayKind::kSuction);
  EXPECT_DOUBLE_EQ(suction.device.hole_radius_mm, 0.5);  // about 1 mm holes
  EXPECT_DOUBLE_EQ(suction.device.footprint_radius_mm(), 0.5);
  EXPECT_DOUBLE_EQ(suction.device.preload_kPa, 5.0);
  ASSERT_EQ(suction.device.footprints.size(), suction.size());
  for (std::size_t i = 0; i < suction.size(); ++i) {
    EXPECT_DOUBLE_EQ(suction.device.footprints[i].x_mm, suction.x_mm[i]);
    EXPECT_DOUBLE_EQ(suction.device.footprints[i].y_mm, suction.y_mm[i]);
    EXPECT_DOUBLE_EQ(suction.device.footprints[i].radius_mm, 0.5);
  }
  EXPECT_EQ(suction.device.surface_center_mm, (std::array<double, 2>{0.0, 0.0}));

  const DisplayProfile pin = LoadNamedDisplayProfile("pin_6x4");
  ASSERT_TRUE(pin.has_device_model());
  EXPECT_EQ(pin.device.kind, DisplayKind::kPin);
  EXPECT_DOUBLE_EQ(pin.device.pin_radius_mm, 0.5);
  EXPECT_EQ(pin.device.tip, PinTip::kRounded);
  EXPECT_DOUBLE_EQ(pin.device.tip_radius_mm, 0.5);
  EXPECT_DOUBLE_EQ(pin.device.travel_mm, 2.0);
  EXPECT_GE(pin.device.travel_mm, pin.range_max);
  EXPECT_EQ(pin.device.surface_center_mm, (std::array<double, 2>{0.0, 0.0}));  // the grid's center_mm

  EXPECT_FALSE(LoadNamedDisplayProfile("electrotactile_4x4").has_device_model());
}

// The pitch study's displays: hypothetical, 1 mm pitch, the curve's sampling radius half the
// pitch, the footprint radius below it.
TEST(DisplayDevice, HypotheticalDenserProfilesLoadForThePitchStudy) {
  for (const char* name : {"suction_8x8", "pin_8x8", "pin_16x16"}) {
    SCOPED_TRACE(name);
    const DisplayProfile p = LoadNamedDisplayProfile(name);
    EXPECT_NE(p.description.find("hypothetical, for the pitch study"), std::string::npos);
    ASSERT_TRUE(p.has_device_model());
    const double pitch_mm = NearestActuatorDistance_mm(p.x_mm, p.y_mm);
    EXPECT_DOUBLE_EQ(pitch_mm, 1.0);
    EXPECT_DOUBLE_EQ(p.mapping.radius_mm, pitch_mm / 2);
    EXPECT_LT(p.device.footprint_radius_mm(), pitch_mm / 2);
  }
  EXPECT_EQ(LoadNamedDisplayProfile("suction_8x8").size(), 64u);
  EXPECT_EQ(LoadNamedDisplayProfile("pin_8x8").size(), 64u);
  EXPECT_EQ(LoadNamedDisplayProfile("pin_16x16").size(), 256u);
}

TEST(DisplayDevice, IsOptionalAndTheKeysAreLocated) {
  std::string no_device = Suction();
  no_device.erase(no_device.find("device:"), no_device.find("range:") - no_device.find("device:"));
  const DisplayProfile plain = Parse(no_device);
  EXPECT_FALSE(plain.has_device_model());
  EXPECT_EQ(plain.device_at.line, 0);  // absent: no location
  EXPECT_EQ(plain.actuators_at.str(), "p.yaml:4:1");

  const DisplayProfile p = Parse(Suction());
  EXPECT_TRUE(p.has_device_model());
  EXPECT_EQ(p.actuators_at.str(), "p.yaml:4:1");
  EXPECT_EQ(p.device_at.str(), "p.yaml:6:1");
  EXPECT_EQ(p.device.surface_center_mm, (std::array<double, 2>{0.0, 1.0}));
  EXPECT_DOUBLE_EQ(p.device.footprints[0].x_mm, -2.0);
  EXPECT_DOUBLE_EQ(p.device.footprints[0].y_mm, 1.5);
  EXPECT_DOUBLE_EQ(p.device.footprints[5].radius_mm, 0.4);
}

TEST(DisplayDevice, HoleRadiusMustBeBelowHalfTheNearestActuatorDistance) {
  // Nearest sites are 1 mm apart (the y pitch), so 0.5 mm holes would touch.
  EXPECT_EQ(ParseMessage(Suction("  hole_radius_mm: 0.5\n  preload_kPa: 5.0\n  surface_half_size_mm: [3.0, 2.0]\n")),
            "p.yaml:7:19: 'hole_radius_mm' (0.5 mm) must be below half the nearest actuator distance (1 mm / 2): "
            "neighbouring holes would overlap");
  EXPECT_EQ(ParseMessage(Suction("  hole_radius_mm: 0\n  preload_kPa: 5.0\n  surface_half_size_mm: [3.0, 2.0]\n")),
            "p.yaml:7:19: 'hole_radius_mm' must be > 0 (got 0)");
  EXPECT_EQ(ParseMessage(Pin(With(With(kRoundedPin, "pin_radius_mm", "  pin_radius_mm: 1.0"), "tip_radius_mm",
                                  "  tip_radius_mm: 1.0"))),
            "p.yaml:7:18: 'pin_radius_mm' (1 mm) must be below half the nearest actuator distance (2 mm / 2): "
            "neighbouring pins would overlap");
}

TEST(DisplayDevice, PinTravelMustCoverSafetyMaxAndTheRange) {
  EXPECT_EQ(ParseMessage(Pin(With(kRoundedPin, "travel_mm", "  travel_mm: 1.0"))),
            "p.yaml:10:14: 'travel_mm' (1 mm) is below safety.max (1.5 mm): the limiter would allow heights the pin "
            "cannot reach");
  EXPECT_EQ(ParseMessage(Pin(With(kRoundedPin, "travel_mm", "  travel_mm: 1.8"))),
            "p.yaml:10:14: 'travel_mm' (1.8 mm) is below range[1] (2 mm): the device would accept heights beyond "
            "its pin's stroke");
  EXPECT_EQ(ParseMessage(Pin(With(kRoundedPin, "travel_mm", "  travel_mm: 6.0"))),
            "p.yaml:10:14: 'travel_mm' (6 mm) exceeds 5 mm, the most any pin display may take "
            "(config/displays/README.md)");
}

TEST(DisplayDevice, TipRadiusBelongsToRoundedTipsOnly) {
  const std::string flat = With(With(kRoundedPin, "tip", "  tip: flat"), "tip_radius_mm", "");
  EXPECT_EQ(Parse(Pin(flat)).device.tip, PinTip::kFlat);
  EXPECT_EQ(Parse(Pin(flat)).device.tip_radius_mm, 0.0);
  EXPECT_EQ(ParseMessage(Pin(With(kRoundedPin, "tip", "  tip: flat"))),
            "p.yaml:9:18: 'tip_radius_mm' is for a rounded tip; a flat tip has none");
  EXPECT_EQ(ParseMessage(Pin(With(kRoundedPin, "tip_radius_mm", ""))), "p.yaml:8:8: a rounded tip needs 'tip_radius_mm'");
  EXPECT_EQ(ParseMessage(Pin(With(kRoundedPin, "tip_radius_mm", "  tip_radius_mm: 0.3"))),
            "p.yaml:9:18: 'tip_radius_mm' (0.3 mm) must be >= 'pin_radius_mm' (0.5 mm): the tip is a spherical cap "
            "on the pin");
  EXPECT_EQ(ParseMessage(Pin(With(kRoundedPin, "tip", "  tip: pointed"))),
            "p.yaml:8:8: 'tip' must be one of: flat, rounded (got 'pointed')");
}

TEST(DisplayDevice, ElectrotactileHasNoDeviceModel) {
  std::string electro = Suction();
  electro.replace(electro.find("kind: suction"), 13, "kind: electrotactile");
  electro.replace(electro.find("unit: kPa"), 9, "unit: mA");
  electro.replace(electro.find("range: [0.0, 40.0]"), 18, "range: [0.0, 10.0]");
  electro.replace(electro.find("max: 20.0"), 9, "max: 4.0");
  EXPECT_EQ(ParseMessage(electro),
            "p.yaml:6:1: electrotactile has no mechanical load: its rendering is against the SA1 rate estimate; "
            "remove 'device'");
  // Refused for the kind, whatever the block holds.
  electro.replace(electro.find("hole_radius_mm"), 14, "electrode_radius_mm");
  EXPECT_NE(ParseMessage(electro).find("p.yaml:6:1: electrotactile has no mechanical load"), std::string::npos);
}

TEST(DisplayDevice, UnknownDuplicateMissingAndOtherKindsKeysAreRefused) {
  EXPECT_EQ(ParseMessage(Suction("  hole_radius_mm: 0.4\n  preload_kPa: 5.0\n  surface_half_size_mm: [3.0, 2.0]\n"
                                 "  hole_depth_mm: 1.0\n")),
            "p.yaml:10:3: unknown key 'hole_depth_mm'");
  EXPECT_NE(ParseMessage(Suction("  hole_radius_mm: 0.4\n  hole_radius_mm: 0.3\n  preload_kPa: 5.0\n"
                                 "  surface_half_size_mm: [3.0, 2.0]\n"))
                .find("p.yaml:8:3:"),
            std::string::npos);
  EXPECT_EQ(ParseMessage(Suction("  hole_radius_mm: 0.4\n  surface_half_size_mm: [3.0, 2.0]\n")),
            "p.yaml:7:3: a suction display's 'device' needs 'preload_kPa'");
  EXPECT_EQ(ParseMessage(Suction("  hole_radius_mm: 0.4\n  travel_mm: 2.0\n  preload_kPa: 5.0\n"
                                 "  surface_half_size_mm: [3.0, 2.0]\n")),
            "p.yaml:8:14: 'travel_mm' is no key of a suction display's device (it takes hole_radius_mm, preload_kPa, "
            "surface_half_size_mm)");
  EXPECT_EQ(ParseMessage(Pin(With(kRoundedPin, "pin_radius_mm", "  hole_radius_mm: 0.5"))),
            "p.yaml:7:19: 'hole_radius_mm' is no key of a pin display's device (it takes pin_radius_mm, tip, "
            "tip_radius_mm, travel_mm, preload_kPa, surface_half_size_mm)");
  EXPECT_EQ(ParseMessage(Pin(With(kRoundedPin, "travel_mm", ""))), "p.yaml:7:3: a pin display's 'device' needs 'travel_mm'");
}

TEST(DisplayDevice, PreloadAndSurfaceAreBounded) {
  EXPECT_EQ(ParseMessage(Suction("  hole_radius_mm: 0.4\n  preload_kPa: 150\n  surface_half_size_mm: [3.0, 2.0]\n")),
            "p.yaml:8:16: 'preload_kPa' must be in [0, 100] (got 150)");
  EXPECT_EQ(ParseMessage(Suction("  hole_radius_mm: 0.4\n  preload_kPa: -1\n  surface_half_size_mm: [3.0, 2.0]\n")),
            "p.yaml:8:16: 'preload_kPa' must be in [0, 100] (got -1)");
  EXPECT_EQ(Parse(Suction("  hole_radius_mm: 0.4\n  preload_kPa: 0\n  surface_half_size_mm: [3.0, 2.0]\n"))
                .device.preload_kPa,
            0.0);
  // The outermost holes reach x = 2.4 mm and y = 1.9 mm from the surface centre (0, 1).
  EXPECT_EQ(ParseMessage(Suction("  hole_radius_mm: 0.4\n  preload_kPa: 5.0\n  surface_half_size_mm: [2.3, 2.0]\n")),
            "p.yaml:9:25: 'surface_half_size_mm' (2.3, 2) mm does not cover actuator 0 at (-2, 1.5) mm with its "
            "0.4 mm hole (the surface is centred on the actuators' centre (0, 1) mm)");
  EXPECT_EQ(ParseMessage(Suction("  hole_radius_mm: 0.4\n  preload_kPa: 5.0\n  surface_half_size_mm: [3.0, 60.0]\n")),
            "p.yaml:9:31: 'surface_half_size_mm' must be in (0, 50] (got 60)");
  EXPECT_EQ(ParseMessage(Suction("  hole_radius_mm: 0.4\n  preload_kPa: 5.0\n  surface_half_size_mm: [3.0]\n")),
            "p.yaml:9:25: 'surface_half_size_mm' must be a list of 2 numbers");
}

TEST(DisplayDevice, ListedSitesUseTheirBoundingBoxCentreAndNearestDistance) {
  std::string listed = Suction("  hole_radius_mm: 0.6\n  preload_kPa: 5.0\n  surface_half_size_mm: [3.0, 3.0]\n");
  listed.replace(listed.find("  grid:"), listed.find("device:") - listed.find("  grid:"),
                 "  positions_mm: [[0.0, 0.0], [4.0, 0.0], [1.5, 2.0]]\n");
  const DisplayProfile p = Parse(listed);
  EXPECT_EQ(p.device.surface_center_mm, (std::array<double, 2>{2.0, 1.0}));
  EXPECT_DOUBLE_EQ(NearestActuatorDistance_mm(p.x_mm, p.y_mm), 2.5);  // (0, 0)-(1.5, 2)
  EXPECT_EQ(NearestActuatorDistance_mm({1.0}, {2.0}), std::numeric_limits<double>::infinity());
}

using test_util::LineOf;

TEST(DisplayDevice, CheckDeviceFitsPadAcceptsTheShippedDisplaysAndRefusesAWiderGrid) {
  for (const char* name : {"suction_4x4", "pin_6x4", "electrotactile_4x4", "suction_8x8", "pin_8x8", "pin_16x16"}) {
    SCOPED_TRACE(name);
    EXPECT_EQ(CheckDeviceFitsPad(LoadNamedDisplayProfile(name), kPadHalfX_mm, kPadHalfY_mm), "");
  }
  // 16 columns at 1 mm: holes to x = 7.5 + 0.4 mm, beyond a pad 7.5 mm wide each side.
  const DisplayProfile wide = LoadNamedDisplayProfile("pin_16x16");
  const std::string m = CheckDeviceFitsPad(wide, 7.5, kPadHalfY_mm);
  EXPECT_EQ(wide.actuators_at.line, LineOf(wide.file, "actuators:"));
  EXPECT_EQ(wide.device_at.line, LineOf(wide.file, "device:"));
  EXPECT_EQ(m.rfind(wide.actuators_at.str() + ": actuator 0 at (-7.5, 7.5) mm with its 0.4 mm pin (device at " +
                        wide.device_at.str() + ") is not on the finger's pad",
                    0),
            0u)
      << m;

  // A grid wider than the pad, no device model: its sites alone are checked.
  std::string wider = Suction();
  wider.erase(wider.find("device:"), wider.find("range:") - wider.find("device:"));
  wider.replace(wider.find("rows: 2, cols: 3, pitch_mm: [2.0, 1.0]"), 38, "rows: 2, cols: 10, pitch_mm: [2.0, 1.0]");
  EXPECT_EQ(CheckDeviceFitsPad(Parse(wider), kPadHalfX_mm, kPadHalfY_mm),
            "p.yaml:4:1: actuator 0 at (-9, 1.5) mm is not on the finger's pad, whose contact face spans x -8..8 mm, "
            "y -10..10 mm (pad frame)");
  EXPECT_EQ(CheckDeviceFitsPad(Parse(Suction()), kPadHalfX_mm, kPadHalfY_mm), "");
  // On a pad narrower than the footprints: the device's radius counts.
  EXPECT_EQ(CheckDeviceFitsPad(Parse(Suction()), 2.2, kPadHalfY_mm),
            "p.yaml:4:1: actuator 0 at (-2, 1.5) mm with its 0.4 mm hole (device at p.yaml:6:1) is not on the "
            "finger's pad, whose contact face spans x -2.2..2.2 mm, y -10..10 mm (pad frame)");
}

// The leader's pad is not symmetric (it reaches further toward the finger's base than toward
// its tip): each side of the extent is checked on its own, the footprint's radius counted.
TEST(DisplayDevice, CheckDeviceFitsPadChecksEachSideOfAnAsymmetricPad) {
  const DisplayProfile p = Parse(Suction());  // holes of 0.4 mm at x -2, 0, 2 and y 1.5 (tip row), 0.5
  EXPECT_EQ(CheckDeviceFitsPad(p, PadExtent{-2.45, 2.45, 0.05, 1.95}), "");  // 0.05 mm to spare each side
  const auto refuses = [&](const PadExtent& pad, const std::string& start) {
    const std::string m = CheckDeviceFitsPad(p, pad);
    EXPECT_EQ(m.rfind(start, 0), 0u) << m;
  };
  refuses({-2.35, 2.45, 0.05, 1.95}, "p.yaml:4:1: actuator 0 at (-2, 1.5) mm with its 0.4 mm hole");
  refuses({-2.45, 2.35, 0.05, 1.95}, "p.yaml:4:1: actuator 2 at (2, 1.5) mm");
  refuses({-2.45, 2.45, 0.05, 1.85}, "p.yaml:4:1: actuator 0 at (-2, 1.5) mm");
  refuses({-2.45, 2.45, 0.15, 1.95}, "p.yaml:4:1: actuator 3 at (-2, 0.5) mm");
}

}  // namespace
}  // namespace sedbridge::display
