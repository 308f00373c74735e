#include "sensors/frame_pump.h"

#include <gtest/gtest.h>

#include <deque>
#include <optional>
#include <stdexcept>
#include <vector>

#include "sensors/taxel_codec.h"

namespace sedbridge::sensors {
namespace {

// Hands out a scripted list: a frame, or std::nullopt for a receive timeout. Done after the
// last entry; counts frames as a real source does.
class ScriptedSource final : public FrameSource {
 public:
  explicit ScriptedSource(std::deque<std::optional<Frame>> script) : script_(std::move(script)) {}
  std::optional<Frame> Next(int64_t) override {
    ++next_calls;
    if (script_.empty()) return std::nullopt;
    std::optional<Frame> f = script_.front();
    script_.pop_front();
    if (f) {
      ++stats_.frames;
      if (f->error) CountErrorFrame(*f, &stats_);
    }
    return f;
  }
  bool Done() const override { return script_.empty(); }
  FrameSourceStats Stats() const override { return stats_; }
  std::string Describe() const override { return "scripted"; }
  int next_calls = 0;

 private:
  std::deque<std::optional<Frame>> script_;
  FrameSourceStats stats_;
};

// cyskin_16: four frames a scan, partial timeout 6 ms.
class FramePumpTest : public ::testing::Test {
 protected:
  FramePumpTest()
      : profile_(LoadSensorProfile(ResolveProfilePath("cyskin_16"))), codec_(profile_), assembler_(profile_) {
    options_.wall_clock_utime = [this] { return wall_utime_ += 10; };
  }

  std::vector<Frame> ScanFrames(int32_t value, int64_t utime) {
    std::vector<int32_t> raw(16, value);
    auto frames = codec_.EncodeScan(raw, -1, utime);
    for (size_t k = 0; k < frames.size(); ++k) frames[k].utime = utime + 100 * static_cast<int64_t>(k);
    return frames;
  }

  static void Append(std::deque<std::optional<Frame>>* script, const std::vector<Frame>& frames) {
    for (const Frame& f : frames) script->push_back(f);
  }

  PumpResult Pump(ScriptedSource& source) {
    return PumpFrames(
        source, assembler_,
        [this](Scan& s, int64_t wall) {
          scans_.push_back(s);
          walls_.push_back(wall);
        },
        options_);
  }

  SensorProfile profile_;
  TaxelCodec codec_;
  ScanAssembler assembler_;
  PumpOptions options_;
  int64_t wall_utime_ = 0;
  std::vector<Scan> scans_;
  std::vector<int64_t> walls_;
};

TEST_F(FramePumpTest, ScansComeOutInOrderAndEveryFrameIsCountedOnce) {
  std::deque<std::optional<Frame>> script;
  for (int k = 0; k < 3; ++k) Append(&script, ScanFrames(1100 + 100 * k, 4000 * k));
  ScriptedSource source(script);
  const PumpResult r = Pump(source);
  EXPECT_EQ(r.frames, 12);
  EXPECT_EQ(r.scans, 3);
  EXPECT_FALSE(r.stopped);
  ASSERT_EQ(scans_.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(scans_[k].sequence, k);
    EXPECT_EQ(scans_[k].raw_counts[0], 1100 + 100 * k);
    EXPECT_TRUE(scans_[k].complete);
  }
  EXPECT_EQ(source.Stats().frames, 12);
  EXPECT_EQ(assembler_.counters().frames, 12);
  EXPECT_LT(walls_[0], walls_[1]);  // stamped when the finishing frame came in
}

TEST_F(FramePumpTest, BadFramesAreCountedOnceBySourceAndAssembler) {
  std::deque<std::optional<Frame>> script;
  Append(&script, ScanFrames(1500, 0));
  Frame foreign;
  foreign.id = 0x123;  // not in the profile
  foreign.len = 8;
  foreign.utime = 500;
  script.push_back(foreign);
  Frame error;
  error.error = true;
  error.id = 0x40;  // CAN_ERR_BUSOFF
  error.len = 8;
  error.utime = 600;
  script.push_back(error);
  ScriptedSource source(script);
  const PumpResult r = Pump(source);
  EXPECT_EQ(r.frames, 6);
  EXPECT_EQ(assembler_.counters().frames, 6);
  EXPECT_EQ(assembler_.counters().unknown_id, 1);
  EXPECT_EQ(assembler_.counters().error_frames, 1);
  EXPECT_EQ(source.Stats().frames, 6);
  EXPECT_EQ(source.Stats().error_frames, 1);
  EXPECT_EQ(source.Stats().bus_off, 1);
  EXPECT_EQ(r.scans, 1);
}

TEST_F(FramePumpTest, EndOfSourceFlushesTheScanInProgressAsPartial) {
  std::deque<std::optional<Frame>> script;
  auto frames = ScanFrames(1500, 0);
  frames.pop_back();  // the last slot never arrives
  Append(&script, frames);
  ScriptedSource source(script);
  int idles = 0;
  options_.on_idle = [&](int64_t) { ++idles; };
  const PumpResult r = Pump(source);
  ASSERT_EQ(r.scans, 1);
  EXPECT_FALSE(scans_[0].complete);
  EXPECT_EQ(assembler_.counters().scans_partial, 1);
  EXPECT_EQ(idles, 0);  // the end is not a timeout
  EXPECT_EQ(source.next_calls, 3);
}

TEST_F(FramePumpTest, TimeoutPollsOutAPartialScanAndCallsOnIdle) {
  std::deque<std::optional<Frame>> script;
  auto frames = ScanFrames(1500, 1000000);
  frames.pop_back();
  Append(&script, frames);
  script.push_back(std::nullopt);  // a receive timeout, 1 s of wall clock later
  Append(&script, ScanFrames(1600, 1100000));
  ScriptedSource source(script);
  wall_utime_ = 1000000;
  options_.wall_clock_utime = [this] { return wall_utime_ += 500000; };
  std::vector<int64_t> idle_walls;
  options_.on_idle = [&](int64_t wall) {
    idle_walls.push_back(wall);
    EXPECT_EQ(scans_.size(), 0u);  // on_idle runs after the poll, before the scan is handed out
  };
  const PumpResult r = Pump(source);
  ASSERT_EQ(idle_walls.size(), 1u);
  ASSERT_EQ(r.scans, 2);
  EXPECT_FALSE(scans_[0].complete);  // polled out on the timeout, not when the next began
  EXPECT_EQ(walls_[0], idle_walls[0]);
  EXPECT_TRUE(scans_[1].complete);
}

TEST_F(FramePumpTest, WithoutPollATimeoutLeavesTheScanOpen) {
  std::deque<std::optional<Frame>> script;
  auto frames = ScanFrames(1500, 0);
  frames.pop_back();
  Append(&script, frames);
  script.push_back(std::nullopt);
  Frame foreign;  // keeps the source going past the timeout; starts no scan
  foreign.id = 0x123;
  foreign.len = 8;
  foreign.utime = 2000000;
  script.push_back(foreign);
  ScriptedSource source(script);
  options_.poll_on_timeout = false;
  options_.wall_clock_utime = [this] { return wall_utime_ += 1000000; };
  size_t scans_at_idle = 99;
  options_.on_idle = [&](int64_t) { scans_at_idle = scans_.size(); };
  Pump(source);
  EXPECT_EQ(scans_at_idle, 0u);
  EXPECT_EQ(scans_.size(), 1u);  // flushed at the end instead
}

TEST_F(FramePumpTest, StopEndsAtOnceWithoutFlushing) {
  std::deque<std::optional<Frame>> script;
  Append(&script, ScanFrames(1500, 0));
  Append(&script, ScanFrames(1600, 4000));
  ScriptedSource source(script);
  int frames_seen = 0;
  options_.on_frame = [&](const Frame&) { ++frames_seen; };
  options_.stop = [&] { return frames_seen == 6; };
  const PumpResult r = Pump(source);
  EXPECT_TRUE(r.stopped);
  EXPECT_EQ(r.frames, 6);
  EXPECT_EQ(r.scans, 1);  // the second scan is still in progress, not flushed
  EXPECT_FALSE(source.Done());
}

TEST_F(FramePumpTest, NeedsAWallClock) {
  ScriptedSource source({});
  options_.wall_clock_utime = nullptr;
  EXPECT_THROW(Pump(source), std::invalid_argument);
}

}  // namespace
}  // namespace sedbridge::sensors
