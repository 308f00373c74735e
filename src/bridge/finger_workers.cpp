#include "bridge/finger_workers.h"

#include <algorithm>
#include <utility>

namespace sedbridge::bridge {

FingerWorkers::FingerWorkers(int fingers, int threads) : threads_(std::clamp(threads, 1, std::max(1, fingers))) {
  if (threads_ == 1) return;
  for (int i = 0; i < threads_; ++i) workers_.push_back(std::make_unique<Worker>());
  for (auto& w : workers_) w->thread = std::thread([this, worker = w.get()] { Run(*worker); });
}

FingerWorkers::~FingerWorkers() {
  try {
    Finish();
  } catch (...) {
  }
}

void FingerWorkers::Fail(std::exception_ptr e) {
  const std::lock_guard<std::mutex> lock(error_mutex_);
  if (!error_) error_ = e;
}

void FingerWorkers::Post(int finger, std::function<void()> task) {
  {
    const std::lock_guard<std::mutex> lock(error_mutex_);
    if (error_) return;
  }
  if (workers_.empty()) {
    try {
      task();
    } catch (...) {
      Fail(std::current_exception());
    }
    return;
  }
  Worker& w = *workers_[size_t(finger % threads_)];
  {
    const std::lock_guard<std::mutex> lock(w.mutex);
    w.tasks.push_back(std::move(task));
  }
  w.wake.notify_one();
}

void FingerWorkers::Run(Worker& w) {
  std::unique_lock<std::mutex> lock(w.mutex);
  while (true) {
    w.wake.wait(lock, [&] { return w.stop || !w.tasks.empty(); });
    if (w.tasks.empty()) return;  // stop, and nothing left
    std::function<void()> task = std::move(w.tasks.front());
    w.tasks.pop_front();
    lock.unlock();
    bool failed;
    {
      const std::lock_guard<std::mutex> e(error_mutex_);
      failed = bool(error_);
    }
    if (!failed) {
      try {
        task();
      } catch (...) {
        Fail(std::current_exception());
      }
    }
    lock.lock();
  }
}

void FingerWorkers::Finish() {
  if (!finished_) {
    finished_ = true;
    for (auto& w : workers_) {
      {
        const std::lock_guard<std::mutex> lock(w->mutex);
        w->stop = true;
      }
      w->wake.notify_one();
    }
    for (auto& w : workers_) w->thread.join();
  }
  const std::lock_guard<std::mutex> lock(error_mutex_);
  if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
}

}  // namespace sedbridge::bridge
