#pragma once
// Team size of the FE step, chosen by measurement.
//
// A second OpenMP thread speeds up the element assembly on an idle core (1.8x on model B),
// but on a busy machine every barrier waits for a thread the scheduler has parked: measured
// here, a backward Euler contact step on B took 15 ms with one thread and 42 ms with two
// while one compile ran beside it (docs/performance.md). On a quiet 16-core machine the
// step is fastest with 4-8 threads and slower again with all 16, and with half the cores
// busy 16 threads made a 1.4 ms step take 186 ms. Which team is fastest depends on the
// machine and its load, which changes, so the step measures it: it climbs a ladder of team
// sizes (1, 2, 4, ... up to the cores) one rung at a time, comparing each rung with the
// best so far for a few steps, and stops at the first rung that is not clearly faster, so
// a team is never tried unless the one below it paid; a rung whose first step costs twice
// the best's has lost at once. It measures again, around the kept team, every so often or
// when the kept one slows down. ChosenTeamScope runs a step on the team it picks.

#include <chrono>
#include <vector>

namespace sedbridge::fem {

/// Whether Simulation::Step chooses its team size itself. Default: yes, unless the user set
/// OMP_NUM_THREADS. Off: the team is omp_get_max_threads() as set by the caller (the bridge's
/// SetFeThreads, benchmarks with a fixed thread column).
void SetAutoThreadTeam(bool on);
bool AutoThreadTeam();

class ThreadTeamChooser {
 public:
  /// @param max_threads      the largest team tried (the ladder is 1, 2, 4, ... and
  ///                         max_threads itself; <= 1: always one)
  /// @param samples          steps measured per team size before choosing
  /// @param reexplore_steps  steps after which the choice is measured again; doubled (up to
  ///                         64x) each time the measurement confirms the same team, since
  ///                         every measurement runs a few steps with the slower one
  /// @param slowdown         the kept team's recent median cost over its chosen median that
  ///                         triggers a new measurement (load changed) [-]
  explicit ThreadTeamChooser(int max_threads, int samples = 3, int reexplore_steps = 64, double slowdown = 1.5);

  int max_threads() const { return max_threads_; }
  /// Team size for the next step.
  int Next() const;
  /// Cost of the step just run with `team` threads, per unit of work (e.g. ms per Newton
  /// iteration). The first call is a warm-up (first factorizations, first touch) and is
  /// not compared.
  void Record(int team, double cost);
  /// The team kept, or 0 while measuring.
  int chosen() const { return chosen_; }
  /// Team sizes that may be tried, smallest first.
  const std::vector<int>& ladder() const { return ladder_; }

 private:
  int max_threads_, samples_, reexplore_steps_, period_;
  double slowdown_;
  std::vector<int> ladder_;
  bool warm_ = false;
  // While measuring: the best rung so far against the rung being tried, above it (climbing)
  // or below it (descending after a re-measure found no gain above).
  int best_ = 0, trial_ = 1;
  bool climbing_ = true, may_descend_ = false;
  std::vector<double> best_costs_, trial_costs_;
  int chosen_ = 0, last_choice_ = 0;
  double chosen_cost_ = 0;
  int steps_since_choice_ = 0;
  std::vector<double> recent_;  // the kept team's last `samples_` costs
  void Compare(bool trial_lost = false);
  void Keep(int rung);
  void Restart();
};

/// Runs a scope (one FE step and the work that belongs to it) on the team `chooser` picks
/// when AutoThreadTeam(), else on the caller's team, and restores the caller's team at
/// exit. Record() gives the chooser the scope's cost so far.
class ChosenTeamScope {
 public:
  explicit ChosenTeamScope(ThreadTeamChooser& chooser);
  ~ChosenTeamScope();
  ChosenTeamScope(const ChosenTeamScope&) = delete;
  ChosenTeamScope& operator=(const ChosenTeamScope&) = delete;

  /// Whether the team was chosen (AutoThreadTeam() and more than one core).
  bool choosing() const { return choosing_; }
  /// The team the scope runs on (the chosen one, else the caller's).
  int team() const { return team_; }
  /// Records the wall time since construction per `work_units` (e.g. Newton iterations);
  /// once per scope, and only when choosing().
  void Record(double work_units = 1.0);

 private:
  ThreadTeamChooser& chooser_;
  bool choosing_, recorded_ = false;
  int caller_threads_, team_;
  std::chrono::steady_clock::time_point t0_;
};

}  // namespace sedbridge::fem
