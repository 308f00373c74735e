#include "common/stage_times.h"

#include <gtest/gtest.h>

#include <set>
#include <string>
#include <thread>

namespace sedbridge {
namespace {

TEST(StageTimes, EveryStageHasItsOwnName) {
  std::set<std::string> names;
  for (int i = 0; i < kNumStages; ++i) names.insert(ToString(static_cast<Stage>(i)));
  EXPECT_EQ(names.size(), size_t(kNumStages));
  EXPECT_EQ(names.count("?"), 0u);
  EXPECT_STREQ(ToString(Stage::kBoundaryCondition), "boundary_condition");
  // The table is in enum order: CSV columns and BRIDGE_STATUS fields follow it.
  ASSERT_EQ(NamesOf(Stage{}).size(), size_t(kNumStages));
  for (int i = 0; i < kNumStages; ++i) EXPECT_EQ(NamesOf(Stage{})[size_t(i)].first, static_cast<Stage>(i));
}

TEST(StageTimes, TimerAddsItsWallTimeToOneStageOnce) {
  StageTimes times;
  {
    StageTimer timer(times, Stage::kSolve);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
    timer.Stop();
    const double after_stop = times[Stage::kSolve];
    EXPECT_GE(after_stop, 2.0);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }  // the destructor adds nothing after Stop()
  EXPECT_LT(times[Stage::kSolve], 4.0 + 50.0);  // generous: a loaded machine
  for (int i = 0; i < kNumStages; ++i)
    if (static_cast<Stage>(i) != Stage::kSolve) EXPECT_EQ(times.ms[size_t(i)], 0.0);
}

TEST(StageTimes, AddSumsStageByStage) {
  StageTimes a, b;
  a[Stage::kAssembly] = 1.0;
  b[Stage::kAssembly] = 2.0;
  b[Stage::kSed] = 0.5;
  a.Add(b);
  EXPECT_EQ(a[Stage::kAssembly], 3.0);
  EXPECT_EQ(a[Stage::kSed], 0.5);
  EXPECT_EQ(a.total_ms(), 3.5);
}

}  // namespace
}  // namespace sedbridge
