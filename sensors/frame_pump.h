#pragma once
// The one loop that moves frames from a FrameSource through a ScanAssembler and hands out
// the scans: used by `sedbridge decode`, the bridge replay and the live bridge's receiver,
// so frames are counted in one place (the source's Stats() and the assembler's counters).

#include <cstdint>
#include <functional>
#include <vector>

#include "sensors/can_frame.h"
#include "sensors/frame_router.h"
#include "sensors/frame_source.h"
#include "sensors/scan.h"
#include "sensors/scan_assembler.h"

namespace sedbridge::sensors {

/// How PumpFrames reads its source and what it calls besides `on_scan`.
struct PumpOptions {
  /// Longest wait for one frame [us], passed to FrameSource::Next (negative = until a frame
  /// arrives or the source ends).
  int64_t frame_wait_us = -1;
  /// Wall clock [us since the epoch]. Required: it stamps the scans with the time their last
  /// frame was received and, on a timeout, tells the assembler how late it is.
  std::function<int64_t()> wall_clock_utime;
  /// On a timeout, emit the scan in progress as partial once its partial timeout has passed
  /// (ScanAssembler::Poll). Live buses want this; a paced log replay does not.
  bool poll_on_timeout = true;
  /// Checked before each frame; true stops the pump at once (the scan in progress is then
  /// not flushed). Empty = run until the source is done.
  std::function<bool()> stop;
  /// Called with every frame before the assembler sees it (recording, progress).
  std::function<void(const Frame&)> on_frame;
  /// Called when a wait for a frame timed out and the source is not done, after the poll,
  /// with the wall time [us] (idle display ticks).
  std::function<void(int64_t wall_utime)> on_idle;
};

struct PumpResult {
  int64_t frames = 0;    ///< frames handed to the assembler
  int64_t scans = 0;     ///< scans handed to on_scan
  bool stopped = false;  ///< ended by PumpOptions::stop rather than by the end of the source
};

/// Receives each scan, in the order the assembler emitted it, with the wall time [us] at
/// which the frame that finished it was received (the flush time for the last, partial scan).
/// The callee may move from `scan`.
using ScanCallback = std::function<void(Scan& scan, int64_t receive_wall_utime)>;

/// Reads frames from `source` into `assembler` until the source is done or options.stop()
/// returns true, and hands every scan to `on_scan`. When the source is done, the scan in
/// progress is flushed (ScanAssembler::Flush) and handed out as well. Exceptions from the
/// callbacks or the source propagate. Throws std::invalid_argument without a wall clock.
PumpResult PumpFrames(FrameSource& source, ScanAssembler& assembler, const ScanCallback& on_scan,
                      const PumpOptions& options);

/// A scan of sensor `index` (its assembler's place in PumpRoutedFrames' list).
using RoutedScanCallback = std::function<void(int index, Scan& scan, int64_t receive_wall_utime)>;

/// PumpFrames for several sensors on one source (a hand): each frame goes to the assemblers
/// `router` names (FrameRouter::Route; unclaimed frames are counted there), a timeout polls
/// every assembler, the end flushes each in index order. Scans are handed out in the order
/// the frames that finished them came, so a log gives the same order run to run.
PumpResult PumpRoutedFrames(FrameSource& source, FrameRouter& router, const std::vector<ScanAssembler*>& assemblers,
                            const RoutedScanCallback& on_scan, const PumpOptions& options);

}  // namespace sedbridge::sensors
