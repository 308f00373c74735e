#include "config/yaml_reader.h"

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

}  // namespace
}  // namespace sedbridge::config
