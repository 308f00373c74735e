// ThreadTeamChooser (fem/thread_team.h): fed step costs, not clocks, so the choice is
// deterministic: it keeps the faster team, prefers one thread on a tie, climbs the ladder of
// team sizes only while each rung pays, and measures again when the kept team slows down or
// after its re-measure period.

#include "fem/thread_team.h"

#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <functional>
#include <map>

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

// Step costs of the contact step on B_fine on a quiet 16-core machine, per team (ms;
// docs/performance.md "Thread scaling on a 16-core machine"): fastest at 4-8, slower at 16.
double QuietSixteenCores(int team, int) {
  static const std::map<int, double> ms{{1, 8.05}, {2, 5.09}, {4, 4.15}, {8, 4.25}, {16, 6.85}};
  return ms.at(team);
}

TEST(ThreadTeamChooser, LadderDoublesUpToTheCores) {
  EXPECT_EQ(ThreadTeamChooser(16).ladder(), (std::vector<int>{1, 2, 4, 8, 16}));
  EXPECT_EQ(ThreadTeamChooser(6).ladder(), (std::vector<int>{1, 2, 4, 6}));
  EXPECT_EQ(ThreadTeamChooser(2).ladder(), (std::vector<int>{1, 2}));
}

TEST(ThreadTeamChooser, ClimbsToTheFastestTeamAndNoFurther) {
  ThreadTeamChooser chooser(16, 3, 1000);
  int largest = 0;
  RunSteps(chooser, 40, [&](int team, int k) {
    largest = std::max(largest, team);
    return QuietSixteenCores(team, k);
  });
  // 1 -> 2 (1.58x) -> 4 (1.23x) pay; 8 is not 5 % faster than 4, so 16 is never tried.
  EXPECT_EQ(chooser.chosen(), 4);
  EXPECT_EQ(largest, 8);
}

TEST(ThreadTeamChooser, NeverTriesALargeTeamOnABusyMachine) {
  // Half the cores busy: every extra thread makes the step slower (16 threads: 186 ms for
  // a 1.4 ms step, measured). Only 2 is ever tried against 1.
  ThreadTeamChooser chooser(16, 3, 1000);
  int largest = 0;
  RunSteps(chooser, 40, [&](int team, int) {
    largest = std::max(largest, team);
    return team == 1 ? 2.8 : 2.8 * team;
  });
  EXPECT_EQ(chooser.chosen(), 1);
  EXPECT_EQ(largest, 2);
}

TEST(ThreadTeamChooser, AFarSlowerRungLosesAfterOneStep) {
  // Half the cores busy, as measured: 8 threads still 9 % faster than 4, 16 threads 130x
  // slower. 16 is tried once, not three times.
  const std::map<int, double> loaded{{1, 2.70}, {2, 1.67}, {4, 1.17}, {8, 1.07}, {16, 186.0}};
  ThreadTeamChooser chooser(16, 3, 1000);
  std::vector<int> teams;
  RunSteps(chooser, 40, [&](int team, int) {
    teams.push_back(team);
    return loaded.at(team);
  });
  EXPECT_EQ(chooser.chosen(), 8);
  EXPECT_EQ(std::count(teams.begin(), teams.end(), 16), 1);
}

TEST(ThreadTeamChooser, MeasuresAgainAroundTheKeptTeam) {
  ThreadTeamChooser chooser(16, 3, 20);
  RunSteps(chooser, 25, QuietSixteenCores);  // warm-up + 4 comparisons of 3 + 3 steps, then 12 kept
  ASSERT_EQ(chooser.chosen(), 4);
  // Some cores got busy: 4 threads are now no faster than 2, 8 slower, 1 still slower.
  // After the period the chooser tries 8, then 2, keeps going down while the smaller team
  // does as well (the tie goes to fewer threads), stops at 2 against 1; 16 is never run.
  const std::map<int, double> busy{{1, 8.0}, {2, 5.0}, {4, 5.0}, {8, 9.0}};
  std::vector<int> teams;
  RunSteps(chooser, 30, [&](int team, int) {  // 8 more steps kept, 6 + 6 + 3 measuring, 7 kept
    teams.push_back(team);
    return busy.at(team);
  });
  EXPECT_EQ(chooser.chosen(), 2);
  EXPECT_GT(std::count(teams.begin(), teams.end(), 8), 0);
  EXPECT_EQ(std::count(teams.begin(), teams.end(), 16), 0);
}

TEST(ThreadTeamChooser, ASlowdownOnlyTriesSmallerTeams) {
  ThreadTeamChooser chooser(16, 3, 1000);
  RunSteps(chooser, 40, QuietSixteenCores);
  ASSERT_EQ(chooser.chosen(), 4);
  // Load arrives: every team is slower, more threads more so.
  std::vector<int> teams;
  RunSteps(chooser, 30, [&](int team, int) {
    teams.push_back(team);
    return 6.0 * team;
  });
  EXPECT_EQ(chooser.chosen(), 1);
  EXPECT_EQ(*std::max_element(teams.begin(), teams.end()), 4);
}

TEST(ChosenTeamScope, RunsOnTheChosenTeamAndRestoresTheCallers) {
  const bool auto_before = AutoThreadTeam();
  const int threads_before = omp_get_max_threads();
  SetAutoThreadTeam(true);
  omp_set_num_threads(3);
  ThreadTeamChooser chooser(4, 1, 1000);  // ladder 1, 2, 4; one sample per rung
  {
    ChosenTeamScope scope(chooser);
    EXPECT_TRUE(scope.choosing());
    EXPECT_EQ(omp_get_max_threads(), 2);  // the warm-up step
    scope.Record();
  }
  EXPECT_EQ(omp_get_max_threads(), 3);
  for (int expected : {1, 2, 4}) {  // 1 against 2; 2 won (cost 1/team), so 4 against 2's cost
    ChosenTeamScope scope(chooser);
    EXPECT_EQ(omp_get_max_threads(), expected);
    chooser.Record(expected, 10.0 / expected);  // a fed cost, not the clock
  }
  EXPECT_EQ(chooser.chosen(), 4);
  SetAutoThreadTeam(false);  // the user chose: the scope keeps the caller's team
  {
    ChosenTeamScope scope(chooser);
    EXPECT_FALSE(scope.choosing());
    EXPECT_EQ(omp_get_max_threads(), 3);
  }
  SetAutoThreadTeam(auto_before);
  omp_set_num_threads(threads_before);
}

TEST(ThreadTeamChooser, OneCoreAlwaysOneThread) {
  ThreadTeamChooser chooser(1);
  EXPECT_EQ(chooser.Next(), 1);
  RunSteps(chooser, 5, [](int, int) { return 1.0; });
  EXPECT_EQ(chooser.chosen(), 1);
}

}  // namespace
}  // namespace sedbridge::fem
