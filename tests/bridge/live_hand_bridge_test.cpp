// Live mode for a hand (bridge::LiveHandBridge) without AF_CAN: an injected source carries a
// simulated press on can0 and can1; one finger's bus goes silent or bus-off, and that
// finger's display ramps to zero (watchdog) while the other finger goes on; every way out
// (stop, receiver fault) zeroes both displays.

#include "bridge/live_hand_bridge.h"

#include <gtest/gtest.h>
#include <linux/can/error.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "bridge/make_fe_step.h"
#include "bridge_test_util.h"
#include "common/wall_clock.h"
#include "sensors/simulated/simulated_sensor.h"

namespace sedbridge::bridge {
namespace {

using Clock = std::chrono::steady_clock;

// The simulated sensor's scans in a loop, one every 2 ms of wall time, each frame on can0 and,
// until `can1_for` has passed, on can1 too; then (with `bus_off`) one bus-off error frame on can1.
class TwoBusSimulatedSource final : public sensors::FrameSource {
 public:
  TwoBusSimulatedSource(sensors::SimulatedSensorConfig c, std::chrono::milliseconds can1_for, bool bus_off)
      : config_(std::move(c)), sim_(config_), can1_until_(Clock::now() + can1_for), bus_off_(bus_off) {}
  std::optional<sensors::Frame> Next(int64_t) override {
    if (closed_) return std::nullopt;
    if (next_ >= frames_.size()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
      frames_.clear();
      next_ = 0;
      std::vector<sensors::Frame> one;
      sim_.ScanFrames(scan_++ % sim_.scan_count(), &one);
      const bool can1 = Clock::now() < can1_until_;
      for (sensors::Frame f : one) {
        f.SetInterface("can0");
        frames_.push_back(f);
        if (can1) {
          f.SetInterface("can1");
          frames_.push_back(f);
        }
      }
      if (!can1 && bus_off_) {
        sensors::Frame e;
        e.error = true;
        e.id = CAN_ERR_BUSOFF;
        e.len = 8;
        e.SetInterface("can1");
        frames_.push_back(e);
        bus_off_ = false;
      }
    }
    sensors::Frame f = frames_[next_++];
    f.utime = WallClockUtime();
    ++stats_.frames;
    return f;
  }
  bool Done() const override { return closed_; }
  void Close() override { closed_ = true; }
  sensors::FrameSourceStats Stats() const override { return stats_; }
  std::string Describe() const override { return "two-bus simulated sensor"; }

 private:
  sensors::SimulatedSensorConfig config_;
  sensors::SimulatedSensor sim_;
  Clock::time_point can1_until_;
  bool bus_off_;
  std::vector<sensors::Frame> frames_;
  size_t next_ = 0;
  int64_t scan_ = 0;
  std::atomic<bool> closed_{false};
  sensors::FrameSourceStats stats_;
};

struct TwoFingers {
  BridgeConfig config = testing::TestConfig();
  sensors::SimulatedSensorConfig sim = sensors::LoadSimulatedSensorScene(
      std::string(SEDBRIDGE_SOURCE_DIR) + "/config/bridge/example_press_scene.yaml", config.sensor_profile);
  std::unique_ptr<BridgePipeline> index, middle;
  TwoFingers() {
    lcm_io::LcmSettings lcm;
    lcm.url = "memq://";
    index = std::make_unique<BridgePipeline>(config, sim.profile, testing::ConfigDisplay(config),
                                             MakeFeStep(config, sim.profile), lcm);
    middle = std::make_unique<BridgePipeline>(config, sim.profile, testing::ConfigDisplay(config),
                                              MakeFeStep(config, sim.profile), lcm);
  }
  std::vector<LiveFinger> Fingers() {
    return {{"index", "can0", &sim.profile, index.get(), 5000, 0}, {"middle", "can1", &sim.profile, middle.get(), 5000, 0}};
  }
};

LiveHandResult RunFor(LiveHandBridge& bridge, std::chrono::milliseconds how_long) {
  std::atomic<bool> stop{false};
  std::thread stopper([&] {
    std::this_thread::sleep_for(how_long);
    stop = true;
  });
  LiveHandResult r = bridge.Run(stop);
  stopper.join();
  return r;
}

void ExpectZeroed(const BridgePipeline& p) {
  EXPECT_TRUE(p.last_command().shutdown);
  for (double v : p.last_command().value) EXPECT_EQ(v, 0.0);
}

TEST(LiveHandBridge, SilentSensorRampsItsOwnDisplayToZeroWhileTheOtherGoesOn) {
  TwoFingers hand;
  TwoBusSimulatedSource source(hand.sim, std::chrono::milliseconds(400), false);
  LiveHandBridge bridge(source, hand.Fingers());
  const LiveHandResult r = RunFor(bridge, std::chrono::milliseconds(1500));
  ASSERT_EQ(r.fingers.size(), 2u);
  EXPECT_TRUE(r.stopped_by_request);
  EXPECT_GT(r.fingers[0].scans_processed, 5);
  EXPECT_GT(r.fingers[1].scans_processed, 2);
  // The silent finger's watchdog expired: its ticks went out stale (ramped to zero); the
  // other finger's scans kept coming and none of its commands was stale.
  EXPECT_GT(r.fingers[1].ticks, 0);
  EXPECT_GT(hand.middle->display().controller().stats().commands_stale, 0);
  EXPECT_EQ(hand.index->display().controller().stats().commands_stale, 0);
  EXPECT_GT(r.fingers[0].scans_processed, r.fingers[1].scans_processed);
  ExpectZeroed(*hand.index);
  ExpectZeroed(*hand.middle);
}

TEST(LiveHandBridge, BusOffIsTheFaultOfTheFingersOnThatBusOnly) {
  TwoFingers hand;
  TwoBusSimulatedSource source(hand.sim, std::chrono::milliseconds(300), true);
  LiveHandBridge bridge(source, hand.Fingers());
  const LiveHandResult r = RunFor(bridge, std::chrono::milliseconds(1200));
  EXPECT_EQ(bridge.assembler(1).counters().bus_state, sensors::kBusOff);
  EXPECT_EQ(bridge.assembler(1).counters().bus_off_events, 1);
  EXPECT_NE(bridge.assembler(0).counters().bus_state, sensors::kBusOff);
  EXPECT_GT(hand.middle->display().controller().stats().commands_stale, 0);
  EXPECT_EQ(hand.index->display().controller().stats().commands_stale, 0);
  EXPECT_GT(r.fingers[0].scans_processed, 5);
  ExpectZeroed(*hand.index);
  ExpectZeroed(*hand.middle);
}

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

TEST(LiveHandBridge, ReceiverFaultZeroesEveryDisplayAndRethrows) {
  TwoFingers hand;
  ThrowingSource source;
  LiveHandBridge bridge(source, hand.Fingers());
  std::atomic<bool> stop{false};
  EXPECT_THROW(bridge.Run(stop), std::runtime_error);
  ExpectZeroed(*hand.index);
  ExpectZeroed(*hand.middle);
}

TEST(LiveHandBridge, OneIdOnOneBusClaimedByTwoFingersIsRefusedNamingBoth) {
  TwoFingers hand;
  ThrowingSource source;
  std::vector<LiveFinger> fingers = hand.Fingers();
  fingers[1].interface = "can0";
  try {
    LiveHandBridge bridge(source, fingers);
    FAIL() << "two fingers on one id accepted";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("index"), std::string::npos) << what;
    EXPECT_NE(what.find("middle"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace sedbridge::bridge
