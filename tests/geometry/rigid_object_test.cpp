#include "common/geometry/rigid_object.h"

#include <gtest/gtest.h>

#include "common/config_error.h"
#include "common/yaml_reader.h"

namespace sedbridge::geometry {
namespace {

// `list_yaml` as the `objects:` list of a file ("objects:" is its line 1).
std::vector<RigidObject> ParseList(const std::string& list_yaml, const std::string& file) {
  const config::YamlDocument doc = config::LoadYamlString("objects:\n" + list_yaml, file);
  config::MapReader owner(doc.root, doc.file);
  return ParseRigidObjects(owner, "objects");
}

TEST(RigidObject, ParsesMovingSphere) {
  auto objs = ParseList(
      "- shape: sphere\n  radius_mm: 5\n  position_mm: [0, 0, 5]\n"
      "  motion:\n    keyframes: [{t_s: 0, offset_mm: [0,0,0]}, {t_s: 1, offset_mm: [0,0,-2]}]\n",
      "objs.yaml");
  ASSERT_EQ(objs.size(), 1u);
  EXPECT_EQ(objs[0].name, "sphere");
  EXPECT_NEAR(objs[0].Evaluate({0, 0, 0}, 0.0).distance_m, 0.0, 1e-12);
  EXPECT_NEAR(objs[0].Evaluate({0, 0, 0}, 1.0).distance_m, -0.002, 1e-12);
}

TEST(RigidObject, RotatedPlaneNormal) {
  auto objs = ParseList("- shape: plane\n  rpy_deg: [180, 0, 0]\n", "p.yaml");
  EXPECT_NEAR(objs[0].Evaluate({0, 0, 0.001}, 0).normal.z(), -1.0, 1e-12);
  EXPECT_NEAR(objs[0].Evaluate({0, 0, 0.001}, 0).distance_m, -0.001, 1e-12);
}

TEST(RigidObject, BadKeysAndValuesNameTheLine) {
  try {
    ParseList("- shape: sphere\n  radius_mm: -1\n", "bad.yaml");
    FAIL();
  } catch (const config::ConfigError& e) {
    EXPECT_EQ(e.where().line, 3);  // the radius line, below "objects:"
  }
  EXPECT_THROW(ParseList("- shape: sphere\n  radius_mm: 1\n  radus_mm: 2\n", "typo.yaml"), config::ConfigError);
  EXPECT_THROW(ParseList("- shape: cone\n", "cone.yaml"), config::ConfigError);
}

std::string ErrorOf(const std::string& list_yaml) {
  try {
    ParseList(list_yaml, "o.yaml");
  } catch (const config::ConfigError& e) {
    return e.what();
  }
  return "accepted";
}

TEST(RigidObject, ShapeKeysDefaultsAndChecks) {
  const auto edge = ParseList("- {shape: edge, length_mm: 10}\n", "e.yaml");
  EXPECT_NEAR(edge[0].Evaluate({0, 0, 0}, 0).distance_m, -0.25e-3, 1e-12);  // default radius 0.25 mm
  EXPECT_EQ(ErrorOf("- {shape: cylinder}\n"), "o.yaml:2:3: missing required key 'radius_mm'");
  EXPECT_EQ(ErrorOf("- {shape: sphere, radius_mm: 1, size_mm: [1, 1, 1]}\n"), "o.yaml:2:33: unknown key 'size_mm'");
  EXPECT_EQ(ErrorOf("- {shape: box, size_mm: [2, 2, 2], rounding_mm: 1.5}\n"),
            "o.yaml:2:49: 'rounding_mm' must be in [0, min(size)/2]");
  EXPECT_EQ(ErrorOf("- {shape: grating, period_mm: 1, ridge_width_mm: 1, depth_mm: 1}\n"),
            "o.yaml:2:50: 'ridge_width_mm' must be < 'period_mm'");
  EXPECT_EQ(ErrorOf("- {shape: plane, motion: {keyframes: [{t_s: 1}, {t_s: 1}]}}\n"),
            "o.yaml:2:49: keyframe times must increase");
  EXPECT_EQ(ErrorOf("- {shape: plane, motion: {vibration: {amplitude_mm: 1, frequency_Hz: 5, direction: [0, 0, 0]}}}\n"),
            "o.yaml:2:84: 'direction' must be non-zero");
  EXPECT_EQ(ErrorOf("{shape: plane}\n"), "o.yaml:2:1: expected a list of objects");
}

}  // namespace
}  // namespace sedbridge::geometry
