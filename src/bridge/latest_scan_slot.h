#pragma once
// Hand-over between the receiver thread (frames -> scans) and the solver thread: a slot
// that holds only the newest complete scan. Put() replaces a scan the solver has not taken
// yet (that scan is dropped and counted): the solver always works on the freshest data and
// never builds a backlog. Thread-safe.

#include <condition_variable>
#include <cstdint>
#include <mutex>

#include "sensors/bad_frame_counters.h"
#include "sensors/frame_source.h"
#include "sensors/scan.h"

namespace sedbridge::bridge {

class LatestScanSlot {
 public:
  struct Entry {
    sensors::Scan scan;
    int64_t receive_wall_utime = 0;  ///< latency origin [us, wall clock]
  };

  /// Stores `entry`, replacing (dropping) an untaken one; wakes the solver.
  void Put(Entry entry);
  /// Waits up to `timeout_us` (< 0: forever) for a scan; false on timeout or when closed
  /// and empty.
  bool Take(Entry* out, int64_t timeout_us);
  /// No more Put()s; wakes a waiting Take().
  void Close();

  /// Sensor-side counters, published by the receiver, read by the solver.
  void SetCounters(const sensors::BadFrameCounters& counters, const sensors::FrameSourceStats& stats);
  void GetCounters(sensors::BadFrameCounters* counters, sensors::FrameSourceStats* stats) const;

  bool closed() const;
  int64_t put_count() const;
  int64_t taken_count() const;
  int64_t dropped_count() const;  ///< scans replaced before the solver took them

 private:
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  Entry entry_;
  bool full_ = false, closed_ = false;
  int64_t put_ = 0, taken_ = 0, dropped_ = 0;
  sensors::BadFrameCounters counters_;
  sensors::FrameSourceStats stats_;
};

}  // namespace sedbridge::bridge
