#pragma once
// Live mode for a hand: one receiver thread reads the one frame source (several SocketCAN
// buses through sensors::MultiSocketCanSource, or a `candump -l any` log played at speed),
// routes each frame by interface and CAN id to its finger's assembler (sensors::FrameRouter,
// through the same pump as a replay: PumpRoutedFrames) and puts each finger's scans into
// that finger's newest-scan slot; each finger has a solver thread of its own running the
// one-finger solver loop (RunLiveSolver). A finger whose sensor goes silent or bus-off gets
// no scans: its thread ticks its display, whose watchdog ramps it to zero, while the other
// fingers' threads go on. On return — stop requested, source done, or an exception in any
// thread (which stops every thread) — every finger's display has been driven to zero.
//
// A thread a finger (not FingerWorkers' team): each finger waits on its own slot with its
// own tick period, so a slow finger never delays another's tick; the threads sleep between
// scans (a hand's 5 x 100 Hz leaves them mostly idle).

#include <atomic>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "bridge/bridge_pipeline.h"
#include "bridge/latest_scan_slot.h"
#include "bridge/live_bridge.h"
#include "sensors/frame_router.h"
#include "sensors/frame_source.h"
#include "sensors/scan_assembler.h"

namespace sedbridge::bridge {

/// One finger of a live hand (references must outlive LiveHandBridge::Run).
struct LiveFinger {
  std::string name;
  std::string interface;             ///< its bus (frames routed by this and its ids)
  const sensors::SensorProfile* profile = nullptr;  ///< its ids already moved
  BridgePipeline* pipeline = nullptr;
  int64_t tick_period_us = 5000;     ///< display tick when no scan within this [us]
  int tare_scans = 0;                ///< its assembler's automatic tare (config tare_scans)
};

struct LiveHandResult {
  std::vector<LiveResult> fingers;   ///< one per finger, in the order given
  std::map<std::string, int64_t> unclaimed_frames;  ///< per interface (FrameRouter)
  int64_t frames = 0;                ///< frames read from the source
  bool stopped_by_request = false;
};

class LiveHandBridge {
 public:
  /// Claims every finger's ids on its interface (throws std::invalid_argument naming both
  /// fingers when two claim one id on one bus). `options.tick_period_us` is ignored (each
  /// finger's own is used). `finger_stats`: the source counters a finger's BRIDGE_STATUS
  /// shows (e.g. its own bus's, MultiSocketCanSource::Stats(interface)); empty = source.Stats().
  LiveHandBridge(sensors::FrameSource& source, std::vector<LiveFinger> fingers, LiveOptions options = {},
                 std::function<sensors::FrameSourceStats(const std::string& interface)> finger_stats = {});

  /// Blocks until `stop` becomes true or the source is done; rethrows the first exception of
  /// any thread after every display was shut down.
  LiveHandResult Run(const std::atomic<bool>& stop);

  const sensors::ScanAssembler& assembler(size_t finger) const { return *assemblers_[finger]; }
  const LatestScanSlot& slot(size_t finger) const { return *slots_[finger]; }

 private:
  sensors::FrameSourceStats StatsOf(size_t finger) const;

  sensors::FrameSource& source_;
  std::vector<LiveFinger> fingers_;
  LiveOptions options_;
  std::function<sensors::FrameSourceStats(const std::string&)> finger_stats_;
  sensors::FrameRouter router_;
  std::vector<std::unique_ptr<sensors::ScanAssembler>> assemblers_;
  std::vector<std::unique_ptr<LatestScanSlot>> slots_;
};

}  // namespace sedbridge::bridge
