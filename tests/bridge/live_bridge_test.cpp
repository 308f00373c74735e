// Live mode without AF_CAN: the receiver/solver threading, driven by injected frame sources
// (the newest-scan slot itself: latest_scan_slot_test.cpp).

#include "bridge/live_bridge.h"

#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include "bridge/make_fe_step.h"
#include "bridge_test_util.h"
#include "common/wall_clock.h"
#include "sensors/scan_assembler.h"
#include "sensors/simulated/simulated_sensor.h"

namespace sedbridge::bridge {
namespace {

// A simulated sensor that never ends (its scan loops), frames stamped with the wall clock.
class EndlessSimulatedSource final : public sensors::FrameSource {
 public:
  explicit EndlessSimulatedSource(sensors::SimulatedSensorConfig c) : config_(std::move(c)), sim_(config_) {}
  std::optional<sensors::Frame> Next(int64_t) override {
    if (closed_) return std::nullopt;
    if (next_ >= frames_.size()) {
      frames_.clear();
      next_ = 0;
      sim_.ScanFrames(scan_++ % sim_.scan_count(), &frames_);
    }
    sensors::Frame f = frames_[next_++];
    f.utime = WallClockUtime();
    ++stats_.frames;
    return f;
  }
  bool Done() const override { return closed_; }
  void Close() override { closed_ = true; }
  sensors::FrameSourceStats Stats() const override { return stats_; }
  std::string Describe() const override { return "endless simulated sensor"; }

 private:
  sensors::SimulatedSensorConfig config_;
  sensors::SimulatedSensor sim_;
  std::vector<sensors::Frame> frames_;
  size_t next_ = 0;
  int64_t scan_ = 0;
  std::atomic<bool> closed_{false};
  sensors::FrameSourceStats stats_;
};

TEST(LiveBridge, FastSensorSlowSolverDropsOldScansAndStopsCleanly) {
  const BridgeConfig config = testing::TestConfig();
  sensors::SimulatedSensorConfig sim = sensors::LoadSimulatedSensorScene(
      std::string(SEDBRIDGE_SOURCE_DIR) + "/config/bridge/example_press_scene.yaml", config.sensor_profile);
  const sensors::SensorProfile profile = sim.profile;
  EndlessSimulatedSource source(sim);  // frames as fast as the receiver reads: far above the solver
  lcm_io::LcmSettings lcm;
  lcm.url = "memq://";
  BridgePipeline pipeline(config, profile, testing::ConfigDisplay(config), MakeFeStep(config, profile), lcm);
  sensors::ScanAssembler assembler(profile);
  LiveBridge bridge(source, assembler, pipeline);

  std::atomic<bool> stop{false};
  std::thread stopper([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(800));
    stop = true;
  });
  const LiveResult r = bridge.Run(stop);
  stopper.join();
  EXPECT_TRUE(r.stopped_by_request);
  EXPECT_GT(r.scans_processed, 5);
  EXPECT_GT(r.scans_dropped, 0);
  // Every scan the receiver produced was either processed or dropped (one may sit in the slot).
  EXPECT_LE(r.scans_processed + r.scans_dropped, r.scans_received);
  EXPECT_GE(r.scans_processed + r.scans_dropped + 1, r.scans_received);
  // A partial scan (the assembler splits scans arriving this fast) may be rejected.
  EXPECT_EQ(pipeline.counters().steps + pipeline.counters().scans_rejected, r.scans_processed);
  // Display driven to zero on exit.
  const display::DisplayCommand& last = pipeline.last_command();
  EXPECT_TRUE(last.shutdown);
  for (double v : last.value) EXPECT_EQ(v, 0.0);
  EXPECT_EQ(pipeline.MakeStatus(0).scans_dropped, r.scans_dropped + pipeline.counters().scans_rejected);
}

// A source whose receiver throws: the solver stops, the display goes to zero, the error surfaces.
class ThrowingSource final : public sensors::FrameSource {
 public:
  std::optional<sensors::Frame> Next(int64_t) override {
    std::this_thread::sleep_for(std::chrono::milliseconds(30));
    throw std::runtime_error("bus gone");
  }
  bool Done() const override { return false; }
  sensors::FrameSourceStats Stats() const override { return {}; }
  std::string Describe() const override { return "throwing"; }
};

TEST(LiveBridge, ReceiverFaultDrivesDisplayToZeroAndRethrows) {
  const BridgeConfig config = testing::TestConfig();
  const sensors::SensorProfile profile = sensors::LoadNamedSensorProfile(config.sensor_profile);
  lcm_io::LcmSettings lcm;
  lcm.url = "memq://";
  BridgePipeline pipeline(config, profile, testing::ConfigDisplay(config), MakeFeStep(config, profile), lcm);
  sensors::ScanAssembler assembler(profile);
  ThrowingSource source;
  LiveBridge bridge(source, assembler, pipeline);
  std::atomic<bool> stop{false};
  EXPECT_THROW(bridge.Run(stop), std::runtime_error);
  EXPECT_TRUE(pipeline.last_command().shutdown);
}

}  // namespace
}  // namespace sedbridge::bridge
