#include "common/yaml_read_archive.h"
#include "common/schema_keys.h"

#include <gtest/gtest.h>

#include <optional>
#include <string>
#include <vector>

namespace sedbridge::config {
namespace {

enum class Shape { kSphere, kCylinder };
const EnumNames<Shape>& NamesOf(Shape) {
  static const EnumNames<Shape> names{{Shape::kSphere, "sphere"}, {Shape::kCylinder, "cylinder"}};
  return names;
}

struct Spring {
  double stiffness_N_m = 200;
  double damping_N_s_m = 0.1;
  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(Field("stiffness_N_m", &stiffness_N_m).Positive());
    a->Visit(Field("damping_N_s_m", &damping_N_s_m).NonNegative());
  }
};

struct Example {
  std::string name;
  double rate_Hz = 10;
  int steps = 50;
  double tolerance_m = 1e-6;
  Shape shape = Shape::kSphere;
  std::string preset = "fast";
  bool verbose = false;
  Spring spring;
  std::optional<Spring> extra;
  std::optional<double> limit;
  std::vector<double> gains;
  std::array<double, 2> offset_mm{0, 0};
  int flat_in_section = 0;

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(Field("name", &name).Required());
    a->Visit(Field("rate_Hz", &rate_Hz).Unit("Hz").InRange(0.1, 100));
    a->Visit(Field("steps", &steps).InRange(1, 1000));
    a->Visit(Field("tolerance_mm", &tolerance_m).Positive().Scale(1e-3));
    a->Visit(Field("shape", &shape));
    a->Visit(Field("preset", &preset).OneOf({"fast", "balanced", "accurate"}));
    a->Visit(Field("verbose", &verbose));
    a->Visit(Field("spring", &spring));
    a->Visit(Field("extra", &extra));
    a->Visit(Field("limit", &limit).Positive());
    a->Visit(Field("gains", &gains).Within({0, 5, true, false}));
    a->Visit(Field("offset_mm", &offset_mm));
    a->Section("group", [&](auto* g) { g->Visit(Field("flat", &flat_in_section).NonNegative()); });
  }
};

Example Read(const std::string& text) {
  auto doc = LoadYamlString(text, "e.yaml");
  MapReader r(doc.root, doc.file);
  Example e;
  ReadYaml(r, &e);
  return e;
}

// The error text of reading `text`, "" when it reads.
std::string ErrorOf(const std::string& text) {
  try {
    Read(text);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(YamlArchive, AbsentKeysKeepTheMemberDefaults) {
  const Example e = Read("name: x\n");
  EXPECT_EQ(e.name, "x");
  EXPECT_DOUBLE_EQ(e.rate_Hz, 10);
  EXPECT_EQ(e.steps, 50);
  EXPECT_EQ(e.shape, Shape::kSphere);
  EXPECT_DOUBLE_EQ(e.spring.stiffness_N_m, 200);
  EXPECT_FALSE(e.extra.has_value());
  EXPECT_FALSE(e.limit.has_value());
  EXPECT_TRUE(e.gains.empty());
  EXPECT_EQ(e.flat_in_section, 0);
}

TEST(YamlArchive, ReadsEveryKindOfField) {
  const Example e = Read(
      "name: x\nrate_Hz: 50\nsteps: 3\ntolerance_mm: 0.5\nshape: cylinder\npreset: accurate\n"
      "verbose: true\nspring: {stiffness_N_m: 5}\nextra: {damping_N_s_m: 2}\nlimit: 7\n"
      "gains: [1, 2.5]\noffset_mm: [1, -2]\ngroup: {flat: 4}\n");
  EXPECT_DOUBLE_EQ(e.rate_Hz, 50);
  EXPECT_EQ(e.steps, 3);
  EXPECT_DOUBLE_EQ(e.tolerance_m, 0.5e-3);  // the key is in mm, the member in m
  EXPECT_EQ(e.shape, Shape::kCylinder);
  EXPECT_EQ(e.preset, "accurate");
  EXPECT_TRUE(e.verbose);
  EXPECT_DOUBLE_EQ(e.spring.stiffness_N_m, 5);
  EXPECT_DOUBLE_EQ(e.spring.damping_N_s_m, 0.1);  // nested default kept
  ASSERT_TRUE(e.extra.has_value());
  EXPECT_DOUBLE_EQ(e.extra->damping_N_s_m, 2);
  EXPECT_DOUBLE_EQ(e.extra->stiffness_N_m, 200);
  ASSERT_TRUE(e.limit.has_value());
  EXPECT_DOUBLE_EQ(*e.limit, 7);
  EXPECT_EQ(e.gains, (std::vector<double>{1, 2.5}));
  EXPECT_DOUBLE_EQ(e.offset_mm[1], -2);
  EXPECT_EQ(e.flat_in_section, 4);
}

TEST(YamlArchive, DuplicateKeyIsAnErrorAtTheSecondOne) {
  EXPECT_EQ(ErrorOf("name: x\nsteps: 3\nsteps: 4\n"),
            "e.yaml:3:1: duplicate key 'steps' (given earlier in the same mapping)");
  EXPECT_EQ(ErrorOf("name: x\nspring:\n  stiffness_N_m: 1\n  stiffness_N_m: 2\n"),
            "e.yaml:4:3: duplicate key 'stiffness_N_m' (given earlier in the same mapping)");
}

TEST(YamlArchive, UnknownKeyNamesItsLocation) {
  EXPECT_EQ(ErrorOf("name: x\nstep: 3\n"), "e.yaml:2:1: unknown key 'step'");
  EXPECT_EQ(ErrorOf("name: x\nspring:\n  stifness_N_m: 1\n"), "e.yaml:3:3: unknown key 'stifness_N_m'");
  EXPECT_EQ(ErrorOf("name: x\ngroup:\n  flat: 1\n  round: 2\n"), "e.yaml:4:3: unknown key 'round'");
}

TEST(YamlArchive, MissingRequiredKeyNamesTheMapping) {
  EXPECT_EQ(ErrorOf("steps: 3\n"), "e.yaml:1:1: missing required key 'name'");
}

TEST(YamlArchive, RangeViolationsNameTheValueTheRuleAndTheValue) {
  EXPECT_EQ(ErrorOf("name: x\nrate_Hz: 0.01\n"), "e.yaml:2:10: 'rate_Hz' must be in [0.1, 100] Hz (got 0.01)");
  EXPECT_EQ(ErrorOf("name: x\nsteps: 0\n"), "e.yaml:2:8: 'steps' must be in [1, 1000] (got 0)");
  EXPECT_EQ(ErrorOf("name: x\ntolerance_mm: 0\n"), "e.yaml:2:15: 'tolerance_mm' must be > 0 (got 0)");
  EXPECT_EQ(ErrorOf("name: x\nspring:\n  damping_N_s_m: -1\n"),
            "e.yaml:3:18: 'damping_N_s_m' must be >= 0 (got -1)");
  EXPECT_EQ(ErrorOf("name: x\nlimit: -3\n"), "e.yaml:2:8: 'limit' must be > 0 (got -3)");
  // Each entry of a sequence is checked, and the error is at the entry.
  EXPECT_EQ(ErrorOf("name: x\ngains: [1, 0]\n"), "e.yaml:2:12: 'gains' must be in (0, 5] (got 0)");
  EXPECT_EQ(ErrorOf("name: x\ngroup: {flat: -1}\n"), "e.yaml:2:15: 'flat' must be >= 0 (got -1)");
}

TEST(YamlArchive, NonFiniteAndWrongTypesAreErrors) {
  EXPECT_NE(ErrorOf("name: x\nrate_Hz: .nan\n").find("e.yaml:2:10: 'rate_Hz' must be a finite number"),
            std::string::npos);
  EXPECT_NE(ErrorOf("name: x\nsteps: many\n").find("e.yaml:2:8: 'steps' has the wrong type"), std::string::npos);
  EXPECT_EQ(ErrorOf("name: x\nspring: 3\n"), "e.yaml:2:9: expected a mapping (key: value pairs)");
  EXPECT_EQ(ErrorOf("name: x\ngains: 3\n"), "e.yaml:2:8: 'gains' must be a list");
  EXPECT_EQ(ErrorOf("name: x\noffset_mm: [1, 2, 3]\n"), "e.yaml:2:12: 'offset_mm' must be a list of 2 numbers");
}

TEST(YamlArchive, EnumAndChoiceErrorsListTheAllowedNames) {
  EXPECT_EQ(ErrorOf("name: x\nshape: cube\n"), "e.yaml:2:8: 'shape' must be one of: sphere, cylinder (got 'cube')");
  EXPECT_EQ(ErrorOf("name: x\npreset: quick\n"),
            "e.yaml:2:9: 'preset' must be one of: fast, balanced, accurate (got 'quick')");
}

TEST(EnumNames, OneTableGivesBothDirections) {
  EXPECT_EQ(NameOf(Shape::kCylinder), "cylinder");
  EXPECT_EQ(EnumFromName<Shape>("sphere"), Shape::kSphere);
  EXPECT_FALSE(EnumFromName<Shape>("cube").has_value());
  EXPECT_EQ(AllNames<Shape>(), (std::vector<std::string>{"sphere", "cylinder"}));
  try {
    ParseEnum<Shape>("cube", "shape");
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "unknown shape 'cube' (sphere, cylinder)");
  }
}

}  // namespace
}  // namespace sedbridge::config

// ---- common/schema_keys.h: the same Serialize, listed ----

namespace sedbridge::config {
namespace {

TEST(SchemaKeys, ListsEveryKeyDottedWithNestedStructsAndSections) {
  const std::vector<std::string> keys = SchemaKeys<Example>();
  const std::vector<std::string> expected = {
      "name", "rate_Hz", "steps", "tolerance_mm", "shape", "preset", "verbose",
      "spring.stiffness_N_m", "spring.damping_N_s_m", "extra.stiffness_N_m", "extra.damping_N_s_m",
      "limit", "gains", "offset_mm", "group.flat"};
  EXPECT_EQ(keys, expected);
}

}  // namespace
}  // namespace sedbridge::config
