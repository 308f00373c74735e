#include "bridge/latest_scan_slot.h"

#include <chrono>

namespace sedbridge::bridge {

void LatestScanSlot::Put(Entry entry) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (closed_) return;
    if (full_) ++dropped_;
    entry_ = std::move(entry);
    full_ = true;
    ++put_;
  }
  cv_.notify_one();
}

bool LatestScanSlot::Take(Entry* out, int64_t timeout_us) {
  std::unique_lock<std::mutex> lock(mutex_);
  auto ready = [this] { return full_ || closed_; };
  if (timeout_us < 0)
    cv_.wait(lock, ready);
  else
    cv_.wait_for(lock, std::chrono::microseconds(timeout_us), ready);
  if (!full_) return false;
  std::swap(*out, entry_);  // keeps the vectors' capacity cycling between the two threads
  full_ = false;
  ++taken_;
  return true;
}

void LatestScanSlot::Close() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    closed_ = true;
  }
  cv_.notify_all();
}

void LatestScanSlot::SetCounters(const sensors::BadFrameCounters& counters, const sensors::FrameSourceStats& stats) {
  std::lock_guard<std::mutex> lock(mutex_);
  counters_ = counters;
  stats_ = stats;
}

void LatestScanSlot::GetCounters(sensors::BadFrameCounters* counters, sensors::FrameSourceStats* stats) const {
  std::lock_guard<std::mutex> lock(mutex_);
  *counters = counters_;
  *stats = stats_;
}

bool LatestScanSlot::closed() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return closed_;
}
int64_t LatestScanSlot::put_count() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return put_;
}
int64_t LatestScanSlot::taken_count() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return taken_;
}
int64_t LatestScanSlot::dropped_count() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return dropped_;
}

}  // namespace sedbridge::bridge
