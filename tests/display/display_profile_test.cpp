#include "display/display_profile.h"

#include <gtest/gtest.h>

#include <string>

#include "config/config_error.h"

namespace sedbridge::display {
namespace {

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

DisplayProfile Parse(const std::string& text) {
  return ParseDisplayProfile(config::LoadYamlString(text, "p.yaml"));
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
