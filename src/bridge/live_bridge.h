#pragma once
// Live mode: a receiver thread reads frames (SocketCAN, or any FrameSource), assembles
// scans and puts each complete or timed-out scan into a LatestScanSlot; the calling
// (solver) thread takes the newest scan, runs it through the pipeline and publishes, or
// ticks the display when none arrived within a tick period. Older scans are dropped and
// counted, never queued. On return — stop requested, source done, or an exception in
// either thread — the display has been driven to zero (pipeline.Shutdown).

#include <atomic>
#include <cstdint>
#include <functional>

#include "bridge/bridge_pipeline.h"
#include "bridge/latest_scan_slot.h"
#include "sensors/frame_source.h"
#include "sensors/scan_assembler.h"

namespace sedbridge::bridge {

struct LiveOptions {
  int64_t tick_period_us = 5000;      ///< display Tick when no scan within this [us]
  int64_t receive_timeout_us = 2000;  ///< receiver's wait per Next() [us]
  /// Latency origin: true = the scan's utime (kernel receive time on SocketCAN, wall
  /// clock); false = wall time when the assembler emitted the scan (for sources whose
  /// utimes are not wall-clock, e.g. logs without restamping).
  bool scan_utime_is_wall_clock = true;
};

struct LiveResult {
  int64_t scans_received = 0;  ///< scans the receiver produced
  int64_t scans_processed = 0; ///< scans the solver took
  int64_t scans_dropped = 0;   ///< replaced in the slot before the solver took them
  int64_t ticks = 0;
  bool stopped_by_request = false;
};

/// The solver side of live mode, one finger: until `stopped()` or the slot is closed and
/// empty after `receiver_done`, takes the newest scan from `slot` and processes it, or ticks
/// the display when none came within options.tick_period_us. Counts into `result`
/// (scans_processed, ticks). Used by LiveBridge and, a thread per finger, LiveHandBridge.
void RunLiveSolver(LatestScanSlot& slot, BridgePipeline& pipeline, const LiveOptions& options,
                   const std::function<bool()>& stopped, const std::atomic<bool>& receiver_done,
                   LiveResult* result);

class LiveBridge {
 public:
  /// All references must outlive Run().
  LiveBridge(sensors::FrameSource& source, sensors::ScanAssembler& assembler, BridgePipeline& pipeline,
             LiveOptions options = {});

  /// Blocks until `stop` becomes true or the source is done. Rethrows the first exception
  /// of either thread after the display was shut down.
  LiveResult Run(const std::atomic<bool>& stop);

  const LatestScanSlot& slot() const { return slot_; }

 private:
  void Receive(const std::atomic<bool>& stop);

  sensors::FrameSource& source_;
  sensors::ScanAssembler& assembler_;
  BridgePipeline& pipeline_;
  LiveOptions options_;
  LatestScanSlot slot_;
};

}  // namespace sedbridge::bridge
