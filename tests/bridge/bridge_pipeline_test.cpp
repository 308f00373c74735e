// One scan through the bridge pipeline, by hand (no frames, no replay loop): the fault path
// for bad scans, latency on the injected wall clock, shutdown to zero, the status counters.

#include "bridge/bridge_pipeline.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "bridge/make_fe_step.h"
#include "bridge_test_util.h"
#include "common/wall_clock.h"
#include "lcm/display_session.h"

namespace sedbridge::bridge {
namespace {

// LCM inside the process: the pipeline publishes, nothing leaves the machine.
lcm_io::LcmSettings InProcessLcm() {
  lcm_io::LcmSettings lcm;
  lcm.url = "memq://";
  return lcm;
}

TEST(BridgePipeline, NanScansAreCountedSkippedAndZeroTheDisplay) {
  const BridgeConfig config = testing::TestConfig();
  const sensors::SensorProfile profile = sensors::LoadNamedSensorProfile(config.sensor_profile);
  const lcm_io::LcmSettings lcm = InProcessLcm();
  BridgePipeline pipeline(config, profile, testing::ConfigDisplay(config), MakeFeStep(config, profile), lcm);
  int64_t t = 1'000'000;
  // A firm press brings the display up.
  for (int i = 0; i < 30; ++i, t += 10'000) {
    const ScanOutcome o = pipeline.ProcessScan(testing::UniformScan(profile, 8e3, t), t, WallClockUtime());
    ASSERT_TRUE(o.stepped) << o.problem;
  }
  float before = 0;
  for (double v : pipeline.last_command().value) before = std::max<float>(before, float(v));
  ASSERT_GT(before, 0.0f);
  // An all-NaN scan: not stepped (the FE would throw), counted, display to zero with fault.
  sensors::Scan bad = testing::UniformScan(profile, 8e3, t);
  for (double& p : bad.pressure_Pa) p = std::nan("");
  const ScanOutcome o = pipeline.ProcessScan(bad, t, WallClockUtime());
  EXPECT_FALSE(o.stepped);
  EXPECT_EQ(pipeline.counters().scans_rejected, 1);
  EXPECT_EQ(pipeline.counters().rejected_by_reason[RejectReason::kTooManyInvalidTaxels], 1);
  EXPECT_EQ(pipeline.counters().rejected_by_reason.total(), 1);
  ASSERT_TRUE(o.reject_reason.has_value());
  EXPECT_EQ(*o.reject_reason, RejectReason::kTooManyInvalidTaxels);
  EXPECT_EQ(pipeline.counters().nonfinite_values, 16);
  EXPECT_EQ(pipeline.fault_state(), FaultState::kFault);
  EXPECT_TRUE(pipeline.last_command().fault);
  for (double v : pipeline.last_command().value) EXPECT_EQ(v, 0.0);
  // The next good scan recovers.
  t += 10'000;
  EXPECT_TRUE(pipeline.ProcessScan(testing::UniformScan(profile, 8e3, t), t, WallClockUtime()).stepped);
  EXPECT_EQ(pipeline.fault_state(), FaultState::kOk);
  EXPECT_EQ(pipeline.counters().steps, 31);
}

TEST(BridgePipeline, LatencyIsMeasuredOnTheInjectedWallClockFromTheReceiveTime) {
  const BridgeConfig config = testing::TestConfig();
  const sensors::SensorProfile profile = sensors::LoadNamedSensorProfile(config.sensor_profile);
  const lcm_io::LcmSettings lcm = InProcessLcm();
  int64_t wall_us = 50'000;
  BridgePipeline pipeline(config, profile, testing::ConfigDisplay(config), MakeFeStep(config, profile), lcm, [&] { return wall_us; });
  const ScanOutcome o = pipeline.ProcessScan(testing::UniformScan(profile, 8e3, 1'000'000), 1'000'000, 46'500);
  ASSERT_TRUE(o.stepped) << o.problem;
  EXPECT_EQ(o.latency_us, 3'500);
  EXPECT_EQ(pipeline.latency().Run().count, 1);
  EXPECT_GT(o.total_force_N, 0);
  EXPECT_NEAR(o.applied_force_N, o.total_force_N, 1e-6 * o.total_force_N);
}

TEST(BridgePipeline, ShutdownZeroesTheDisplayOnceAndRefusesLaterScans) {
  const BridgeConfig config = testing::TestConfig();
  const sensors::SensorProfile profile = sensors::LoadNamedSensorProfile(config.sensor_profile);
  const lcm_io::LcmSettings lcm = InProcessLcm();
  BridgePipeline pipeline(config, profile, testing::ConfigDisplay(config), MakeFeStep(config, profile), lcm);
  int64_t t = 1'000'000;
  for (int i = 0; i < 10; ++i, t += 10'000)
    ASSERT_TRUE(pipeline.ProcessScan(testing::UniformScan(profile, 8e3, t), t, WallClockUtime()).stepped);
  pipeline.Shutdown(t);
  for (double v : pipeline.last_command().value) EXPECT_EQ(v, 0.0);
  const int64_t commands = pipeline.counters().commands;
  const int64_t status = pipeline.counters().status_messages;
  pipeline.Shutdown(t + 1000);  // idempotent: nothing more is published
  pipeline.Tick(t + 2000);
  EXPECT_EQ(pipeline.counters().commands, commands);
  EXPECT_EQ(pipeline.counters().status_messages, status);
  const ScanOutcome o = pipeline.ProcessScan(testing::UniformScan(profile, 8e3, t), t, WallClockUtime());
  EXPECT_FALSE(o.stepped);
  EXPECT_EQ(o.problem, "shut down");
  EXPECT_EQ(pipeline.counters().scans, 10);
  EXPECT_EQ(pipeline.MakeStatus(t).fault_state, 2);
}

TEST(BridgePipeline, StatusCountsScansDroppedUpstreamAndRejected) {
  const BridgeConfig config = testing::TestConfig();
  const sensors::SensorProfile profile = sensors::LoadNamedSensorProfile(config.sensor_profile);
  const lcm_io::LcmSettings lcm = InProcessLcm();
  BridgePipeline pipeline(config, profile, testing::ConfigDisplay(config), MakeFeStep(config, profile), lcm);
  sensors::BadFrameCounters counters;
  counters.scans_dropped = 2;
  pipeline.SetSensorCounters(counters, sensors::FrameSourceStats{});
  pipeline.SetScansDroppedUpstream(3);
  sensors::Scan bad = testing::UniformScan(profile, 8e3, 1'000'000);
  for (double& p : bad.pressure_Pa) p = std::nan("");  // nothing usable: rejected
  EXPECT_FALSE(pipeline.ProcessScan(bad, 1'000'000, WallClockUtime()).stepped);
  EXPECT_EQ(pipeline.counters().scans_rejected, 1);
  const lcmt_bridge_status status = pipeline.MakeStatus(1'000'000);
  EXPECT_EQ(status.scans_dropped, 2 + 3 + 1);
  // The rejected scan under its reason, every reason named in enum order.
  ASSERT_EQ(status.num_reject_reasons, kNumRejectReasons);
  for (int k = 0; k < kNumRejectReasons; ++k) {
    const auto reason = static_cast<RejectReason>(k);
    EXPECT_EQ(status.reject_reason[size_t(k)], ToString(reason));
    EXPECT_EQ(status.scans_rejected[size_t(k)], reason == RejectReason::kTooManyInvalidTaxels ? 1 : 0);
  }
}

}  // namespace
}  // namespace sedbridge::bridge
