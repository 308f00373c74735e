#include "fem/thread_team.h"

#include <algorithm>
#include <atomic>
#include <cstdlib>

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

// More threads are kept only when clearly faster: a tie goes to one thread, which leaves
// the other core to the rest of the machine [-].
constexpr double kMinSpeedup = 1.05;
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
  if (max_threads_ == 1) chosen_ = 1;
}

int ThreadTeamChooser::Next() const {
  if (chosen_ > 0) return chosen_;
  if (!warm_) return max_threads_;
  return one_.size() <= many_.size() ? 1 : max_threads_;  // alternate while measuring
}

void ThreadTeamChooser::Record(int team, double cost) {
  if (max_threads_ == 1) return;
  if (!warm_) {
    warm_ = true;
    return;
  }
  if (chosen_ == 0) {
    (team == 1 ? one_ : many_).push_back(cost);
    if (int(one_.size()) >= samples_ && int(many_.size()) >= samples_) {
      const double one = Median(one_), many = Median(many_);
      const int choice = many * kMinSpeedup < one ? max_threads_ : 1;
      period_ = choice == last_choice_ ? std::min(period_ * 2, kMaxPeriodFactor * reexplore_steps_) : reexplore_steps_;
      chosen_ = last_choice_ = choice;
      chosen_cost_ = chosen_ == 1 ? one : many;
      steps_since_choice_ = 0;
      recent_.clear();
    }
    return;
  }
  if (team != chosen_) return;
  recent_.push_back(cost);
  if (int(recent_.size()) > samples_) recent_.erase(recent_.begin());
  ++steps_since_choice_;
  const bool slowed = int(recent_.size()) == samples_ && Median(recent_) > slowdown_ * chosen_cost_;
  if (steps_since_choice_ >= period_ || slowed) Restart();
}

void ThreadTeamChooser::Restart() {
  one_.clear();
  many_.clear();
  recent_.clear();
  chosen_ = 0;
}

}  // namespace sedbridge::fem
