// Every way `run`, `replay` and `simulate` can be asked to stop leaves the display at zero and
// the LCM log whole: SIGINT, SIGTERM, SIGHUP and SIGQUIT, each on each command, and
// a live replay paused in the middle of a press ramps to zero on its own watchdog ticks.
// Bounds are event counts and generous time limits, never measured durations.

#include <gtest/gtest.h>

#include <signal.h>
#include <unistd.h>

#include <cctype>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <ostream>
#include <string>
#include <vector>

#include "tests/common/child_process.h"
#include "tests/common/lcm_log_check.h"

namespace {

namespace fs = std::filesystem;
using sedbridge::testing::AllZero;
using sedbridge::testing::ReadLog;
using sedbridge::testing::Slurp;
using sedbridge::testing::Spawn;
using sedbridge::testing::WaitExit;
using sedbridge::testing::WaitFor;

std::string TempDir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("sedbridge_exit_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d.string();
}

// Waits (up to `limit_s`) until `path` holds more than `bytes`: the run is in its loop.
bool WaitForBytes(const std::string& path, std::uintmax_t bytes, double limit_s) {
  return WaitFor(
      [&] {
        std::error_code ec;
        return fs::exists(path, ec) && fs::file_size(path, ec) > bytes;
      },
      limit_s);
}

// B_coarse on memq://, LCM log in `dir`.
std::string WriteConfig(const std::string& dir) {
  const std::string path = dir + "/bridge.yaml";
  // The curve: exit paths are about the limiter and the watchdog, not the renderer.
  std::ofstream(path) << "fe: {model: B_coarse, preset: fast}\ndisplay: {profile: suction_4x4, rendering: curve}\nlcm: {url: \"memq://\", log: \""
                      << dir << "/bridge.lcmlog\"}\n";
  return path;
}

std::string ExampleLog() { return std::string(SEDBRIDGE_SOURCE_DIR) + "/config/bridge/example_press.log"; }

// Copies the example log to `path`, shifting line stamps at or after `from_us` by `shift_us`;
// `repeats` > 1 appends further copies, each 3 s later (a press every 3 s).
void WriteShiftedLog(const std::string& path, long long from_us, long long shift_us, int repeats = 1) {
  std::ofstream out(path);
  for (int r = 0; r < repeats; ++r) {
    std::ifstream in(ExampleLog());
    for (std::string line; std::getline(in, line);) {
      // "(1700000001.500000) can0 ..." : seconds and micros.
      const long long s = std::stoll(line.substr(1, 10));
      const long long us = std::stoll(line.substr(12, 6));
      long long t = s * 1000000 + us + r * 3000000LL;
      if (t >= from_us) t += shift_us;
      char stamp[32];
      std::snprintf(stamp, sizeof stamp, "(%lld.%06lld)", t / 1000000, t % 1000000);
      out << stamp << line.substr(19) << "\n";
    }
  }
}

const char* Abbrev(int sig) {
  switch (sig) {
    case SIGINT: return "INT";
    case SIGTERM: return "TERM";
    case SIGHUP: return "HUP";
    case SIGQUIT: return "QUIT";
  }
  return "OTHER";
}

std::vector<std::string> CommandFor(const std::string& which, const std::string& dir) {
  const std::string bin = SEDBRIDGE_BINARY, config = WriteConfig(dir);
  if (which == "run") {  // 20 presses at recorded speed: 60 s, far longer than the test needs
    WriteShiftedLog(dir + "/long.log", 0, 0, 20);
    return {bin, "run", "--config", config, "--log-input", dir + "/long.log", "--duration-s", "600"};
  }
  if (which == "replay")
    return {bin, "replay", ExampleLog(), "--config", config, "--speed", "0.25", "--out", dir, "--no-plots", "--quiet"};
  return {bin, "simulate", std::string(SEDBRIDGE_SOURCE_DIR) + "/config/scenes/sensor_sphere_press.yaml", "--config",
          config, "--duration-s", "600", "--out", dir, "--no-plots", "--quiet"};
}

struct Case {
  std::string command;
  int signal;
};

// Readable test names in ctest's output.
void PrintTo(const Case& c, std::ostream* os) { *os << c.command << " + signal " << c.signal; }

class ExitPaths : public ::testing::TestWithParam<Case> {};

TEST_P(ExitPaths, SignalPublishesAFinalZeroAndClosesTheLog) {
  const Case c = GetParam();
  const std::string dir = TempDir(c.command + std::to_string(c.signal));
  const pid_t pid = Spawn(CommandFor(c.command, dir), dir + "/out.txt");
  ASSERT_GT(pid, 0);
  // In its loop once the log has grown (model loaded, commands flowing).
  const bool running = WaitForBytes(dir + "/bridge.lcmlog", 8192, 120);
  ::kill(pid, c.signal);
  const int status = WaitExit(pid, 60);
  const std::string out = Slurp(dir + "/out.txt");
  ASSERT_TRUE(running) << out;
  // 128 + signal: it was stopped by the signal (not by the end of its input) and exited itself.
  ASSERT_EQ(status, 128 + c.signal) << out;
  const auto log = ReadLog(dir + "/bridge.lcmlog");
  EXPECT_TRUE(log.whole()) << "cut record: " << log.record_bytes << " of " << log.file_bytes << " bytes";
  ASSERT_FALSE(log.commands.empty());
  EXPECT_GT(log.commands.size(), 3u);
  const auto& last = log.commands.back();
  EXPECT_TRUE(last.shutdown);
  EXPECT_TRUE(AllZero(last));
  fs::remove_all(dir);
}

std::vector<Case> AllCases() {
  std::vector<Case> cases;
  for (const char* command : {"run", "replay", "simulate"})
    for (int sig : {SIGINT, SIGTERM, SIGHUP, SIGQUIT}) cases.push_back({command, sig});
  return cases;
}

INSTANTIATE_TEST_SUITE_P(EverySignalEveryCommand, ExitPaths, ::testing::ValuesIn(AllCases()),
                         [](const ::testing::TestParamInfo<Case>& info) {
                           return info.param.command + "_" + std::string(Abbrev(info.param.signal));
                         });

// A hand on `run` (two fingers on can0 and can1, the two-bus example log played at speed):
// a signal zeroes every finger's display, each in its own log (lcm.log gets the finger's name).
TEST(ExitPaths, HandRunSignalZeroesEveryFingersDisplayInItsOwnLog) {
  const std::string dir = TempDir("hand");
  const std::string config = dir + "/hand.yaml";
  std::ofstream(config) << "fe: {model: B_coarse, preset: fast}\ndisplay: {profile: suction_4x4, rendering: curve}\n"
                           "lcm: {url: \"memq://\", log: \""
                        << dir << "/bridge.lcmlog\"}\nfingers:\n"
                                  "  - {name: thumb, sensor: {profile: uskin_4x4, interface: can0}}\n"
                                  "  - {name: middle, sensor: {profile: uskin_4x4, interface: can1}}\n";
  const pid_t pid = Spawn({SEDBRIDGE_BINARY, "run", "--config", config, "--log-input",
                           std::string(SEDBRIDGE_SOURCE_DIR) + "/config/bridge/example_hand.log", "--duration-s", "600"},
                          dir + "/out.txt");
  ASSERT_GT(pid, 0);
  const bool running = WaitForBytes(dir + "/bridge_thumb.lcmlog", 8192, 120);
  ::kill(pid, SIGINT);
  const int status = WaitExit(pid, 60);
  const std::string out = Slurp(dir + "/out.txt");
  ASSERT_TRUE(running) << out;
  ASSERT_EQ(status, 128 + SIGINT) << out;
  for (const std::string finger : {"thumb", "middle"}) {
    std::string channel = "DISPLAY_COMMAND_";
    for (char ch : finger) channel += char(std::toupper(static_cast<unsigned char>(ch)));
    const auto log = ReadLog(dir + "/bridge_" + finger + ".lcmlog", channel);
    EXPECT_TRUE(log.whole()) << finger;
    ASSERT_FALSE(log.commands.empty()) << finger;
    EXPECT_TRUE(log.commands.back().shutdown) << finger;
    EXPECT_TRUE(AllZero(log.commands.back())) << finger;
  }
  fs::remove_all(dir);
}

TEST(ExitPaths, LiveReplayPausedMidPressRampsToZeroOnItsOwnTicks) {
  // The example press with a 3 s hole at t = 1.5 s, where the display is at ~2 kPa (found by
  // adversarial review: a live replay held 20 kPa through 3 s of silence). Played at speed 2:
  // 1.5 s of wall time.
  const std::string dir = TempDir("pause");
  const std::string log = dir + "/paused.log";
  WriteShiftedLog(log, 1700000001500000LL, 3000000);
  const std::string bin = SEDBRIDGE_BINARY;
  const pid_t pid = Spawn(
      {bin, "replay", log, "--config", WriteConfig(dir), "--speed", "2", "--out", dir, "--no-plots", "--quiet"},
      dir + "/out.txt");
  const int status = WaitExit(pid, 120);
  ASSERT_EQ(status, 0) << Slurp(dir + "/out.txt");
  const auto check = ReadLog(dir + "/bridge.lcmlog");
  EXPECT_TRUE(check.whole());
  // suction_4x4: watchdog 0.1 s, slew 200 kPa/s, max 20 kPa -> zero within 0.2 s of log time.
  const int64_t gap_start = 1700000001500000LL, gap_end = gap_start + 3000000;
  double before = 0;
  int in_gap = 0, zero_late = 0;
  for (const auto& m : check.commands) {
    if (m.utime < gap_start) {
      for (float v : m.value) before = std::max(before, double(v));
      continue;
    }
    if (m.utime >= gap_end) break;
    ++in_gap;
    if (m.utime > gap_start + 200000) {
      EXPECT_TRUE(AllZero(m)) << "not zero " << (m.utime - gap_start) * 1e-6 << " s into the pause";
      EXPECT_TRUE(m.stale);
      ++zero_late;
    }
  }
  EXPECT_GT(before, 1.0) << "the press must be on when the pause starts";
  // Ticked through the pause (at tick_Hz, nominally 600 ticks of wall time; any dozen will do).
  EXPECT_GT(in_gap, 12);
  EXPECT_GT(zero_late, 10);
  fs::remove_all(dir);
}

}  // namespace
