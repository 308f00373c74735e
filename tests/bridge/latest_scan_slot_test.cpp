// The newest-scan slot between the receiver and the solver thread: newest wins, drops are
// counted, Take() wakes on Put() and Close(), counters pass between the threads.

#include "bridge/latest_scan_slot.h"

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

namespace sedbridge::bridge {
namespace {

TEST(LatestScanSlot, NewestWinsAndDropsAreCounted) {
  LatestScanSlot slot;
  for (int i = 0; i < 5; ++i) {
    LatestScanSlot::Entry e;
    e.scan.sequence = i;
    slot.Put(std::move(e));
  }
  LatestScanSlot::Entry out;
  ASSERT_TRUE(slot.Take(&out, 0));
  EXPECT_EQ(out.scan.sequence, 4);
  EXPECT_FALSE(slot.Take(&out, 1000));  // empty: times out
  EXPECT_EQ(slot.put_count(), 5);
  EXPECT_EQ(slot.dropped_count(), 4);
  EXPECT_EQ(slot.taken_count(), 1);
  slot.Close();
  EXPECT_FALSE(slot.Take(&out, -1));  // closed and empty: returns at once
}

TEST(LatestScanSlot, TakeWakesOnPutFromAnotherThread) {
  LatestScanSlot slot;
  std::thread producer([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    LatestScanSlot::Entry e;
    e.scan.sequence = 7;
    slot.Put(std::move(e));
  });
  LatestScanSlot::Entry out;
  EXPECT_TRUE(slot.Take(&out, 5'000'000));
  EXPECT_EQ(out.scan.sequence, 7);
  producer.join();
}

TEST(LatestScanSlot, CloseWakesAWaitingTakeAndEndsPuts) {
  LatestScanSlot slot;
  std::thread closer([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    slot.Close();
  });
  LatestScanSlot::Entry out;
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_FALSE(slot.Take(&out, 5'000'000));  // woken by Close, not by the 5 s timeout
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(4));
  closer.join();
  EXPECT_TRUE(slot.closed());
}

TEST(LatestScanSlot, AScanPutBeforeCloseIsStillTaken) {
  LatestScanSlot slot;
  LatestScanSlot::Entry e;
  e.scan.sequence = 3;
  e.receive_wall_utime = 123456;
  slot.Put(std::move(e));
  slot.Close();
  LatestScanSlot::Entry out;
  ASSERT_TRUE(slot.Take(&out, 0));
  EXPECT_EQ(out.scan.sequence, 3);
  EXPECT_EQ(out.receive_wall_utime, 123456);
  EXPECT_FALSE(slot.Take(&out, 0));
  slot.Put({});  // after Close: ignored
  EXPECT_FALSE(slot.Take(&out, 0));
  EXPECT_EQ(slot.put_count(), 1);
  EXPECT_EQ(slot.dropped_count(), 0);
}

TEST(LatestScanSlot, CountersPassFromReceiverToSolver) {
  LatestScanSlot slot;
  sensors::BadFrameCounters counters;
  counters.frames = 40;
  counters.duplicates = 2;
  sensors::FrameSourceStats stats;
  stats.frames = 41;
  stats.kernel_drops = 5;
  slot.SetCounters(counters, stats);
  sensors::BadFrameCounters got_counters;
  sensors::FrameSourceStats got_stats;
  slot.GetCounters(&got_counters, &got_stats);
  EXPECT_EQ(got_counters.frames, 40);
  EXPECT_EQ(got_counters.duplicates, 2);
  EXPECT_EQ(got_stats.frames, 41);
  EXPECT_EQ(got_stats.kernel_drops, 5);
}

}  // namespace
}  // namespace sedbridge::bridge
