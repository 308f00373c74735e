#pragma once
// Team size of the FE step, chosen by measurement.
//
// A second OpenMP thread speeds up the element assembly on an idle core (1.8x on model B),
// but on a busy machine every barrier waits for a thread the scheduler has parked: measured
// here, a backward Euler contact step on B took 15 ms with one thread and 42 ms with two
// while one compile ran beside it (docs/performance.md). Which is faster depends on the
// load, which changes, so the step measures it: it alternates team sizes for a few steps,
// keeps the faster, and measures again every so often or when the kept one slows down.

#include <vector>

namespace sedbridge::fem {

/// Whether Simulation::Step chooses its team size itself. Default: yes, unless the user set
/// OMP_NUM_THREADS. Off: the team is omp_get_max_threads() as set by the caller (the bridge's
/// SetFeThreads, benchmarks with a fixed thread column).
void SetAutoThreadTeam(bool on);
bool AutoThreadTeam();

class ThreadTeamChooser {
 public:
  /// @param max_threads      the team compared with one thread (<= 1: always one)
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

 private:
  int max_threads_, samples_, reexplore_steps_, period_;
  double slowdown_;
  bool warm_ = false;
  std::vector<double> one_, many_;  // costs measured since the last (re)start
  int chosen_ = 0, last_choice_ = 0;
  double chosen_cost_ = 0;
  int steps_since_choice_ = 0;
  std::vector<double> recent_;  // the kept team's last `samples_` costs
  void Restart();
};

}  // namespace sedbridge::fem
