#include "common/geometry/rigid_object.h"

#include <gtest/gtest.h>

namespace sedbridge::geometry {
namespace {

TEST(RigidObject, ParsesMovingSphere) {
  auto doc = config::LoadYamlString(
      "- shape: sphere\n  radius_mm: 5\n  position_mm: [0, 0, 5]\n"
      "  motion:\n    keyframes: [{t_s: 0, offset_mm: [0,0,0]}, {t_s: 1, offset_mm: [0,0,-2]}]\n",
      "objs.yaml");
  auto objs = ParseRigidObjects(doc.root, doc.file);
  ASSERT_EQ(objs.size(), 1u);
  EXPECT_EQ(objs[0].name, "sphere");
  EXPECT_NEAR(objs[0].Evaluate({0, 0, 0}, 0.0).distance_m, 0.0, 1e-12);
  EXPECT_NEAR(objs[0].Evaluate({0, 0, 0}, 1.0).distance_m, -0.002, 1e-12);
}

TEST(RigidObject, RotatedPlaneNormal) {
  auto doc = config::LoadYamlString("- shape: plane\n  rpy_deg: [180, 0, 0]\n", "p.yaml");
  auto objs = ParseRigidObjects(doc.root, doc.file);
  EXPECT_NEAR(objs[0].Evaluate({0, 0, 0.001}, 0).normal.z(), -1.0, 1e-12);
  EXPECT_NEAR(objs[0].Evaluate({0, 0, 0.001}, 0).distance_m, -0.001, 1e-12);
}

TEST(RigidObject, BadKeysAndValuesNameTheLine) {
  auto doc = config::LoadYamlString("- shape: sphere\n  radius_mm: -1\n", "bad.yaml");
  try {
    ParseRigidObjects(doc.root, doc.file);
    FAIL();
  } catch (const config::ConfigError& e) {
    EXPECT_EQ(e.where().line, 2);
  }
  auto doc2 = config::LoadYamlString("- shape: sphere\n  radius_mm: 1\n  radus_mm: 2\n", "typo.yaml");
  EXPECT_THROW(ParseRigidObjects(doc2.root, doc2.file), config::ConfigError);
  auto doc3 = config::LoadYamlString("- shape: cone\n", "cone.yaml");
  EXPECT_THROW(ParseRigidObjects(doc3.root, doc3.file), config::ConfigError);
}

}  // namespace
}  // namespace sedbridge::geometry
