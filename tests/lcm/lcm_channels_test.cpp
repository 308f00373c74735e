#include "lcm/lcm_channels.h"

#include <gtest/gtest.h>

#include <stdexcept>

#include "common/config_error.h"
#include "common/yaml_reader.h"

namespace sedbridge::lcm_io {
namespace {

TEST(LcmChannels, UpperSnake) {
  for (const char* ok : {"DISPLAY_COMMAND", "TACTILE_SCAN", "SED2", "A"}) EXPECT_TRUE(IsUpperSnake(ok)) << ok;
  for (const char* bad : {"", "display_command", "Display", "_X", "X_", "A__B", "2SED", "A-B", "A B"})
    EXPECT_FALSE(IsUpperSnake(bad)) << bad;
}

TEST(LcmChannels, DefaultsAreTheDocumentedNames) {
  const LcmChannels ch;
  EXPECT_EQ(ch.tactile_scan, "TACTILE_SCAN");
  EXPECT_EQ(ch.sed, "FINGERTIP_SED");
  EXPECT_EQ(ch.command, "DISPLAY_COMMAND");
  EXPECT_EQ(ch.status, "BRIDGE_STATUS");
  EXPECT_NO_THROW(ch.Validate());
  EXPECT_EQ(std::string(kDefaultLcmUrl), "udpm://239.255.76.67:7667?ttl=0");
  LcmChannels bad;
  bad.sed = "fingertip-sed";
  EXPECT_THROW(bad.Validate(), std::invalid_argument);
}

TEST(LcmChannels, ParsesTheLcmSection) {
  auto doc = config::LoadYamlString(
      "url: memq://\nlog: out/x.lcmlog\nchannels:\n  command: LEFT_DISPLAY\n", "b.yaml");
  config::MapReader r(doc.root, doc.file);
  const LcmSettings s = ParseLcmSettings(r);
  EXPECT_EQ(s.url, "memq://");
  EXPECT_EQ(s.log_path, "out/x.lcmlog");
  EXPECT_EQ(s.channels.command, "LEFT_DISPLAY");
  EXPECT_EQ(s.channels.sed, "FINGERTIP_SED");
}

TEST(LcmChannels, BadChannelOrUnknownKeyNamesTheLocation) {
  auto doc = config::LoadYamlString("channels:\n  status: bridge_status\n", "b.yaml");
  config::MapReader r(doc.root, doc.file);
  try {
    ParseLcmSettings(r);
    FAIL();
  } catch (const config::ConfigError& e) {
    EXPECT_EQ(e.where().line, 2);
    EXPECT_NE(std::string(e.what()).find("UPPER_SNAKE"), std::string::npos);
  }
  auto doc2 = config::LoadYamlString("channels:\n  comand: X\n", "b.yaml");
  config::MapReader r2(doc2.root, doc2.file);
  try {
    ParseLcmSettings(r2);
    FAIL();
  } catch (const config::ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), "b.yaml:2:3: unknown key 'comand'");
  }
}

}  // namespace
}  // namespace sedbridge::lcm_io
