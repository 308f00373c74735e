// A hand's replay (bridge::RunHandReplay): frames routed by bus and CAN id to each finger,
// one finger's silent sensor ramps its own display to zero while the others go on, fingers
// with different sensors and displays, the same files run to run, and a finger whose leader
// model fails stops the start-up before any display is driven.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "bridge/fingers.h"
#include "bridge/replay.h"
#include "lcm/lcm_log_reader.h"
#include "sedbridge/lcmt_bridge_status.hpp"
#include "sedbridge/lcmt_display_command.hpp"
#include "sensors/candump_log.h"
#include "sensors/interface_filter_source.h"
#include "tests/bridge/bridge_test_util.h"

namespace sedbridge::bridge {
namespace {

std::string TempDir(const std::string& name) {
  const std::string dir = (std::filesystem::temp_directory_path() / ("sedbridge_hand_" + name)).string();
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

// The example log on can0 and, until `can1_until_s` after its start, the same frames on can1
// (then, with `bus_off`, a bus-off error frame on can1).
std::string TwoBusLog(const std::string& dir, double can1_until_s, bool bus_off = false) {
  std::ifstream in(testing::ExampleLogPath());
  const std::string path = dir + "/two_bus.log";
  std::ofstream out(path);
  double t0 = -1;
  for (std::string line; std::getline(in, line);) {
    out << line << '\n';
    const double t = std::stod(line.substr(1, line.find(')') - 1));
    if (t0 < 0) t0 = t;
    const size_t bus = line.find(" can0 ");
    if (bus != std::string::npos && t - t0 < can1_until_s) out << line.substr(0, bus) << " can1 " << line.substr(bus + 6) << '\n';
    if (bus_off && t - t0 >= can1_until_s) {
      out << line.substr(0, bus) << " can1 20000040#0000000000000000\n";  // CAN_ERR_FLAG | CAN_ERR_BUSOFF
      bus_off = false;
    }
  }
  return path;
}

std::vector<HandFinger> HandOf(const BridgeConfig& config) {
  std::vector<HandFinger> hand;
  for (Finger& f : FingersOf(config))
    hand.push_back({f.name, f.config, LoadFingerSensorProfile(f.config),
                    display::LoadNamedDisplayProfile(f.config.display_profile), nullptr});
  return hand;
}

// The test bridge (B_coarse, curve) with `fingers` appended.
BridgeConfig HandConfig(const std::string& fingers_yaml) {
  std::ifstream in(testing::TestConfigPath());
  std::stringstream yaml;
  yaml << in.rdbuf() << "fingers:\n" << fingers_yaml;
  return ParseBridgeConfig(yaml.str(), "hand.yaml");
}

struct Command {
  int64_t utime;
  float max;
  bool shutdown;
};

std::vector<Command> CommandsOn(const std::string& log, const std::string& channel) {
  lcm_io::LcmLogReader reader(log);
  std::vector<Command> out;
  while (const lcm::LogEvent* e = reader.Next()) {
    lcmt_display_command c;
    if (e->channel != channel || !lcm_io::LcmLogReader::Decode(*e, &c)) continue;
    out.push_back({c.utime, c.value.empty() ? 0.f : *std::max_element(c.value.begin(), c.value.end()), bool(c.shutdown)});
  }
  return out;
}

TEST(MultiFingerReplay, SilentSensorRampsItsOwnDisplayToZeroWhileTheOthersGoOn) {
  const std::string dir = TempDir("silent");
  // index's sensor goes silent at 1.2 s, in the middle of the press (peak about 1.5 s).
  const std::string log = TwoBusLog(dir, 1.2);
  const BridgeConfig config = HandConfig("  - {name: thumb, sensor: {interface: can0}}\n"
                                         "  - {name: index, sensor: {interface: can1}}\n");
  sensors::CandumpLogSource source(log);
  ReplayOptions options;
  options.out_dir = dir + "/out";
  const HandReplayResult r = RunHandReplay(HandOf(config), source, options);
  ASSERT_EQ(r.fingers.size(), 2u);
  EXPECT_EQ(r.fingers[0].rows.size(), 300u);
  EXPECT_EQ(r.fingers[1].rows.size(), 120u);
  EXPECT_TRUE(r.unclaimed_frames.empty());

  const auto thumb = CommandsOn(options.out_dir + "/thumb/bridge.lcmlog", "DISPLAY_COMMAND_THUMB");
  const auto index = CommandsOn(options.out_dir + "/index/bridge.lcmlog", "DISPLAY_COMMAND_INDEX");
  const int64_t t0 = r.fingers[0].rows.front().utime;
  const int64_t silent = t0 + 1'200'000;
  float index_before = 0, index_late = 0, thumb_late = 0;
  int index_late_commands = 0;
  for (const Command& c : index) {
    if (c.shutdown) continue;
    if (c.utime < silent) index_before = std::max(index_before, c.max);
    if (c.utime > silent + 500'000 && c.utime < t0 + 2'000'000) index_late = std::max(index_late, c.max), ++index_late_commands;
  }
  for (const Command& c : thumb)
    if (!c.shutdown && c.utime > silent + 500'000 && c.utime < t0 + 2'000'000) thumb_late = std::max(thumb_late, c.max);
  EXPECT_GT(index_before, 0.5f);       // pressed before its sensor fell silent
  EXPECT_GT(index_late_commands, 10);  // ticked in log time while thumb's scans came
  EXPECT_EQ(index_late, 0.f);          // ... down to zero
  EXPECT_GT(thumb_late, 0.5f);         // thumb went on
  // Every exit zeroes every display.
  ASSERT_FALSE(thumb.empty());
  ASSERT_FALSE(index.empty());
  EXPECT_TRUE(thumb.back().shutdown && thumb.back().max == 0.f);
  EXPECT_TRUE(index.back().shutdown && index.back().max == 0.f);
  std::filesystem::remove_all(dir);
}

TEST(MultiFingerReplay, BusOffOnOneBusFaultsThatFingerAloneAndRampsItsDisplayToZero) {
  const std::string dir = TempDir("bus_off");
  const std::string log = TwoBusLog(dir, 1.2, true);
  const BridgeConfig config = HandConfig("  - {name: thumb, sensor: {interface: can0}}\n"
                                         "  - {name: index, sensor: {interface: can1}}\n");
  sensors::CandumpLogSource source(log);
  ReplayOptions options;
  options.out_dir = dir + "/out";
  options.finger_threads = 2;
  const HandReplayResult r = RunHandReplay(HandOf(config), source, options);
  EXPECT_EQ(r.fingers[1].bad_frames.bus_off_events, 1);
  EXPECT_EQ(r.fingers[0].bad_frames.bus_off_events, 0);
  const int64_t late = r.fingers[0].rows.front().utime + 1'700'000;
  auto status_at = [&](const std::string& finger) {
    lcm_io::LcmLogReader reader(options.out_dir + "/" + finger + "/bridge.lcmlog");
    lcmt_bridge_status last{};
    while (const lcm::LogEvent* e = reader.Next()) {
      lcmt_bridge_status st;
      if (e->channel == "BRIDGE_STATUS" + FingerChannelSuffix(finger) && lcm_io::LcmLogReader::Decode(*e, &st) &&
          st.utime <= late && st.fault_message != "shut down")
        last = st;
    }
    return last;
  };
  EXPECT_EQ(status_at("index").fault_state, 2);
  EXPECT_EQ(status_at("index").fault_message, "CAN bus-off");
  EXPECT_EQ(status_at("thumb").fault_state, 0);
  float index_late = 0, thumb_late = 0;
  for (const Command& c : CommandsOn(options.out_dir + "/index/bridge.lcmlog", "DISPLAY_COMMAND_INDEX"))
    if (!c.shutdown && c.utime > late - 200'000) index_late = std::max(index_late, c.max);
  for (const Command& c : CommandsOn(options.out_dir + "/thumb/bridge.lcmlog", "DISPLAY_COMMAND_THUMB"))
    if (!c.shutdown && c.utime > late - 200'000 && c.utime < late) thumb_late = std::max(thumb_late, c.max);
  EXPECT_EQ(index_late, 0.f);
  EXPECT_GT(thumb_late, 0.5f);
  std::filesystem::remove_all(dir);
}

TEST(MultiFingerReplay, FingersWithDifferentSensorsAndDisplaysGiveTheSameFilesOnOneAndTwoThreads) {
  // The shipped three-finger log: uskin_4x4 on can0 and can1, cyskin_16 (one axis, 250 Hz) on can0.
  const BridgeConfig config = HandConfig(
      "  - {name: thumb, sensor: {profile: uskin_4x4, interface: can0}}\n"
      "  - {name: index, sensor: {profile: cyskin_16, interface: can0}, display: {profile: pin_6x4}}\n"
      "  - {name: middle, sensor: {profile: uskin_4x4, interface: can1}, display: {profile: electrotactile_4x4}}\n");
  const std::string log = std::string(SEDBRIDGE_SOURCE_DIR) + "/config/bridge/example_hand.log";
  std::string summaries[2];
  for (int run = 0; run < 2; ++run) {
    const std::string dir = TempDir("profiles" + std::to_string(run));
    sensors::CandumpLogSource source(log);
    ReplayOptions options;
    options.out_dir = dir;
    options.finger_threads = run == 0 ? 1 : 2;  // the same files on any number of threads
    const HandReplayResult r = RunHandReplay(HandOf(config), source, options);
    EXPECT_EQ(r.finger_threads, options.finger_threads);
    ASSERT_EQ(r.fingers.size(), 3u);
    EXPECT_EQ(r.fingers[0].rows.size(), 300u);
    EXPECT_EQ(r.fingers[1].rows.size(), 750u);
    EXPECT_EQ(r.fingers[2].rows.size(), 300u);
    EXPECT_EQ(r.fingers[0].display_actuators, 16);
    EXPECT_EQ(r.fingers[1].display_actuators, 24);
    for (const ReplayResult& f : r.fingers) {
      EXPECT_EQ(f.counters.scans_rejected, 0);
      ASSERT_GE(f.peak_index, 0);
      EXPECT_GT(f.rows[size_t(f.peak_index)].max_command, 0.0);
    }
    // Each finger pressed at its own time: thumb 0.3-1.6 s, index 1.0-2.2 s, middle 1.6-2.9 s.
    const int64_t t0 = r.fingers[0].rows.front().utime;
    const double peaks_s[3] = {(r.fingers[0].rows[size_t(r.fingers[0].peak_index)].utime - t0) * 1e-6,
                               (r.fingers[1].rows[size_t(r.fingers[1].peak_index)].utime - t0) * 1e-6,
                               (r.fingers[2].rows[size_t(r.fingers[2].peak_index)].utime - t0) * 1e-6};
    EXPECT_GT(peaks_s[0], 0.6);
    EXPECT_LT(peaks_s[0], 1.3);
    EXPECT_GT(peaks_s[1], 1.3);
    EXPECT_LT(peaks_s[1], 1.9);
    EXPECT_GT(peaks_s[2], 1.9);
    EXPECT_LT(peaks_s[2], 2.6);
    for (const char* finger : {"thumb", "index", "middle"}) {
      std::ifstream summary(dir + "/" + finger + "/summary.csv");
      std::string line;
      while (std::getline(summary, line)) {
        // latency_ms (column 5) is the one wall-clock value
        std::vector<std::string> cols;
        std::stringstream ss(line);
        for (std::string c; std::getline(ss, c, ',');) cols.push_back(c);
        if (cols.size() > 5) cols[5].clear();
        for (const std::string& c : cols) summaries[run] += c + ',';
        summaries[run] += '\n';
      }
      for (const Command& c : CommandsOn(dir + "/" + finger + "/bridge.lcmlog", "DISPLAY_COMMAND" + FingerChannelSuffix(finger)))
        summaries[run] += std::to_string(c.utime) + ' ' + std::to_string(c.max) + (c.shutdown ? " shutdown\n" : "\n");
    }
    std::filesystem::remove_all(dir);
  }
  EXPECT_GT(summaries[0].size(), 1000u);
  EXPECT_EQ(summaries[0], summaries[1]);
}

// Once its finger's press has ended, a pin display's commands are 0: a pin is retracted,
// not left at its gap with the ~0 stroke a converged fit holds (it commanded 0.95 mm there).
TEST(MultiFingerReplay, PinsRetractOnceTheirFingersPressHasEnded) {
  // The shipped hand (model B, inverse rendering); its index finger wears pin_6x4.
  const BridgeConfig config = LoadBridgeConfig(std::string(SEDBRIDGE_SOURCE_DIR) + "/config/bridge/example_hand.yaml");
  sensors::CandumpLogSource source(std::string(SEDBRIDGE_SOURCE_DIR) + "/config/bridge/example_hand.log");
  const HandReplayResult r = RunHandReplay(HandOf(config), source, ReplayOptions{});
  ASSERT_EQ(r.fingers.size(), 3u);
  const ReplayResult& index = r.fingers[1];
  ASSERT_EQ(index.display_actuators, 24);
  const std::vector<ReplayRow>& rows = index.rows;
  ASSERT_GE(index.peak_index, 0);
  EXPECT_GT(rows[size_t(index.peak_index)].max_command, 0.0);
  int64_t last_touch = -1;
  for (const ReplayRow& row : rows)
    if (row.total_force_N > 0.005) last_touch = row.utime;
  ASSERT_GT(last_touch, 0);
  int after = 0;
  for (const ReplayRow& row : rows) {
    if (row.utime < last_touch + 200'000) continue;  // the limiter's ramp down
    ++after;
    EXPECT_EQ(row.max_command, 0.0) << "at " << (row.utime - rows.front().utime) * 1e-6 << " s";
  }
  EXPECT_GT(after, 50);
}

std::string SummaryWithoutLatency(const std::vector<ReplayRow>& rows) {
  std::string out;
  char buf[256];
  for (const ReplayRow& r : rows) {
    std::snprintf(buf, sizeof buf, "%lld,%.9g,%.9g,%.9g,%.9g,%d,%d\n", static_cast<long long>(r.utime), r.total_force_N,
                  r.applied_force_N, r.max_sed_Pa, r.max_command, r.stepped ? 1 : 0, r.invalid_taxels);
    out += buf;
  }
  return out;
}

TEST(MultiFingerReplay, SharedLeaderModelGivesEachFingerWhatItsReplayAloneGives) {
  const std::string dir = TempDir("shared");
  const std::string log = TwoBusLog(dir, 10);
  std::ifstream in(testing::TestConfigPath());
  std::stringstream yaml;
  yaml << in.rdbuf() << "fe: {model: B_coarse, preset: fast, step: contact, compliance_cache: " << dir << "/cache}\n"
       << "fingers:\n  - {name: thumb, sensor: {interface: can0}}\n  - {name: index, sensor: {interface: can1}}\n";
  std::string text = yaml.str();
  text.replace(text.find("fe: {model: B_coarse, preset: fast}\n"), std::string("fe: {model: B_coarse, preset: fast}\n").size(), "");
  const BridgeConfig config = ParseBridgeConfig(text, "hand.yaml");
  sensors::CandumpLogSource source(log);
  const HandReplayResult hand = RunHandReplay(HandOf(config), source, ReplayOptions{});
  EXPECT_EQ(hand.leader_models_loaded, 1);
  EXPECT_EQ(hand.leader_models_shared, 1);
  EXPECT_EQ(hand.leader_operators_shared, 1);
  const std::vector<Finger> fingers = FingersOf(config);
  for (size_t i = 0; i < 2; ++i) {
    sensors::CandumpLogSource whole(log);
    sensors::InterfaceFilterSource one_bus(whole, fingers[i].config.can_interface);
    const ReplayResult alone = testing::ReplayWithConfigProfiles(fingers[i].config, one_bus, ReplayOptions{});
    ASSERT_EQ(hand.fingers[i].rows.size(), 300u);
    EXPECT_EQ(SummaryWithoutLatency(hand.fingers[i].rows), SummaryWithoutLatency(alone.rows)) << fingers[i].name;
    EXPECT_GT(hand.fingers[i].rows[size_t(hand.fingers[i].peak_index)].max_sed_Pa, 100.0);
  }
  std::filesystem::remove_all(dir);
}

TEST(MultiFingerReplay, LeaderModelThatFailsStopsStartUpBeforeAnyDisplayIsDriven) {
  const std::string dir = TempDir("bad_model");
  const BridgeConfig config = HandConfig("  - {name: thumb, sensor: {interface: can0}}\n"
                                         "  - {name: index, sensor: {interface: can1}, fe: {model: no_such_model}}\n");
  sensors::CandumpLogSource source(TwoBusLog(dir, 10));
  ReplayOptions options;
  options.out_dir = dir + "/out";
  try {
    RunHandReplay(HandOf(config), source, options);
    FAIL() << "no error";
  } catch (const std::exception& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("finger 'index'"), std::string::npos) << what;
    EXPECT_NE(what.find("no_such_model"), std::string::npos) << what;
  }
  // No display session was made: no log, nothing published.
  EXPECT_FALSE(std::filesystem::exists(options.out_dir + "/thumb/bridge.lcmlog"));
  EXPECT_FALSE(std::filesystem::exists(options.out_dir + "/index/bridge.lcmlog"));
  std::filesystem::remove_all(dir);
}

TEST(MultiFingerReplay, FramesNoFingerClaimsAreCountedPerInterface) {
  const std::string dir = TempDir("unclaimed");
  const BridgeConfig config = HandConfig("  - {name: thumb, sensor: {interface: can0}}\n"
                                         "  - {name: index, sensor: {interface: can2}}\n");
  sensors::CandumpLogSource source(TwoBusLog(dir, 1.0));
  const HandReplayResult r = RunHandReplay(HandOf(config), source, ReplayOptions{});
  EXPECT_EQ(r.fingers[0].rows.size(), 300u);
  EXPECT_TRUE(r.fingers[1].rows.empty());
  ASSERT_EQ(r.unclaimed_frames.count("can1"), 1u);
  EXPECT_EQ(r.unclaimed_frames.at("can1"), 100 * 16);
  EXPECT_EQ(r.unclaimed_frames.count("can0"), 0u);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace sedbridge::bridge
