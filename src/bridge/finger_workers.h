#pragma once
// Runs a hand's fingers on a few threads, deterministically: each finger belongs to one
// worker (finger i to worker i mod N), and a finger's tasks run in the order they were posted.
// A finger's outputs then depend on its own task sequence only, never on the threads'
// timing (the pump posts scans and ticks in the log's order). With one thread every task
// runs at once on the caller's thread. The fingers' stages share nothing mutable (a shared
// leader model and its precompute are const, bridge/leader_model_cache.h).

#include <condition_variable>
#include <deque>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace sedbridge::bridge {

class FingerWorkers {
 public:
  /// @param threads  workers (1 = the caller's thread; clamped to [1, fingers])
  FingerWorkers(int fingers, int threads);
  ~FingerWorkers();  ///< Finish() unless done; never throws
  FingerWorkers(const FingerWorkers&) = delete;
  FingerWorkers& operator=(const FingerWorkers&) = delete;

  /// Runs `task` for `finger` after the finger's earlier tasks. After a task threw, later
  /// tasks are dropped (Finish rethrows).
  void Post(int finger, std::function<void()> task);
  /// Waits for every posted task and stops the workers; rethrows the first task's exception.
  void Finish();
  int threads() const { return threads_; }

 private:
  struct Worker {
    std::mutex mutex;
    std::condition_variable wake;
    std::deque<std::function<void()>> tasks;
    bool stop = false;
    std::thread thread;
  };
  void Run(Worker& w);
  void Fail(std::exception_ptr e);

  int threads_;
  std::vector<std::unique_ptr<Worker>> workers_;
  std::mutex error_mutex_;
  std::exception_ptr error_;
  bool finished_ = false;
};

}  // namespace sedbridge::bridge
