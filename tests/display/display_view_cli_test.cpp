// `sedbridge display-view` end to end: a recorded run (DisplaySession -> LCM log) shown as a
// terminal heatmap and rendered to PNG frames.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <algorithm>
#include <filesystem>
#include <regex>
#include <vector>
#include <string>
#include <unistd.h>

#include "lcm/display_command_message.h"
#include "lcm/display_session.h"
#include "lcm/lcm_log_writer.h"
#include "lcm/taxel_health_message.h"
#include "sedbridge/lcmt_bridge_status.hpp"
#include "tests/common/child_process.h"

namespace sedbridge::display {
using namespace sedbridge::lcm_io;  // LCM messages in and out
namespace {

namespace fs = std::filesystem;

using sedbridge::testing::RunShell;
using sedbridge::testing::ShellResult;

class DisplayViewCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("sedbridge_view_cli_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    log_ = (dir_ / "run.lcmlog").string();
    LcmSettings settings;
    settings.url = "memq://";
    settings.log_path = log_;
    DisplaySession session(LoadDisplayProfile("config/displays/pin_6x4.yaml"), settings);
    int64_t t = 1'000'000;
    for (int k = 0; k < 60; ++k, t += 10'000) {
      SedField f;
      f.utime = t;
      for (double x = -5; x <= 5; x += 0.5)
        for (double y = -6; y <= 8; y += 0.5) {
          f.x_mm.push_back(x);
          f.y_mm.push_back(y);
          f.z_mm.push_back(-1.5);
          f.sed_Pa.push_back(2500 * std::exp(-(x * x + (y - 1) * (y - 1)) / 6));
        }
      session.OnSedField(f, t);
    }
    session.Shutdown(t);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path dir_;
  std::string log_;
};

// --once on a log shows the frame with the largest command, not the final all-zero shutdown
// frame, says which frame it is, and draws the SED on one scale for the whole log.
TEST_F(DisplayViewCli, TerminalOnceShowsThePeakFrameAndSaysWhich) {
  const ShellResult r = RunShell(std::string(SEDBRIDGE_BINARY) + " display-view --log " + log_ +
                   " --once --no-color");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("pin_6x4"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("[SHUTDOWN]"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("the largest command in the log"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("peak 2.5e+03 Pa"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("colour scale 0..2.5e+03 Pa (fixed)"), std::string::npos) << r.output;
}

// Under the frame, the taxels the bridge masks and why, from its BRIDGE_STATUS in the log; a
// log without one (a display session alone) says nothing about taxels.
TEST_F(DisplayViewCli, SaysWhichTaxelsTheBridgeMasks) {
  const ShellResult plain = RunShell(std::string(SEDBRIDGE_BINARY) + " display-view --log " + log_ + " --once --no-color");
  ASSERT_EQ(plain.status, 0) << plain.output;
  EXPECT_EQ(plain.output.find("taxel health"), std::string::npos) << plain.output;
  const std::string log = (dir_ / "health.lcmlog").string();
  {
    LcmLogWriter w(log);
    for (int k = 0; k < 5; ++k) {
      lcmt_bridge_status s{};
      s.utime = 1'000'000 + k * 10'000;
      s.num_taxels = 16;
      s.taxel_health.assign(16, 0);
      if (k >= 2) s.taxel_health[5] = static_cast<int8_t>(TaxelHealthCode::kStuckHigh);
      w.Write("BRIDGE_STATUS", s);
      DisplayCommand c;
      c.utime = s.utime;
      c.sequence = k;
      c.value = {0.0, 0.0};
      w.Write("DISPLAY_COMMAND", ToLcm(c));
    }
  }
  const ShellResult r = RunShell(std::string(SEDBRIDGE_BINARY) + " display-view --log " + log + " --speed 0 --no-color");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("taxel health: all 16 ok"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("taxel health: 1 of 16 masked (5 stuck)"), std::string::npos) << r.output;
}

TEST_F(DisplayViewCli, MidRunFrameShowsAStrongerCentre) {
  const ShellResult r = RunShell(std::string(SEDBRIDGE_BINARY) + " display-view --log " + log_ +
                           " --speed 0 --fps 1000 --no-color");
  ASSERT_EQ(r.status, 0) << r.output;
  // Frame of command 30 (0.3 s into a steady press): read the 6x4 pin heights back.
  const auto at = r.output.find("seq 30 ");
  ASSERT_NE(at, std::string::npos) << r.output;
  const auto begin = r.output.find("tip ^", at), end = r.output.find("x ->", at);
  ASSERT_LT(begin, end);
  const std::string block = r.output.substr(begin, end - begin);
  std::vector<double> v;
  const std::regex cell(R"(\[.\s*([0-9.]+)\s*\])");
  for (auto it = std::sregex_iterator(block.begin(), block.end(), cell); it != std::sregex_iterator(); ++it)
    v.push_back(std::stod((*it)[1]));
  ASSERT_EQ(v.size(), 24u) << block;
  // Row-major from the tip, 4 columns; the bump is centred at y = 1 mm (rows 2 and 3).
  EXPECT_GT(v[2 * 4 + 1], v[0]);   // inner pin > tip corner
  EXPECT_GT(v[2 * 4 + 1], 0.5);    // a clear stimulus (mm)
  EXPECT_LE(*std::max_element(v.begin(), v.end()), 1.5);  // the profile's hard max
}

TEST_F(DisplayViewCli, BadArgumentsAreUsageErrors) {
  EXPECT_EQ(RunShell(std::string(SEDBRIDGE_BINARY) + " display-view --png-dir x").status, 2);
  EXPECT_EQ(RunShell(std::string(SEDBRIDGE_BINARY) + " display-view --bogus").status, 2);
  EXPECT_EQ(RunShell(std::string(SEDBRIDGE_BINARY) + " display-view --log /nonexistent.lcmlog").status, 1);
}

TEST_F(DisplayViewCli, WritesPngFrames) {
  if (RunShell("/usr/bin/python3 -c 'import matplotlib'").status != 0)
    GTEST_SKIP() << "/usr/bin/python3 has no matplotlib (Debian: python3-matplotlib)";
  const fs::path frames = dir_ / "frames";
  const ShellResult r = RunShell(std::string(SEDBRIDGE_BINARY) + " display-view --log " + log_ +
                   " --fps 4 --png-dir " + frames.string());
  ASSERT_EQ(r.status, 0) << r.output;
  int pngs = 0;
  for (const auto& e : fs::directory_iterator(frames))
    if (e.path().extension() == ".png" && fs::file_size(e.path()) > 1000) ++pngs;
  EXPECT_GE(pngs, 3);  // 0.6 s at 4 fps + the last command
  EXPECT_TRUE(fs::exists(frames / "frames.jsonl"));
}

TEST_F(DisplayViewCli, WritesAGifToAPathWithQuotesAndSpaces) {
  if (RunShell("/usr/bin/python3 -c 'import matplotlib, PIL'").status != 0)
    GTEST_SKIP() << "/usr/bin/python3 lacks matplotlib or Pillow (python3-matplotlib, python3-pil)";
  const fs::path gif = dir_ / "it's a run.gif";
  const ShellResult r = RunShell(std::string(SEDBRIDGE_BINARY) + " display-view --log " + log_ +
                           " --fps 4 --animation \"" + gif.string() + "\"");
  ASSERT_EQ(r.status, 0) << r.output;
  ASSERT_TRUE(fs::exists(gif)) << r.output;
  EXPECT_GT(fs::file_size(gif), 1000u);
}

}  // namespace
}  // namespace sedbridge::display
