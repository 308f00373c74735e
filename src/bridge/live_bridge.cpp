#include "bridge/live_bridge.h"

#include <exception>
#include <thread>
#include <vector>

#include "common/wall_clock.h"
#include "sensors/frame_pump.h"

namespace sedbridge::bridge {

LiveBridge::LiveBridge(sensors::FrameSource& source, sensors::ScanAssembler& assembler, BridgePipeline& pipeline,
                       LiveOptions options)
    : source_(source), assembler_(assembler), pipeline_(pipeline), options_(options) {}

void LiveBridge::Receive(const std::atomic<bool>& stop) {
  sensors::PumpOptions pump;
  pump.frame_wait_us = options_.receive_timeout_us;
  pump.wall_clock_utime = WallClockUtime;
  pump.poll_on_timeout = true;  // a scan with a lost frame still goes out after its timeout
  pump.stop = [&] { return stop.load() || slot_.closed(); };
  sensors::PumpFrames(
      source_, assembler_,
      [&](sensors::Scan& scan, int64_t receive_wall_utime) {
        slot_.SetCounters(assembler_.counters(), source_.Stats());
        const int64_t origin = options_.scan_utime_is_wall_clock ? scan.utime : receive_wall_utime;
        slot_.Put({std::move(scan), origin});
      },
      pump);
  slot_.SetCounters(assembler_.counters(), source_.Stats());
}

void RunLiveSolver(LatestScanSlot& slot, BridgePipeline& pipeline, const LiveOptions& options,
                   const std::function<bool()>& stopped, const std::atomic<bool>& receiver_done,
                   LiveResult* result) {
  LatestScanSlot::Entry entry;
  sensors::BadFrameCounters counters;
  sensors::FrameSourceStats stats;
  while (!stopped()) {
    if (slot.Take(&entry, options.tick_period_us)) {
      slot.GetCounters(&counters, &stats);
      pipeline.SetSensorCounters(counters, stats);
      pipeline.SetScansDroppedUpstream(slot.dropped_count());
      pipeline.ProcessScan(entry.scan, WallClockUtime(), entry.receive_wall_utime);
      ++result->scans_processed;
    } else if (receiver_done.load()) {
      break;  // closed and empty
    } else {
      slot.GetCounters(&counters, &stats);  // a silent bus's state (bus-off) on its status
      pipeline.SetSensorCounters(counters, stats);
      pipeline.Tick(WallClockUtime());
      ++result->ticks;
    }
  }
}

LiveResult LiveBridge::Run(const std::atomic<bool>& stop) {
  LiveResult result;
  std::exception_ptr receiver_error, solver_error;
  std::atomic<bool> receiver_done{false};
  std::thread receiver([&] {
    try {
      Receive(stop);
    } catch (...) {
      receiver_error = std::current_exception();
    }
    receiver_done = true;
    slot_.Close();
  });

  try {
    RunLiveSolver(slot_, pipeline_, options_, [&] { return stop.load(); }, receiver_done, &result);
  } catch (...) {
    solver_error = std::current_exception();
  }
  result.stopped_by_request = stop.load();
  slot_.Close();  // the receiver sees it within one receive timeout
  receiver.join();
  source_.Close();
  pipeline_.SetScansDroppedUpstream(slot_.dropped_count());
  pipeline_.Shutdown(WallClockUtime());  // zero on exit and on any fault
  result.scans_received = slot_.put_count();
  result.scans_dropped = slot_.dropped_count();
  if (solver_error) std::rethrow_exception(solver_error);
  if (receiver_error) std::rethrow_exception(receiver_error);
  return result;
}

}  // namespace sedbridge::bridge
