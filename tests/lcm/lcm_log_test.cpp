#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

#include "lcm/display_command_message.h"
#include "lcm/lcm_log_reader.h"
#include "lcm/lcm_log_writer.h"
#include "lcm/lcm_publisher.h"
#include "lcm/merkel_sed_message.h"

namespace sedbridge::lcm_io {
using namespace sedbridge::display;  // the structs the messages carry
namespace {

std::string TempPath(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          ("sedbridge_" + name + "_" + std::to_string(::getpid()) + ".lcmlog"))
      .string();
}

TEST(LcmLog, WriteReadRoundTrip) {
  const std::string path = TempPath("roundtrip");
  {
    LcmLogWriter log(path);
    for (int k = 0; k < 5; ++k) {
      DisplayCommand c;
      c.utime = 1'000'000 + k * 10'000;
      c.sequence = k;
      c.display_id = "pin_6x4";
      c.unit = "mm";
      c.value = {0.1 * k, 0.2};
      log.Write("DISPLAY_COMMAND", ToLcm(c));
    }
    log.WriteRaw("OTHER_CHANNEL", 2'000'000, "abc", 3);
    EXPECT_EQ(log.events_written(), 6);
  }
  LcmLogReader reader(path);
  int commands = 0;
  int64_t last_timestamp = 0;
  while (const lcm::LogEvent* e = reader.Next()) {
    if (e->channel == "DISPLAY_COMMAND") {
      lcmt_display_command m;
      ASSERT_TRUE(LcmLogReader::Decode(*e, &m));
      EXPECT_EQ(m.sequence, commands);
      EXPECT_EQ(e->timestamp, m.utime);  // logplayer paces by the message time
      EXPECT_EQ(m.unit, "mm");
      ++commands;
    } else {
      EXPECT_EQ(e->channel, "OTHER_CHANNEL");
      lcmt_display_command m;
      EXPECT_FALSE(LcmLogReader::Decode(*e, &m));
    }
    last_timestamp = e->timestamp;
  }
  EXPECT_EQ(commands, 5);
  EXPECT_EQ(last_timestamp, 2'000'000);
  std::filesystem::remove(path);
}

TEST(LcmLog, PublisherLeavesALogOfEverythingItSent) {
  const std::string path = TempPath("publisher");
  {
    LcmPublisher out("memq://");
    out.OpenLog(path);
    DisplayCommand c;
    c.utime = 5;
    c.value = {1.0};
    out.Publish(out.channels().command, ToLcm(c));
    SedField f;
    f.utime = 4;
    f.x_mm = {0};
    f.y_mm = {0};
    f.sed_Pa = {10};
    out.Publish(out.channels().sed, ToLcm(f));
    EXPECT_EQ(out.log()->events_written(), 2);
  }
  LcmLogReader reader(path);
  const lcm::LogEvent* e1 = reader.Next();
  ASSERT_NE(e1, nullptr);
  EXPECT_EQ(e1->channel, "DISPLAY_COMMAND");
  const lcm::LogEvent* e2 = reader.Next();
  ASSERT_NE(e2, nullptr);
  EXPECT_EQ(e2->channel, "FINGERTIP_SED");
  lcmt_merkel_sed m;
  EXPECT_TRUE(LcmLogReader::Decode(*e2, &m));
  EXPECT_EQ(reader.Next(), nullptr);
  std::filesystem::remove(path);
}

TEST(LcmLog, MissingOrGarbageFileIsAnError) {
  EXPECT_THROW(LcmLogReader("/nonexistent/dir/x.lcmlog"), std::runtime_error);
  EXPECT_THROW(LcmLogWriter("/nonexistent/dir/x.lcmlog"), std::runtime_error);
  const std::string path = TempPath("garbage");
  std::ofstream(path) << "this is not an LCM log\n";
  LcmLogReader reader(path);
  EXPECT_EQ(reader.Next(), nullptr);  // no valid event; no crash
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace sedbridge::lcm_io
