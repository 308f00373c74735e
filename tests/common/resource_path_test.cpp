#include "common/resource_path.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

namespace sedbridge::config {
namespace {

namespace fs = std::filesystem;

// Runs the test body in a fresh empty working directory and goes back afterwards.
class InTempDir : public ::testing::Test {
 protected:
  void SetUp() override {
    old_ = fs::current_path();
    dir_ = fs::temp_directory_path() / ("sedbridge_resource_path_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    fs::current_path(dir_);
  }
  void TearDown() override {
    fs::current_path(old_);
    fs::remove_all(dir_);
  }
  fs::path old_, dir_;
};

TEST_F(InTempDir, BareNameIsTheShippedYamlInItsFolder) {
  const std::string path = ResolveNameOrPath("suction_4x4", "config/displays");
  EXPECT_EQ(fs::path(path), fs::path(SourceRoot()) / "config/displays/suction_4x4.yaml");
  EXPECT_TRUE(fs::exists(path));
  EXPECT_TRUE(fs::exists(ResolveNameOrPath("B", "config/models")));
  EXPECT_TRUE(fs::exists(ResolveNameOrPath("uskin_4x4", "config/sensors")));
}

TEST_F(InTempDir, AFileThatExistsAsGivenWins) {
  std::ofstream("suction_4x4") << "local\n";
  EXPECT_EQ(ResolveNameOrPath("suction_4x4", "config/displays"), "suction_4x4");
  fs::create_directories("config/displays");
  std::ofstream("config/displays/suction_4x4.yaml") << "local\n";
  EXPECT_EQ(ResolveNameOrPath("config/displays/suction_4x4.yaml", "config/displays"),
            "config/displays/suction_4x4.yaml");
}

TEST_F(InTempDir, PathsResolveUnderTheSourceRootOrComeBackUnchanged) {
  EXPECT_EQ(fs::path(ResolveNameOrPath("config/models/B.msh", "config/models")),
            fs::path(SourceRoot()) / "config/models/B.msh");
  // A name with an extension is a path, not a shipped name.
  EXPECT_EQ(ResolveNameOrPath("B.msh", "config/models"), "B.msh");
  EXPECT_EQ(ResolveNameOrPath("no/such/profile.yaml", "config/displays"), "no/such/profile.yaml");
  // A bare name nothing ships: the shipped spelling, so the error names where it looked.
  EXPECT_EQ(fs::path(ResolveNameOrPath("no_such_display", "config/displays")).filename(), "no_such_display.yaml");
}

}  // namespace
}  // namespace sedbridge::config
