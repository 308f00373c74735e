#include "fem/thread_team.h"

#include <algorithm>
#include <atomic>
#include <cstdlib>

#include <omp.h>

namespace sedbridge::fem {
namespace {

std::atomic<bool>& AutoFlag() {
  static std::atomic<bool> flag{std::getenv("OMP_NUM_THREADS") == nullptr};
  return flag;
}

double Median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(v.size() / 2), v.end());
  return v[v.size() / 2];
}

// A larger team is kept only when clearly faster: a tie goes to the smaller, which leaves
// the other cores to the rest of the machine [-].
constexpr double kMinSpeedup = 1.05;
// A rung whose step costs this much more than the best so far has lost after one step: with
// more threads than idle cores a step can cost 100x (186 ms for 1.4 ms, measured), and
// three such steps would be the worst of the run [-].
constexpr double kAbandonRatio = 2.0;
// Longest re-measure period, in units of the initial one.
constexpr int kMaxPeriodFactor = 64;

}  // namespace

void SetAutoThreadTeam(bool on) { AutoFlag() = on; }
bool AutoThreadTeam() { return AutoFlag(); }

ThreadTeamChooser::ThreadTeamChooser(int max_threads, int samples, int reexplore_steps, double slowdown)
    : max_threads_(std::max(1, max_threads)),
      samples_(std::max(1, samples)),
      reexplore_steps_(std::max(1, reexplore_steps)),
      period_(reexplore_steps_),
      slowdown_(slowdown) {
  for (int team = 1; team < max_threads_; team *= 2) ladder_.push_back(team);
  ladder_.push_back(max_threads_);
  if (max_threads_ == 1) chosen_ = 1;
}

int ThreadTeamChooser::Next() const {
  if (chosen_ > 0) return chosen_;
  if (!warm_) return ladder_[1];  // the warm-up's first factorizations on a small team
  // Alternate the two rungs while measuring, so a change of load hits both alike.
  return best_costs_.size() <= trial_costs_.size() ? ladder_[best_] : ladder_[trial_];
}

void ThreadTeamChooser::Record(int team, double cost) {
  if (max_threads_ == 1) return;
  if (!warm_) {
    warm_ = true;
    return;
  }
  if (chosen_ == 0) {
    if (team == ladder_[best_])
      best_costs_.push_back(cost);
    else if (team == ladder_[trial_])
      trial_costs_.push_back(cost);
    else
      return;
    const bool far_slower = team == ladder_[trial_] && !best_costs_.empty() && cost > kAbandonRatio * Median(best_costs_);
    if (far_slower || (int(best_costs_.size()) >= samples_ && int(trial_costs_.size()) >= samples_))
      Compare(far_slower);
    return;
  }
  if (team != chosen_) return;
  recent_.push_back(cost);
  if (int(recent_.size()) > samples_) recent_.erase(recent_.begin());
  ++steps_since_choice_;
  const bool slowed = int(recent_.size()) == samples_ && Median(recent_) > slowdown_ * chosen_cost_;
  if (steps_since_choice_ >= period_ || slowed) {
    // Slowed down: the load rose, so only smaller teams are worth a try; after the period,
    // the machine may have gone quiet, so try the next larger team first.
    best_ = int(std::find(ladder_.begin(), ladder_.end(), chosen_) - ladder_.begin());
    climbing_ = !slowed && best_ + 1 < int(ladder_.size());
    may_descend_ = climbing_ && best_ > 0;
    if (!climbing_ && best_ == 0) {  // one thread slowed down: nothing smaller, take the new level
      chosen_cost_ = Median(recent_);
      steps_since_choice_ = 0;
      recent_.clear();
      return;
    }
    trial_ = climbing_ ? best_ + 1 : best_ - 1;
    Restart();
  }
}

void ThreadTeamChooser::Compare(bool trial_lost) {
  const double best = Median(best_costs_), trial = Median(trial_costs_);
  // The larger team must be clearly faster; a tie goes to the smaller.
  const bool trial_wins = !trial_lost && (climbing_ ? trial * kMinSpeedup < best : !(best * kMinSpeedup < trial));
  if (trial_wins) {
    best_ = trial_;
    best_costs_.swap(trial_costs_);
    trial_costs_.clear();
    may_descend_ = false;
    const int next = climbing_ ? trial_ + 1 : trial_ - 1;
    if (next < 0 || next >= int(ladder_.size())) return Keep(best_);
    trial_ = next;
    return;
  }
  if (climbing_ && may_descend_) {  // nothing gained above: does the rung below do as well?
    climbing_ = may_descend_ = false;
    trial_ = best_ - 1;
    trial_costs_.clear();
    return;
  }
  Keep(best_);
}

void ThreadTeamChooser::Keep(int rung) {
  const int choice = ladder_[rung];
  period_ = choice == last_choice_ ? std::min(period_ * 2, kMaxPeriodFactor * reexplore_steps_) : reexplore_steps_;
  chosen_ = last_choice_ = choice;
  chosen_cost_ = best_costs_.empty() ? chosen_cost_ : Median(best_costs_);
  steps_since_choice_ = 0;
  recent_.clear();
}

ChosenTeamScope::ChosenTeamScope(ThreadTeamChooser& chooser)
    : chooser_(chooser),
      choosing_(AutoThreadTeam() && chooser.max_threads() > 1),
      caller_threads_(omp_get_max_threads()),
      team_(choosing_ ? chooser.Next() : caller_threads_) {
  if (!choosing_) return;
  omp_set_num_threads(team_);
  t0_ = std::chrono::steady_clock::now();
}

ChosenTeamScope::~ChosenTeamScope() {
  if (choosing_) omp_set_num_threads(caller_threads_);
}

void ChosenTeamScope::Record(double work_units) {
  if (!choosing_ || recorded_) return;
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0_).count();
  chooser_.Record(team_, ms / std::max(1.0, work_units));
  recorded_ = true;
}

void ThreadTeamChooser::Restart() {
  best_costs_.clear();
  trial_costs_.clear();
  recent_.clear();
  chosen_ = 0;
}

}  // namespace sedbridge::fem
