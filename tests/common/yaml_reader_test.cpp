#include "common/yaml_reader.h"

#include <gtest/gtest.h>

namespace sedbridge::config {
namespace {

TEST(YamlReader, ReadsTypedValuesAndDefaults) {
  auto doc = LoadYamlString("a: 1.5\nb: [1, 2]\nname: x\n", "t.yaml");
  MapReader r(doc.root, doc.file);
  EXPECT_DOUBLE_EQ(r.Required<double>("a"), 1.5);
  EXPECT_EQ(r.Required<std::vector<int>>("b").size(), 2u);
  EXPECT_EQ(r.Optional<std::string>("name", "y"), "x");
  EXPECT_EQ(r.Optional<int>("missing", 7), 7);
  EXPECT_NO_THROW(r.Finish());
}

TEST(YamlReader, UnknownKeyNamesFileLineColumn) {
  auto doc = LoadYamlString("a: 1\n  \nbogus_key: 2\n", "scene.yaml");
  MapReader r(doc.root, doc.file);
  r.Required<int>("a");
  try {
    r.Finish();
    FAIL() << "unknown key accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), "scene.yaml:3:1: unknown key 'bogus_key'");
  }
}

TEST(YamlReader, WrongTypeNamesTheValue) {
  auto doc = LoadYamlString("sub:\n  dt_s: fast\n", "s.yaml");
  MapReader r(doc.root, doc.file);
  MapReader sub = r.Child("sub");
  try {
    sub.Required<double>("dt_s");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.where().line, 2);
    EXPECT_EQ(e.where().column, 9);
    EXPECT_NE(std::string(e.what()).find("fast"), std::string::npos);
  }
}

TEST(YamlReader, ParseErrorHasLocation) {
  try {
    LoadYamlString("a: [1, 2\nb: 3\n", "broken.yaml");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.where().file, "broken.yaml");
    EXPECT_GT(e.where().line, 0);
  }
}

TEST(YamlReader, ChoiceRejectsOthers) {
  auto doc = LoadYamlString("mode: warp\n", "c.yaml");
  MapReader r(doc.root, doc.file);
  EXPECT_THROW(r.RequiredChoice("mode", {"cg", "ldlt"}), ConfigError);
}

TEST(YamlReader, MissingRequiredKeyIsAnError) {
  auto doc = LoadYamlString("a: 1\n", "m.yaml");
  MapReader r(doc.root, doc.file);
  EXPECT_THROW(r.Required<double>("b"), ConfigError);
}


TEST(YamlReader, DuplicateKeyIsAnErrorAtTheSecondOccurrence) {
  // yaml-cpp keeps the first: `max: 20` then `max: 5` would silently mean 20.
  try {
    LoadYamlString("safety:\n  max: 20\n  max: 5\n", "d.yaml");
    FAIL() << "duplicate key accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), "d.yaml:3:3: duplicate key 'max' (given earlier in the same mapping)");
  }
  // Inside a sequence of mappings too; the same key in two different mappings is fine.
  EXPECT_THROW(LoadYamlString("k:\n  - {a: 1, a: 2}\n", "s.yaml"), ConfigError);
  EXPECT_NO_THROW(LoadYamlString("x: {a: 1}\ny: {a: 2}\n", "ok.yaml"));
}

TEST(YamlReader, NonFiniteNumbersAreErrors) {
  for (const char* text : {"v: .nan\n", "v: .inf\n", "v: -.inf\n", "v: .NaN\n"}) {
    auto doc = LoadYamlString(text, "n.yaml");
    MapReader r(doc.root, doc.file);
    try {
      r.Required<double>("v");
      FAIL() << text;
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find("n.yaml:1:4: 'v' must be a finite number"), std::string::npos) << e.what();
    }
  }
  auto doc = LoadYamlString("v: [1, 2, .nan]\nf: .inf\n", "n.yaml");
  MapReader r(doc.root, doc.file);
  EXPECT_THROW(r.Required<std::vector<double>>("v"), ConfigError);
  EXPECT_THROW(r.Optional<float>("f", 1.0f), ConfigError);
  // A value too large for a double is not silently infinite either.
  auto big = LoadYamlString("v: 1e400\n", "b.yaml");
  MapReader rb(big.root, big.file);
  EXPECT_THROW(rb.Required<double>("v"), ConfigError);
}

TEST(YamlReader, AliasBombIsRejected) {
  std::string text = "a0: &a0 [x, x, x, x, x, x, x, x, x, x]\n";
  for (int i = 1; i < 9; ++i)
    text += "a" + std::to_string(i) + ": &a" + std::to_string(i) + " [" + std::string("*a") + std::to_string(i - 1) +
            ", *a" + std::to_string(i - 1) + ", *a" + std::to_string(i - 1) + ", *a" + std::to_string(i - 1) +
            ", *a" + std::to_string(i - 1) + ", *a" + std::to_string(i - 1) + ", *a" + std::to_string(i - 1) +
            ", *a" + std::to_string(i - 1) + ", *a" + std::to_string(i - 1) + ", *a" + std::to_string(i - 1) + "]\n";
  EXPECT_THROW(LoadYamlString(text, "bomb.yaml"), ConfigError);
}

}  // namespace
}  // namespace sedbridge::config
