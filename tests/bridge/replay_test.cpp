// End to end: the example candump log through the whole chain over memq://, the published
// commands checked; determinism of two replays (the pipeline's own paths:
// bridge_pipeline_test.cpp).

#include "bridge/replay.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <lcm/lcm-cpp.hpp>

#include "bridge_test_util.h"
#include "lcm/display_command_message.h"
#include "lcm/lcm_log_reader.h"
#include "lcm/merkel_sed_message.h"
#include "sedbridge/lcmt_bridge_status.hpp"
#include "sedbridge/lcmt_display_command.hpp"
#include "sedbridge/lcmt_display_rendering.hpp"
#include "sensors/candump_log.h"
#include "tests/common/lcm_log_check.h"

namespace sedbridge::bridge {
namespace {

struct Collector {
  std::vector<lcmt_display_command> commands;
  std::vector<lcmt_bridge_status> status;
  int scans = 0;
  void OnCommand(const lcm::ReceiveBuffer*, const std::string&, const lcmt_display_command* m) {
    commands.push_back(*m);
  }
  void OnStatus(const lcm::ReceiveBuffer*, const std::string&, const lcmt_bridge_status* m) { status.push_back(*m); }
  void OnScan(const lcm::ReceiveBuffer*, const std::string&) { ++scans; }
};

std::string TempDir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("sedbridge_bridge_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  return dir.string();
}

TEST(Replay, ExampleLogOverMemqPublishesOrderedLimitedCommands) {
  const BridgeConfig config = testing::TestConfig();
  sensors::CandumpLogSource source(testing::ExampleLogPath());
  Collector got;
  lcm::LCM* lcm = nullptr;
  ReplayOptions options;
  options.on_start = [&](BridgePipeline& p) {
    lcm = &p.display().publisher().lcm();
    lcm->subscribe(config.lcm.channels.command, &Collector::OnCommand, &got);
    lcm->subscribe(config.lcm.channels.status, &Collector::OnStatus, &got);
    lcm->subscribe(config.lcm.channels.tactile_scan, &Collector::OnScan, &got);
  };
  auto drain = [&] {
    while (lcm && lcm->handleTimeout(0) > 0) {
    }
  };
  options.on_scan = [&](const ScanOutcome&, BridgePipeline&) { drain(); };
  options.on_finish = [&](BridgePipeline&) {
    drain();
    lcm = nullptr;  // dies with the pipeline
  };
  const ReplayResult r = testing::ReplayWithConfigProfiles(config, source, options);

  // 3 s at 100 Hz: every scan processed, one command each, plus the shutdown commands.
  ASSERT_EQ(r.rows.size(), 300u);
  EXPECT_EQ(r.counters.steps, 300);
  EXPECT_EQ(r.counters.scans_rejected, 0);
  EXPECT_EQ(got.scans, 300);
  ASSERT_EQ(got.commands.size(), 300u + lcm_io::DisplaySession::kShutdownRepeats);
  const double max = 20.0;  // suction_4x4 safety.max [kPa]
  int nonzero = 0;
  for (size_t i = 0; i < got.commands.size(); ++i) {
    const lcmt_display_command& c = got.commands[i];
    EXPECT_EQ(c.sequence, static_cast<int64_t>(i));
    if (i > 0) {
      EXPECT_GE(c.utime, got.commands[i - 1].utime);
    }
    ASSERT_EQ(c.num_actuators, 16);
    for (float v : c.value) {
      EXPECT_GE(v, 0.0f);
      EXPECT_LE(v, max);
    }
    EXPECT_FALSE(c.fault);
    if (i < 300) {
      EXPECT_EQ(c.source_scan_utime, r.rows[i].utime);
    }
    float m = 0;
    for (float v : c.value) m = std::max(m, v);
    if (m > 0) ++nonzero;
  }
  // At rest (first 0.4 s, sphere above the pad; and the shutdown): all zero.
  for (size_t i = 0; i < 40; ++i)
    for (float v : got.commands[i].value) EXPECT_EQ(v, 0.0f) << "command " << i;
  for (size_t i = 300; i < got.commands.size(); ++i) {
    EXPECT_TRUE(got.commands[i].shutdown);
    for (float v : got.commands[i].value) EXPECT_EQ(v, 0.0f);
  }
  // In contact (peak around t = 1.5 s): clearly non-zero.
  float peak = 0;
  for (size_t i = 130; i < 170; ++i)
    for (float v : got.commands[i].value) peak = std::max(peak, v);
  EXPECT_GT(peak, 0.5f);
  EXPECT_GT(nonzero, 40);
  // Force at the peak: the sphere reaches about 0.8 N on the sensor; the FE applied the same.
  const ReplayRow& p = r.rows[size_t(r.peak_index)];
  EXPECT_GT(p.total_force_N, 0.4);
  EXPECT_NEAR(p.applied_force_N, p.total_force_N, 1e-6 * p.total_force_N);
  // Status at ~10 Hz of log time (3 s) plus the final one.
  EXPECT_GE(got.status.size(), 28u);
  EXPECT_LE(got.status.size(), 32u);
  EXPECT_EQ(got.status.back().fault_state, 2);  // "shut down"
  EXPECT_EQ(got.status.back().scans_received, 300);
  // Where the time went: every stepped scan ran conditioning, the FE step and the display;
  // the status carries the window's medians of those stages.
  for (const ReplayRow& row : r.rows) {
    EXPECT_GT(row.stage_ms[Stage::kConditioning], 0.0);
    EXPECT_GT(row.stage_ms[Stage::kSed], 0.0);
    EXPECT_GT(row.stage_ms[Stage::kLimiter], 0.0);
    EXPECT_GT(row.stage_ms[Stage::kPublish], 0.0);
  }
  EXPECT_GT(r.stage_p50_ms[Stage::kSed], 0.0);
  EXPECT_GT(got.status[got.status.size() / 2].sed_p50_ms, 0.0f);
  EXPECT_GT(got.status[got.status.size() / 2].limiter_p50_ms, 0.0f);
}

// DISPLAY_RENDERING: a viewer's message, at most outputs.rendering_Hz on the log's clock,
// naming the command it belongs to; zero where nothing is asked; 'limited' where the
// limiter's slew held the command back from the renderer's answer; none at rendering_Hz 0.
// slew_rate_per_s > 0 replaces the display profile's.
std::vector<lcmt_display_rendering> RenderingMessages(BridgeConfig config, std::vector<lcmt_display_command>* commands,
                                                      double slew_rate_per_s = 0) {
  sensors::CandumpLogSource source(testing::ExampleLogPath());
  display::DisplayProfile display = testing::ConfigDisplay(config);
  if (slew_rate_per_s > 0) display.safety.slew_rate_per_s = slew_rate_per_s;
  struct Got {
    std::vector<lcmt_display_rendering> rendering;
    std::vector<lcmt_display_command>* commands;
    void OnRendering(const lcm::ReceiveBuffer*, const std::string&, const lcmt_display_rendering* m) {
      rendering.push_back(*m);
    }
    void OnCommand(const lcm::ReceiveBuffer*, const std::string&, const lcmt_display_command* m) {
      commands->push_back(*m);
    }
  } got{{}, commands};
  lcm::LCM* lcm = nullptr;
  ReplayOptions options;
  options.on_start = [&](BridgePipeline& p) {
    lcm = &p.display().publisher().lcm();
    lcm->subscribe(config.lcm.channels.rendering, &Got::OnRendering, &got);
    lcm->subscribe(config.lcm.channels.command, &Got::OnCommand, &got);
  };
  auto drain = [&] {
    while (lcm && lcm->handleTimeout(0) > 0) {
    }
  };
  options.on_scan = [&](const ScanOutcome&, BridgePipeline&) { drain(); };
  options.on_finish = [&](BridgePipeline&) {
    drain();
    lcm = nullptr;
  };
  RunReplay(config, sensors::LoadNamedSensorProfile(config.sensor_profile), display, nullptr, source, options);
  return got.rendering;
}

TEST(Replay, DisplayRenderingIsDecimatedNamesItsCommandAndSaysWhenTheLimiterHeldItBack) {
  // B_coarse with pins (its suction holes are not resolved by that mesh: it renders zeros).
  BridgeConfig config = testing::TestConfig();
  config.display_profile = "pin_6x4";
  config.display_rendering = RenderingMethod::kInverse;
  ASSERT_EQ(config.rendering_Hz, 30.0);
  std::vector<lcmt_display_command> commands;
  const std::vector<lcmt_display_rendering> rendering = RenderingMessages(config, &commands);
  // 3 s of scans at 100 Hz: at most one message per 1/30 s, and about that many.
  ASSERT_GE(rendering.size(), 60u);
  EXPECT_LE(rendering.size(), 91u);
  int limited = 0, asked = 0;
  for (size_t k = 0; k < rendering.size(); ++k) {
    const lcmt_display_rendering& m = rendering[k];
    if (k > 0) {
      EXPECT_GE(m.utime - rendering[k - 1].utime, int64_t(1e6 / 30.0) - 1) << k;
    }
    ASSERT_GE(m.command_sequence, 0);
    ASSERT_LT(size_t(m.command_sequence), commands.size());
    const lcmt_display_command& c = commands[size_t(m.command_sequence)];
    EXPECT_EQ(c.utime, m.utime);
    ASSERT_GT(m.num_vertices, 0);
    ASSERT_EQ(m.target_sed_Pa.size(), size_t(m.num_vertices));
    ASSERT_EQ(m.delivered_sed_Pa.size(), size_t(m.num_vertices));
    float target = 0, delivered = 0;
    for (int v = 0; v < m.num_vertices; ++v) {
      ASSERT_TRUE(std::isfinite(m.delivered_sed_Pa[size_t(v)])) << k;
      target = std::max(target, m.target_sed_Pa[size_t(v)]);
      delivered = std::max(delivered, m.delivered_sed_Pa[size_t(v)]);
    }
    EXPECT_EQ(target, m.max_target_sed_Pa);
    EXPECT_EQ(delivered, m.max_delivered_sed_Pa);
    if (target == 0) {  // nothing asked: no fit, nothing delivered, nothing held back
      EXPECT_EQ(delivered, 0.0f) << k;
      EXPECT_FALSE(m.limited) << k;
    }
    asked += target > 0;
    limited += m.limited;
  }
  EXPECT_GT(asked, 20);
  EXPECT_LE(limited, asked);

  // A slow slew (10 kPa/s against the profile's) holds the command back from the renderer's
  // answer on the way up and down: said, not on every message.
  commands.clear();
  limited = asked = 0;
  for (const lcmt_display_rendering& m : RenderingMessages(config, &commands, 10.0)) {
    asked += m.max_target_sed_Pa > 0;
    limited += m.limited;
  }
  EXPECT_GT(limited, 0);
  EXPECT_LT(limited, asked);

  config.rendering_Hz = 0;
  commands.clear();
  EXPECT_TRUE(RenderingMessages(config, &commands).empty());
  EXPECT_EQ(commands.size(), 300u + lcm_io::DisplaySession::kShutdownRepeats);
}

std::string SummaryWithoutLatency(const std::string& path) {
  std::ifstream f(path);
  std::stringstream out;
  std::string line;
  while (std::getline(f, line)) {
    std::vector<std::string> cols;
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) cols.push_back(c);
    for (size_t i = 0; i < cols.size(); ++i)
      if (i != 5) out << cols[i] << ',';  // column 5 = latency_ms, the one wall-clock value
    out << '\n';
  }
  return out.str();
}

std::vector<std::string> LoggedCommands(const std::string& log) {
  lcm_io::LcmLogReader reader(log);
  std::vector<std::string> out;
  while (const lcm::LogEvent* e = reader.Next())
    if (e->channel == "DISPLAY_COMMAND" || e->channel == "TACTILE_SCAN")
      out.push_back(e->channel + std::to_string(e->timestamp) +
                    std::string(static_cast<const char*>(e->data), size_t(e->datalen)));
  return out;
}

TEST(Replay, TwoReplaysWriteIdenticalOutput) {
  const BridgeConfig config = testing::TestConfig();
  std::string dirs[2] = {TempDir("det_a"), TempDir("det_b")};
  for (const std::string& dir : dirs) {
    sensors::CandumpLogSource source(testing::ExampleLogPath());
    ReplayOptions options;
    options.out_dir = dir;
    options.vtu_every = 100;
    testing::ReplayWithConfigProfiles(config, source, options);
  }
  for (const char* f : {"frames.pvd", "frame_000000.vtu", "frame_000100.vtu", "frame_000200.vtu"})
    EXPECT_TRUE(std::filesystem::exists(dirs[0] + "/" + f)) << f;
  const std::string a = SummaryWithoutLatency(dirs[0] + "/summary.csv");
  EXPECT_EQ(std::count(a.begin(), a.end(), '\n'), 301);
  EXPECT_EQ(a, SummaryWithoutLatency(dirs[1] + "/summary.csv"));
  const auto la = LoggedCommands(dirs[0] + "/bridge.lcmlog");
  EXPECT_GT(la.size(), 600u);
  EXPECT_TRUE(la == LoggedCommands(dirs[1] + "/bridge.lcmlog"));
  for (const char* f : {"peak_merkel_sed.csv", "peak_command.csv", "peak_taxels.csv"}) {
    std::ifstream x(dirs[0] + "/" + f), y(dirs[1] + "/" + f);
    std::stringstream sx, sy;
    sx << x.rdbuf();
    sy << y.rdbuf();
    EXPECT_GT(sx.str().size(), 30u) << f;
    EXPECT_EQ(sx.str(), sy.str()) << f;
  }
  for (const std::string& dir : dirs) std::filesystem::remove_all(dir);
}


TEST(Replay, ExceptionInAStageStillZeroesTheDisplayAndClosesTheLog) {
  // A stage failing mid-press (here the per-scan callback, after the display is on) must
  // leave a final zero on the bus and in a whole log before the error propagates.
  const BridgeConfig config = testing::TestConfig();
  sensors::CandumpLogSource source(testing::ExampleLogPath());
  const std::string dir = TempDir("exception");
  ReplayOptions options;
  options.out_dir = dir;
  double max_seen = 0;
  options.on_scan = [&](const ScanOutcome& o, BridgePipeline&) {
    max_seen = std::max(max_seen, o.max_command);
    if (max_seen > 1.0) throw std::runtime_error("stage failed");
  };
  EXPECT_THROW(testing::ReplayWithConfigProfiles(config, source, options), std::runtime_error);
  ASSERT_GT(max_seen, 1.0);
  const auto log = sedbridge::testing::ReadLog(dir + "/bridge.lcmlog");
  EXPECT_TRUE(log.whole());
  ASSERT_FALSE(log.commands.empty());
  EXPECT_TRUE(log.commands.back().shutdown);
  EXPECT_TRUE(sedbridge::testing::AllZero(log.commands.back()));
  std::filesystem::remove_all(dir);
}

TEST(Replay, StopFlagEndsTheRunWithTheDisplayAtZero) {
  const BridgeConfig config = testing::TestConfig();
  sensors::CandumpLogSource source(testing::ExampleLogPath());
  std::atomic<bool> stop{false};
  ReplayOptions options;
  options.stop = &stop;
  options.on_scan = [&](const ScanOutcome& o, BridgePipeline&) {
    if (o.max_command > 1.0) stop = true;
  };
  const ReplayResult r = testing::ReplayWithConfigProfiles(config, source, options);
  EXPECT_TRUE(r.stopped_early);
  EXPECT_LT(r.rows.size(), 300u);  // not the whole log
}


TEST(Replay, BusOffAndErrorPassiveRaiseFaultStateOnBridgeStatus) {
  // A hostile input: 4800 bus-off error frames left fault_state at 0.
  const BridgeConfig config = testing::TestConfig();
  sensors::CandumpLogSource source(testing::ExampleLogPath());
  ReplayOptions options;
  int checked = 0;
  options.on_scan = [&](const ScanOutcome&, BridgePipeline& p) {
    if (checked++ != 10) return;
    sensors::BadFrameCounters c;
    EXPECT_EQ(p.MakeStatus(0).fault_state, 0);
    c.bus_state = sensors::kBusErrorPassive;
    p.SetSensorCounters(c, {});
    EXPECT_EQ(p.MakeStatus(0).fault_state, 1);
    EXPECT_EQ(p.MakeStatus(0).fault_message, "CAN error-passive");
    c.bus_state = sensors::kBusOff;
    p.SetSensorCounters(c, {});
    EXPECT_EQ(p.MakeStatus(0).fault_state, 2);
    EXPECT_EQ(p.MakeStatus(0).fault_message, "CAN bus-off");
  };
  testing::ReplayWithConfigProfiles(config, source, options);
  EXPECT_GT(checked, 10);
}

}  // namespace
}  // namespace sedbridge::bridge
