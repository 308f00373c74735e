// `sedbridge simulate` with a hand (`fingers:`): one simulated sensor per finger, merged in
// time order and run as the hand's replay (runs the built program, reads the logs it leaves).

#include <gtest/gtest.h>

#include <unistd.h>

#include <cctype>
#include <filesystem>
#include <fstream>
#include <string>

#include "tests/common/child_process.h"
#include "tests/common/lcm_log_check.h"

namespace {

namespace fs = std::filesystem;

// Three fingers on B_coarse with the curve (memq): thumb and index on can0 (the index's ids
// moved past the thumb's), middle on can1.
std::string WriteHandConfig(const std::string& dir) {
  const std::string path = dir + "/hand.yaml";
  std::ofstream(path) << "fe: {model: B_coarse, preset: fast}\ndisplay: {profile: suction_4x4, rendering: curve}\n"
                         "lcm: {url: \"memq://\"}\nfingers:\n"
                         "  - {name: thumb, sensor: {profile: uskin_4x4, interface: can0}}\n"
                         "  - {name: index, sensor: {profile: uskin_4x4, interface: can0, id_offset: 32}}\n"
                         "  - {name: middle, sensor: {profile: uskin_4x4, interface: can1}}\n";
  return path;
}

int Lines(const std::string& path) {
  std::ifstream f(path);
  int lines = 0;
  for (std::string l; std::getline(f, l);) ++lines;
  return lines;
}

// The sphere press for thumb and index (SCENE), the edge slide for middle (its own scene):
// each finger's files in DIR/<finger>/, every scan of its sensor stepped, its display driven
// by its press and at zero when the run ends.
TEST(SimulateHand, ThreeFingersWriteEachFingersOutputsAndEveryDisplayEndsAtZero) {
  const fs::path dir = fs::temp_directory_path() / ("sedbridge_simulate_hand_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string scenes = std::string(SEDBRIDGE_SOURCE_DIR) + "/config/scenes/";
  const sedbridge::testing::ShellResult r = sedbridge::testing::RunShell(
      std::string(SEDBRIDGE_BINARY) + " simulate " + scenes + "sensor_sphere_press.yaml --config " +
      WriteHandConfig(dir.string()) + " --finger-scenes middle=" + scenes +
      "sensor_edge_slide.yaml --duration-s 0.8 --no-plots --quiet --out " + dir.string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("hand: 3 fingers"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("frames no finger claims"), std::string::npos) << r.output;
  for (const std::string finger : {"thumb", "index", "middle"}) {
    const fs::path out = dir / finger;
    // 0.8 s at 100 Hz: 80 scans, each a row after the header.
    EXPECT_EQ(Lines((out / "summary.csv").string()), 81) << finger;
    for (const char* file : {"stage_ms.csv", "peak_merkel_sed.csv", "peak_command.csv", "peak_taxels.csv"})
      EXPECT_TRUE(fs::exists(out / file)) << finger << " " << file;
    std::string channel = "DISPLAY_COMMAND_";
    for (char ch : finger) channel += char(std::toupper(static_cast<unsigned char>(ch)));
    const auto log = sedbridge::testing::ReadLog((out / "bridge.lcmlog").string(), channel);
    EXPECT_TRUE(log.whole()) << finger;
    ASSERT_FALSE(log.commands.empty()) << finger;
    bool driven = false;
    for (const auto& m : log.commands) driven |= !sedbridge::testing::AllZero(m);
    EXPECT_TRUE(driven) << finger << ": its press drove no command";
    EXPECT_TRUE(log.commands.back().shutdown) << finger;
    EXPECT_TRUE(sedbridge::testing::AllZero(log.commands.back())) << finger;
  }
  fs::remove_all(dir);
}

TEST(SimulateHand, FingerScenesNamingNoFingerOrAOneFingerConfigAreRefused) {
  const fs::path dir = fs::temp_directory_path() / ("sedbridge_simulate_hand_bad_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string scene = std::string(SEDBRIDGE_SOURCE_DIR) + "/config/scenes/sensor_sphere_press.yaml";
  const std::string bin = std::string(SEDBRIDGE_BINARY) + " simulate " + scene;
  sedbridge::testing::ShellResult r =
      sedbridge::testing::RunShell(bin + " --config " + WriteHandConfig(dir.string()) + " --finger-scenes ring=" + scene +
                                   " --no-plots --quiet --out " + dir.string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("no finger 'ring' in the config (its fingers: thumb, index, middle)"), std::string::npos)
      << r.output;
  const std::string one = (dir / "one.yaml").string();
  std::ofstream(one) << "fe: {model: B_coarse, preset: fast}\nlcm: {url: \"memq://\"}\n";
  r = sedbridge::testing::RunShell(bin + " --config " + one + " --finger-scenes thumb=" + scene +
                                   " --no-plots --quiet --out " + dir.string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("--finger-scenes needs a config with 'fingers:'"), std::string::npos) << r.output;
  fs::remove_all(dir);
}

}  // namespace
