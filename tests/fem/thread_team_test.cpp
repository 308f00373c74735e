// ThreadTeamChooser (fem/thread_team.h): fed step costs, not clocks, so the choice is
// deterministic: it keeps the faster team, prefers one thread on a tie, and measures again
// when the kept team slows down or after its re-measure period.

#include "fem/thread_team.h"

#include <gtest/gtest.h>

#include <functional>

namespace sedbridge::fem {
namespace {

// Runs `steps` steps where a step with `team` threads costs cost(team, step).
void RunSteps(ThreadTeamChooser& chooser, int steps, const std::function<double(int, int)>& cost, int first_step = 0) {
  for (int k = first_step; k < first_step + steps; ++k) {
    const int team = chooser.Next();
    chooser.Record(team, cost(team, k));
  }
}

TEST(ThreadTeamChooser, KeepsTwoThreadsWhenTheyAreFaster) {
  ThreadTeamChooser chooser(2, 3, 64);
  RunSteps(chooser, 7, [](int team, int) { return team == 2 ? 6.0 : 10.0; });  // warm-up + 3 + 3
  EXPECT_EQ(chooser.chosen(), 2);
  EXPECT_EQ(chooser.Next(), 2);
}

TEST(ThreadTeamChooser, KeepsOneThreadOnABusyMachine) {
  // Two threads 3x slower (barriers waiting for a parked thread), with one outlier each way.
  ThreadTeamChooser chooser(2, 3, 64);
  RunSteps(chooser, 7, [](int team, int k) { return team == 2 ? (k == 2 ? 1.0 : 42.0) : (k == 3 ? 90.0 : 15.0); });
  EXPECT_EQ(chooser.chosen(), 1);
}

TEST(ThreadTeamChooser, TieGoesToOneThread) {
  ThreadTeamChooser chooser(2, 3, 64);
  RunSteps(chooser, 7, [](int team, int) { return team == 2 ? 9.8 : 10.0; });  // < 5 % apart
  EXPECT_EQ(chooser.chosen(), 1);
}

TEST(ThreadTeamChooser, MeasuresAgainWhenTheKeptTeamSlowsDown) {
  ThreadTeamChooser chooser(2, 3, 1000);
  RunSteps(chooser, 7, [](int team, int) { return team == 2 ? 6.0 : 10.0; });
  ASSERT_EQ(chooser.chosen(), 2);
  // Another process starts: two threads now cost 40, one thread 12.
  const auto busy = [](int team, int) { return team == 2 ? 40.0 : 12.0; };
  RunSteps(chooser, 3, busy);
  EXPECT_EQ(chooser.chosen(), 0);  // measuring again
  RunSteps(chooser, 6, busy);
  EXPECT_EQ(chooser.chosen(), 1);
}

TEST(ThreadTeamChooser, MeasuresAgainAfterItsPeriod) {
  ThreadTeamChooser chooser(2, 3, 10);
  RunSteps(chooser, 7, [](int team, int) { return team == 2 ? 10.0 : 6.0; });
  ASSERT_EQ(chooser.chosen(), 1);
  RunSteps(chooser, 9, [](int team, int) { return team == 2 ? 10.0 : 6.0; });
  EXPECT_EQ(chooser.chosen(), 1);
  RunSteps(chooser, 1, [](int team, int) { return team == 2 ? 10.0 : 6.0; });
  EXPECT_EQ(chooser.chosen(), 0);
  // Confirmed: the next period is twice as long.
  RunSteps(chooser, 6, [](int team, int) { return team == 2 ? 10.0 : 6.0; });
  ASSERT_EQ(chooser.chosen(), 1);
  RunSteps(chooser, 19, [](int team, int) { return team == 2 ? 10.0 : 6.0; });
  EXPECT_EQ(chooser.chosen(), 1);
  RunSteps(chooser, 1, [](int team, int) { return team == 2 ? 10.0 : 6.0; });
  EXPECT_EQ(chooser.chosen(), 0);
  // The machine went quiet: two threads win now, and the period is back to 10.
  RunSteps(chooser, 6, [](int team, int) { return team == 2 ? 4.0 : 6.0; });
  EXPECT_EQ(chooser.chosen(), 2);
  RunSteps(chooser, 10, [](int team, int) { return team == 2 ? 4.0 : 6.0; });
  EXPECT_EQ(chooser.chosen(), 0);
}

TEST(ThreadTeamChooser, OneCoreAlwaysOneThread) {
  ThreadTeamChooser chooser(1);
  EXPECT_EQ(chooser.Next(), 1);
  RunSteps(chooser, 5, [](int, int) { return 1.0; });
  EXPECT_EQ(chooser.chosen(), 1);
}

}  // namespace
}  // namespace sedbridge::fem
