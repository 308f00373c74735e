#include "display/display_profile.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <set>
#include <string>

#include "common/config_error.h"
#include "common/resource_path.h"
#include "common/schema_keys.h"
#include "tests/common/readme_keys.h"
#include "display/safety_limiter.h"
#include "display_test_util.h"

namespace sedbridge::display {
namespace {

using profile_text::Parse;
using profile_text::ParseMessage;

// A valid profile; tests splice one line in or out to break it.
std::string Profile(const std::string& extra_safety = "", const std::string& extra_top = "") {
  return "name: t\n"
         "kind: suction\n"
         "unit: kPa\n"
         "actuators:\n"
         "  grid: {rows: 2, cols: 3, pitch_mm: [2.0, 1.0], center_mm: [0.0, 1.0]}\n"
         "range: [0.0, 40.0]\n"
         "safety:\n"
         "  max: 20.0\n"
         "  slew_rate_per_s: 100.0\n"
         "  watchdog_timeout_s: 0.1\n" +
         extra_safety +
         "mapping:\n"
         "  sampling: max_within_radius\n"
         "  radius_mm: 1.0\n"
         "  reference_Pa: 1000.0\n"
         "  gain: 5.0\n" +
         extra_top;
}

TEST(DisplayProfile, ShippedProfilesLoad) {
  for (const char* name : {"suction_4x4", "pin_6x4", "electrotactile_4x4"}) {
    SCOPED_TRACE(name);
    const DisplayProfile p = LoadDisplayProfile(std::string("config/displays/") + name + ".yaml");
    EXPECT_EQ(p.name, name);
    EXPECT_GT(p.size(), 0u);
    EXPECT_EQ(p.unit, UnitOf(p.kind));
    EXPECT_LE(p.safety.max, p.range_max);
    EXPECT_EQ(p.safety.max_per_actuator.size(), p.size());
  }
  EXPECT_EQ(LoadDisplayProfile("config/displays/suction_4x4.yaml").kind, DisplayKind::kSuction);
  EXPECT_EQ(LoadDisplayProfile("config/displays/pin_6x4.yaml").kind, DisplayKind::kPin);
  EXPECT_EQ(LoadDisplayProfile("config/displays/electrotactile_4x4.yaml").mapping.calibration_offset.size(),
            16u);
}

TEST(DisplayProfile, GridIsRowMajorFromTheTipRow) {
  const DisplayProfile p = Parse(Profile());
  ASSERT_EQ(p.size(), 6u);
  // row 0 at the larger y (toward the tip), columns left to right.
  EXPECT_DOUBLE_EQ(p.x_mm[0], -2.0);
  EXPECT_DOUBLE_EQ(p.y_mm[0], 1.5);
  EXPECT_DOUBLE_EQ(p.x_mm[2], 2.0);
  EXPECT_DOUBLE_EQ(p.y_mm[5], 0.5);
  EXPECT_DOUBLE_EQ(p.mapping.saturation, 20.0);  // defaults to safety.max
  EXPECT_DOUBLE_EQ(p.mapping.exponent, 1.0);
}

TEST(DisplayProfile, ExplicitPositions) {
  std::string text = Profile();
  text.replace(text.find("  grid:"), text.find("range:") - text.find("  grid:"),
               "  positions_mm: [[0, 0], [1.5, -2]]\n");
  const DisplayProfile p = Parse(text);
  ASSERT_EQ(p.size(), 2u);
  EXPECT_DOUBLE_EQ(p.y_mm[1], -2.0);
}

TEST(DisplayProfile, UnknownKeyIsAnErrorWithLocation) {
  try {
    Parse(Profile("  enabled: false\n"));
    FAIL() << "unknown key accepted";
  } catch (const config::ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), "p.yaml:11:3: unknown key 'enabled'");
  }
}

TEST(DisplayProfile, MaxAboveRangeIsRejected) {
  std::string text = Profile();
  text.replace(text.find("max: 20.0"), 9, "max: 50.0");
  try {
    Parse(text);
    FAIL();
  } catch (const config::ConfigError& e) {
    EXPECT_EQ(e.where().line, 8);
    EXPECT_NE(std::string(e.what()).find("range"), std::string::npos);
  }
}

TEST(DisplayProfile, SafetyCannotBeSwitchedOff) {
  auto with = [](const std::string& from, const std::string& to) {
    std::string text = Profile();
    text.replace(text.find(from), from.size(), to);
    return text;
  };
  EXPECT_THROW(Parse(with("slew_rate_per_s: 100.0", "slew_rate_per_s: 0")), config::ConfigError);
  EXPECT_THROW(Parse(with("slew_rate_per_s: 100.0", "slew_rate_per_s: .inf")), config::ConfigError);
  EXPECT_THROW(Parse(with("watchdog_timeout_s: 0.1", "watchdog_timeout_s: 3600")),
               config::ConfigError);
  EXPECT_THROW(Parse(with("watchdog_timeout_s: 0.1", "watchdog_timeout_s: -1")), config::ConfigError);
  EXPECT_THROW(Parse(with("  max: 20.0\n", "")), config::ConfigError);
  EXPECT_THROW(Parse(with("max: 20.0", "max: .nan")), config::ConfigError);
}

TEST(DisplayProfile, EveryLimitIsCheckedAgainstItsKindsSaneRange) {
  auto with = [](const std::string& from, const std::string& to) {
    std::string text = Profile();
    text.replace(text.find(from), from.size(), to);
    return text;
  };
  // Suction cannot go past ambient: range above 100 kPa is rejected, naming the limit.
  const std::string range = ParseMessage(with("range: [0.0, 40.0]", "range: [0.0, 1e30]"));
  EXPECT_NE(range.find("p.yaml:6:8: 'range' maximum 1e+30 kPa exceeds 100 kPa"), std::string::npos) << range;
  EXPECT_NE(ParseMessage(with("range: [0.0, 40.0]", "range: [0.0, 101]")), "accepted");
  EXPECT_EQ(ParseMessage(with("range: [0.0, 40.0]", "range: [0.0, 100]")), "accepted");
  // max 1e300 (a hostile input: it published +Inf) is far outside any range.
  EXPECT_NE(ParseMessage(with("max: 20.0", "max: 1e300")), "accepted");
  // Slew: full scale in no less than 0.1 s.
  const std::string slew = ParseMessage(with("slew_rate_per_s: 100.0", "slew_rate_per_s: 1e30"));
  EXPECT_NE(slew.find("'slew_rate_per_s' must be in (0, 1000 kPa/s]"), std::string::npos) << slew;
  EXPECT_EQ(ParseMessage(with("slew_rate_per_s: 100.0", "slew_rate_per_s: 1000")), "accepted");
  // Transfer cap and calibration cannot exceed the kind's limit either.
  EXPECT_NE(ParseMessage(Profile("", "  saturation: 500\n")), "accepted");
  EXPECT_NE(ParseMessage(Profile("", "  calibration: {offset: [0, 0, 0, 0, 0, 1000]}\n")), "accepted");
  EXPECT_NE(ParseMessage(Profile("", "  calibration: {gain: [1, 1, 1, 1, 1, 1e6]}\n")), "accepted");
  // Pins: 5 mm at most; current: 10 mA at most.
  std::string pin = Profile();
  pin.replace(pin.find("kind: suction"), 13, "kind: pin");
  pin.replace(pin.find("unit: kPa"), 9, "unit: mm");
  EXPECT_NE(ParseMessage(pin), "accepted");  // range 40 mm
  pin.replace(pin.find("range: [0.0, 40.0]"), 18, "range: [0.0, 5.0]");
  pin.replace(pin.find("max: 20.0"), 9, "max: 2.0");
  pin.replace(pin.find("slew_rate_per_s: 100.0"), 22, "slew_rate_per_s: 20.0");
  EXPECT_EQ(ParseMessage(pin), "accepted");
  std::string current = Profile();
  current.replace(current.find("kind: suction"), 13, "kind: electrotactile");
  current.replace(current.find("unit: kPa"), 9, "unit: mA");
  current.replace(current.find("range: [0.0, 40.0]"), 18, "range: [0.0, 12.0]");
  current.replace(current.find("max: 20.0"), 9, "max: 4.0");
  EXPECT_NE(ParseMessage(current).find("exceeds 10 mA"), std::string::npos) << ParseMessage(current);
}

TEST(DisplayProfile, RangeMinimumIsHonoured) {
  auto with = [](const std::string& from, const std::string& to) {
    std::string text = Profile();
    text.replace(text.find(from), from.size(), to);
    return text;
  };
  // max at or below the device minimum: the display could never turn on.
  EXPECT_THROW(Parse(with("range: [0.0, 40.0]", "range: [25.0, 40.0]")), config::ConfigError);
  const DisplayProfile p = Parse(with("range: [0.0, 40.0]", "range: [3.0, 40.0]"));
  EXPECT_DOUBLE_EQ(p.range_min, 3.0);
  // ... and the limiter gets it as its dead band.
  EXPECT_DOUBLE_EQ(SafetyLimits::FromProfile(p).min_nonzero, 3.0);
}

TEST(DisplayProfile, DuplicateSafetyKeyIsAnError) {
  // A hostile input: `max: 20` then `max: 5` published 20 kPa.
  try {
    Parse(Profile("  max: 5.0\n"));
    FAIL() << "duplicate accepted";
  } catch (const config::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("p.yaml:11:3: duplicate key 'max'"), std::string::npos) << e.what();
  }
}

TEST(DisplayProfile, UnitMustMatchKind) {
  std::string text = Profile();
  text.replace(text.find("unit: kPa"), 9, "unit: mA");
  EXPECT_THROW(Parse(text), config::ConfigError);
}

TEST(DisplayProfile, CalibrationLengthMustMatchActuators) {
  EXPECT_THROW(Parse(Profile("", "  calibration: {gain: [1, 1]}\n")), config::ConfigError);
  const DisplayProfile p = Parse(Profile("", "  calibration: {offset: [0, 0, 0, 1, 1, 1]}\n"));
  EXPECT_EQ(p.mapping.calibration_offset.size(), 6u);
}

TEST(DisplayProfile, PerActuatorMaxMayOnlyLower) {
  EXPECT_THROW(Parse(Profile("  max_per_actuator: [1, 1, 1, 1, 1, 25]\n")), config::ConfigError);
  const DisplayProfile p = Parse(Profile("  max_per_actuator: [1, 2, 3, 4, 5, 0]\n"));
  EXPECT_DOUBLE_EQ(p.safety.max_per_actuator[3], 4.0);
}

TEST(DisplayProfile, MissingFileNamesThePath) {
  try {
    LoadDisplayProfile("config/displays/does_not_exist.yaml");
    FAIL();
  } catch (const config::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("does_not_exist.yaml"), std::string::npos);
  }
}

}  // namespace
}  // namespace sedbridge::display

// The key table of config/displays/README.md and the profile schema name the same keys.
namespace sedbridge::display {
namespace {

TEST(DisplayProfile, ReadmeTableNamesEverySchemaKeyAndNoOther) {
  test_util::ExpectReadmeNamesSchemaKeys(config::ResolveResource("config/displays/README.md"), config::SchemaKeys<DisplayProfile>());
}

TEST(DisplayProfile, EveryShippedProfileLoads) {
  int loaded = 0;
  for (const auto& entry : std::filesystem::directory_iterator(config::ResolveResource("config/displays"))) {
    if (entry.path().extension() != ".yaml") continue;
    SCOPED_TRACE(entry.path().string());
    EXPECT_EQ(LoadDisplayProfile(entry.path().string()).name, entry.path().stem().string());
    ++loaded;
  }
  EXPECT_GE(loaded, 3);
}

TEST(DisplayProfile, DefaultsFollowOtherKeysAndListsMatchTheActuators) {
  const DisplayProfile p = Parse(Profile());
  EXPECT_EQ(p.safety.max_per_actuator, std::vector<double>(6, 20.0));  // safety.max for each
  EXPECT_DOUBLE_EQ(p.mapping.saturation, p.safety.max);
  EXPECT_EQ(p.mapping.z_min_mm, -std::numeric_limits<double>::infinity());
  EXPECT_EQ(ParseMessage(Profile("  max_per_actuator: [1, 2]\n")), "p.yaml:11:21: 'max_per_actuator' must be a list of 6 numbers");
  EXPECT_EQ(ParseMessage(Profile("", "  calibration: {offset: []}\n")), "p.yaml:16:25: 'offset' must be a list of 6 numbers");
  EXPECT_EQ(ParseMessage(Profile("", "  z_window_mm: [2, 1]\n")), "p.yaml:16:16: 'z_window_mm' must be [min, max], min < max");
  std::string no_actuators = Profile();
  no_actuators.replace(no_actuators.find("actuators:"), 10, "actuatorz:");
  EXPECT_EQ(ParseMessage(no_actuators), "p.yaml:1:1: missing required key 'actuators'");
}

}  // namespace
}  // namespace sedbridge::display
