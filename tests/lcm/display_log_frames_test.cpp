#include "lcm/display_log_frames.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

#include "lcm/display_command_message.h"
#include "lcm/lcm_log_writer.h"
#include "lcm/merkel_sed_message.h"
#include "lcm/taxel_health_message.h"
#include "sedbridge/lcmt_bridge_status.hpp"

namespace sedbridge::lcm_io {
using namespace sedbridge::display;  // the structs the messages carry
namespace {

std::string Temp(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          ("sedbridge_frames_" + std::to_string(::getpid()) + "_" + name))
      .string();
}

// 1 s of commands at 100 Hz, a SED field every 20 ms, ending with a shutdown command.
std::string WriteRun() {
  const std::string path = Temp("run.lcmlog");
  LcmLogWriter log(path);
  for (int k = 0; k <= 100; ++k) {
    const int64_t t = 1'000'000 + k * 10'000;
    if (k % 2 == 0) {
      SedField f;
      f.utime = t;
      f.x_mm = {0.0};
      f.y_mm = {0.0};
      f.sed_Pa = {100.0 * k};
      log.Write("FINGERTIP_SED", ToLcm(f));
    }
    DisplayCommand c;
    c.utime = t;
    c.sequence = k;
    c.display_id = "x";
    c.value = {0.01 * k, std::nan("")};
    c.shutdown = k == 100;
    log.Write("DISPLAY_COMMAND", ToLcm(c));
  }
  return path;
}

TEST(DisplayLogFrames, SamplesAtTheFrameRateAndKeepsTheLastCommand) {
  const std::string path = WriteRun();
  std::size_t bad = 99;
  const auto frames = ReadDisplayFrames(path, LcmChannels{}, 10.0, 1000, &bad);
  EXPECT_EQ(bad, 0u);
  ASSERT_EQ(frames.size(), 11u);  // t = 0, 0.1, ..., 1.0 s
  EXPECT_EQ(frames[1].command.sequence, 10);
  EXPECT_TRUE(frames.back().command.shutdown);
  EXPECT_TRUE(frames[1].has_sed);
  EXPECT_DOUBLE_EQ(frames[1].sed.sed_Pa[0], 1000.0);  // latest field at or before seq 10
  const auto all = ReadDisplayFrames(path, LcmChannels{}, 0, 1000);
  EXPECT_EQ(all.size(), 101u);
  const auto capped = ReadDisplayFrames(path, LcmChannels{}, 0, 5);
  ASSERT_EQ(capped.size(), 5u);
  EXPECT_TRUE(capped.back().command.shutdown);
  std::filesystem::remove(path);
}

// display-view's line under each frame: the latest BRIDGE_STATUS's taxel health at or before
// the command, said in words (which taxels are masked, and why).
TEST(DisplayLogFrames, FramesCarryTheLatestTaxelHealthSaidInWords) {
  const std::string path = Temp("health.lcmlog");
  {
    LcmLogWriter log(path);
    for (int k = 0; k < 10; ++k) {
      const int64_t t = 1'000'000 + k * 10'000;
      if (k == 5) {
        lcmt_bridge_status s{};
        s.utime = t;
        s.num_taxels = 16;
        s.taxel_health.assign(16, 0);
        s.taxel_health[5] = static_cast<int8_t>(TaxelHealthCode::kStuckHigh);
        s.taxel_health[9] = static_cast<int8_t>(TaxelHealthCode::kDead);
        s.taxel_health[2] = static_cast<int8_t>(TaxelHealthCode::kDrifting);
        log.Write("BRIDGE_STATUS", s);
      }
      DisplayCommand c;
      c.utime = t;
      c.sequence = k;
      c.value = {0.1 * k};
      log.Write("DISPLAY_COMMAND", ToLcm(c));
    }
  }
  std::size_t bad = 99;
  const auto frames = ReadDisplayFrames(path, LcmChannels{}, 0, 1000, &bad);
  EXPECT_EQ(bad, 0u);
  ASSERT_EQ(frames.size(), 10u);
  EXPECT_TRUE(frames[4].taxel_health.empty());  // no status yet
  ASSERT_EQ(frames[5].taxel_health.size(), 16u);
  EXPECT_EQ(frames[9].taxel_health, frames[5].taxel_health);
  EXPECT_EQ(DescribeTaxelHealth(frames[5].taxel_health),
            "taxel health: 2 of 16 masked (5 stuck, 9 dead); drifting (re-tared): 2");
  EXPECT_EQ(DescribeTaxelHealth(std::vector<int8_t>(16, 0)), "taxel health: all 16 ok");
  EXPECT_EQ(DescribeTaxelHealth({0, 4}), "taxel health: none of 2 masked; drifting (re-tared): 1");
  EXPECT_EQ(DescribeTaxelHealth({0, 3, 0, 42}), "taxel health: 2 of 4 masked (1 frozen, 3 ?)");
  EXPECT_EQ(DescribeTaxelHealth({}), "taxel health: not reported");
  std::filesystem::remove(path);
}

TEST(DisplayLogFrames, JsonLinesHaveHeaderFramesAndNullForNaN) {
  const std::string path = WriteRun();
  const auto frames = ReadDisplayFrames(path, LcmChannels{}, 5.0, 1000);
  const std::string out = Temp("frames.jsonl");
  WriteFramesJsonl(out, {{0, 1}, {0, 0}, 2.0, "kPa"}, "x", frames);
  std::ifstream in(out);
  std::string line;
  int lines = 0;
  std::string header, first;
  while (std::getline(in, line)) {
    if (lines == 0) header = line;
    if (lines == 1) first = line;
    ++lines;
  }
  EXPECT_EQ(lines, 1 + static_cast<int>(frames.size()));
  EXPECT_EQ(header.rfind("{\"display_id\":\"x\",\"unit\":\"kPa\",\"max\":2,", 0), 0u) << header;
  EXPECT_NE(first.find("\"value\":[0,null]"), std::string::npos) << first;
  EXPECT_NE(first.find("\"sed\":{\"x_mm\":[0]"), std::string::npos) << first;
  std::filesystem::remove(path);
  std::filesystem::remove(out);
}

}  // namespace
}  // namespace sedbridge::lcm_io
