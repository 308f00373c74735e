// The rig's cases.json shapes beyond the forward model's primitives: flat punches, pairs of
// objects and finite rods (sensors/calibration_press.h), and their keys' errors.
#include "sensors/calibration_press.h"

#include <gtest/gtest.h>
#include "tests/common/scratch_dir.h"

#include <fstream>
#include <string>

#include "common/config_error.h"
#include "common/resource_path.h"

namespace sedbridge::sensors {
namespace {

SensorProfile Uskin() { return LoadNamedSensorProfile("uskin_4x4"); }

// The error of loading `object` as the one case's object (after the file's path, from the
// first ':'), or "" when it loads past the object's checks (then the missing log fails).
std::string ObjectError(const std::string& object) {
  const std::string path = sedbridge::testing::ScratchDir() + "/cases_object_err.json";
  {
    std::ofstream f(path);
    f << "{\"cases\": [{\"object\": " << object << ", \"force_N\": 1, \"log\": \"missing.log\"}]}";
  }
  try {
    LoadCalibrationPresses(path, Uskin());
  } catch (const config::ConfigError& e) {
    return std::string(e.what()).substr(path.size());
  } catch (const std::runtime_error&) {
  }
  return "";
}

TEST(CalibrationPress, RigHoldsPunchesAPairAndAFiniteRod) {
  const auto rig = LoadCalibrationPresses(config::ResolveResource("config/sensors/rig_uskin_4x4/cases.json"), Uskin());
  ASSERT_EQ(rig.size(), 30u);
  for (size_t i = 0; i < 21; ++i) {
    EXPECT_TRUE(rig[i].is_primitive()) << rig[i].name;
    ASSERT_EQ(rig[i].objects.size(), 1u);
  }
  const CalibrationPress& punch = rig[22];  // 6 x 6 mm, turned 45 deg, at (-1.5, 2), 1 N
  EXPECT_EQ(punch.shape, PressShape::kPunch);
  EXPECT_FALSE(punch.is_primitive());
  ASSERT_EQ(punch.objects.size(), 1u);
  EXPECT_EQ(punch.objects[0].half_size_mm[0], 3.0);
  EXPECT_EQ(punch.objects[0].half_size_mm[1], 3.0);
  EXPECT_EQ(punch.objects[0].primitive.yaw_deg, 45.0);
  EXPECT_EQ(punch.objects[0].primitive.x_mm, -1.5);
  EXPECT_EQ(punch.objects[0].primitive.normal_force_N, 1.0);
  const CalibrationPress& pair = rig[24];  // two 3 mm spheres, 0.8 N split evenly
  EXPECT_EQ(pair.shape, PressShape::kPair);
  ASSERT_EQ(pair.objects.size(), 2u);
  for (const PressedObject& o : pair.objects) {
    EXPECT_EQ(o.shape, PressShape::kSphere);
    EXPECT_EQ(o.primitive.radius_mm, 3.0);
    EXPECT_DOUBLE_EQ(o.primitive.normal_force_N, 0.4);
  }
  EXPECT_EQ(pair.objects[1].primitive.x_mm, 3.0);
  const CalibrationPress& rod = rig[28];  // 1.5 mm, 6 mm long, yaw 120
  EXPECT_TRUE(rod.is_primitive());
  EXPECT_EQ(rod.object.shape, ContactShape::kCylinder);
  EXPECT_EQ(rod.object.length_mm, 6.0);
  EXPECT_EQ(rod.object.yaw_deg, 120.0);
  // fit-sensor's presses: all but the four punches and the pair.
  EXPECT_EQ(PrimitivePresses(rig).size(), 25u);
}

TEST(CalibrationPress, PunchPairAndRodKeysAreCheckedWhereTheyStand) {
  // Loads: a punch, a pair, a finite rod (then the missing log).
  EXPECT_EQ(ObjectError("{\"shape\": \"punch\", \"half_size_mm\": [1, 2], \"yaw_deg\": 30, \"position_mm\": [0, 0]}"), "");
  EXPECT_EQ(ObjectError("{\"shape\": \"pair\", \"split\": [0.25, 0.75], \"objects\": [{\"shape\": \"sphere\", "
                        "\"radius_mm\": 3, \"position_mm\": [0, 0]}, {\"shape\": \"punch\", \"half_size_mm\": [1, 1], "
                        "\"position_mm\": [3, 3]}]}"),
            "");
  EXPECT_EQ(ObjectError("{\"shape\": \"cylinder\", \"radius_mm\": 1, \"length_mm\": 6, \"position_mm\": [0, 0]}"), "");
  // The object mapping starts at column 23, its keys' values where they stand.
  EXPECT_EQ(ObjectError("{\"shape\": \"punch\", \"position_mm\": [0, 0]}"),
            ":1:23: 'half_size_mm' [a, b] (> 0) is required for a punch");
  EXPECT_EQ(ObjectError("{\"shape\": \"punch\", \"half_size_mm\": [1, 0], \"position_mm\": [0, 0]}"),
            ":1:62: 'half_size_mm' must be > 0 (got 0)");
  EXPECT_EQ(ObjectError("{\"shape\": \"punch\", \"half_size_mm\": [1], \"position_mm\": [0, 0]}"),
            ":1:58: 'half_size_mm' must be a list of 2 numbers");
  EXPECT_EQ(ObjectError("{\"shape\": \"punch\", \"half_size_mm\": [1, 1], \"radius_mm\": 1, \"position_mm\": [0, 0]}"),
            ":1:79: 'radius_mm' is a sphere's or a cylinder's, not a punch's");
  EXPECT_EQ(ObjectError("{\"shape\": \"sphere\", \"radius_mm\": 1, \"half_size_mm\": [1, 1], \"position_mm\": [0, 0]}"),
            ":1:75: 'half_size_mm' is a punch's, not a sphere's");
  EXPECT_EQ(ObjectError("{\"shape\": \"punch\", \"half_size_mm\": [1, 1]}"),
            ":1:23: 'position_mm' [x, y] is required for a punch");
  EXPECT_EQ(ObjectError("{\"shape\": \"cylinder\", \"radius_mm\": 1, \"length_mm\": -6, \"position_mm\": [0, 0]}"),
            ":1:74: 'length_mm' must be > 0 (got -6)");
  EXPECT_EQ(ObjectError("{\"shape\": \"sphere\", \"radius_mm\": 1, \"length_mm\": 6, \"position_mm\": [0, 0]}"),
            ":1:72: 'length_mm' is a cylinder's (a finite rod), not a sphere's");
  const std::string sphere = "{\"shape\": \"sphere\", \"radius_mm\": 3, \"position_mm\": [0, 0]}";
  EXPECT_EQ(ObjectError("{\"shape\": \"pair\", \"objects\": [" + sphere + ", " + sphere + "]}"),
            ":1:23: 'split' [s1, s2] (each object's share of force_N) is required for a pair");
  EXPECT_EQ(ObjectError("{\"shape\": \"pair\", \"split\": [0.5, 0.6], \"objects\": [" + sphere + ", " + sphere + "]}"),
            ":1:50: 'split' must give each of the pair's objects a share in [0, 1], the shares summing to 1");
  EXPECT_EQ(ObjectError("{\"shape\": \"pair\", \"split\": [1], \"objects\": [" + sphere + "]}"),
            ":1:66: a pair needs 'objects': two of them");
  EXPECT_EQ(ObjectError("{\"shape\": \"pair\", \"split\": [0.5, 0.5], \"position_mm\": [0, 0], \"objects\": [" + sphere +
                        ", " + sphere + "]}"),
            ":1:77: 'position_mm' is each of a pair's objects', not the pair's");
  // Inside a pair: its second object, a sphere without a radius, and a nested pair.
  EXPECT_EQ(ObjectError("{\"shape\": \"pair\", \"split\": [0.5, 0.5], \"objects\": [" + sphere +
                        ", {\"shape\": \"sphere\", \"position_mm\": [1, 1]}]}"),
            ":1:134: 'radius_mm' (> 0) is required for a sphere");
  EXPECT_EQ(ObjectError("{\"shape\": \"pair\", \"split\": [0.5, 0.5], \"objects\": [" + sphere +
                        ", {\"shape\": \"pair\", \"split\": [1], \"objects\": []}]}"),
            ":1:144: a pair's objects cannot be pairs");
  EXPECT_EQ(ObjectError("{\"shape\": \"pair\", \"split\": [0.5, 0.5], \"objects\": [" + sphere + ", " + sphere +
                        "], \"traction\": [0.1, 0]}"),
            "");
}

}  // namespace
}  // namespace sedbridge::sensors
