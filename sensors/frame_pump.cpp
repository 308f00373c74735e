#include "sensors/frame_pump.h"

#include <stdexcept>
#include <vector>

namespace sedbridge::sensors {
namespace {

void HandOut(std::vector<Scan>* scans, int64_t receive_wall_utime, const ScanCallback& on_scan,
             PumpResult* result) {
  for (Scan& scan : *scans) {
    ++result->scans;
    on_scan(scan, receive_wall_utime);
  }
  scans->clear();
}

// The pump's loop, one sensor or several: frames until the source is done or options.stop
// asks (false then: no flush); on_frame(frame, wall) for each frame, on_timeout(wall) when
// none came within the wait.
template <class OnFrame, class OnTimeout>
bool PumpLoop(FrameSource& source, const PumpOptions& options, PumpResult* result, OnFrame on_frame,
              OnTimeout on_timeout) {
  while (!source.Done()) {
    if (options.stop && options.stop()) {
      result->stopped = true;
      return false;
    }
    const std::optional<Frame> frame = source.Next(options.frame_wait_us);
    const int64_t wall = options.wall_clock_utime();
    if (frame) {
      ++result->frames;
      if (options.on_frame) options.on_frame(*frame);
      on_frame(*frame, wall);
      continue;
    }
    if (source.Done()) break;  // the end, not a timeout
    on_timeout(wall);
  }
  return true;
}

}  // namespace

PumpResult PumpFrames(FrameSource& source, ScanAssembler& assembler, const ScanCallback& on_scan,
                      const PumpOptions& options) {
  if (!options.wall_clock_utime) throw std::invalid_argument("PumpFrames needs a wall clock");
  PumpResult result;
  std::vector<Scan> scans;
  const bool done = PumpLoop(
      source, options, &result,
      [&](const Frame& frame, int64_t wall) {
        assembler.Push(frame, &scans);
        HandOut(&scans, wall, on_scan, &result);
      },
      [&](int64_t wall) {
        if (options.poll_on_timeout) assembler.Poll(wall, &scans);
        if (options.on_idle) options.on_idle(wall);
        HandOut(&scans, wall, on_scan, &result);
      });
  if (!done) return result;
  assembler.Flush(&scans);
  HandOut(&scans, options.wall_clock_utime(), on_scan, &result);
  return result;
}

namespace {

void HandOutRouted(std::vector<Scan>* scans, int index, int64_t receive_wall_utime, const RoutedScanCallback& on_scan,
                   PumpResult* result) {
  for (Scan& scan : *scans) {
    ++result->scans;
    on_scan(index, scan, receive_wall_utime);
  }
  scans->clear();
}

}  // namespace

PumpResult PumpRoutedFrames(FrameSource& source, FrameRouter& router, const std::vector<ScanAssembler*>& assemblers,
                            const RoutedScanCallback& on_scan, const PumpOptions& options) {
  if (!options.wall_clock_utime) throw std::invalid_argument("PumpRoutedFrames needs a wall clock");
  PumpResult result;
  std::vector<Scan> scans;
  const int n = static_cast<int>(assemblers.size());
  const bool done = PumpLoop(
      source, options, &result,
      [&](const Frame& frame, int64_t wall) {
        for (int index : router.Route(frame)) {
          if (index < 0 || index >= n) throw std::out_of_range("FrameRouter names sensor " + std::to_string(index));
          assemblers[size_t(index)]->Push(frame, &scans);
          HandOutRouted(&scans, index, wall, on_scan, &result);
        }
      },
      [&](int64_t wall) {
        for (int index = 0; index < n; ++index) {
          if (options.poll_on_timeout) assemblers[size_t(index)]->Poll(wall, &scans);
          HandOutRouted(&scans, index, wall, on_scan, &result);
        }
        if (options.on_idle) options.on_idle(wall);
      });
  if (!done) return result;
  for (int index = 0; index < n; ++index) {
    assemblers[size_t(index)]->Flush(&scans);
    HandOutRouted(&scans, index, options.wall_clock_utime(), on_scan, &result);
  }
  return result;
}

}  // namespace sedbridge::sensors
