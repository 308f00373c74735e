#include "bridge/live_hand_bridge.h"

#include <exception>
#include <mutex>
#include <stdexcept>
#include <thread>

#include "common/wall_clock.h"
#include "sensors/frame_pump.h"

namespace sedbridge::bridge {

LiveHandBridge::LiveHandBridge(sensors::FrameSource& source, std::vector<LiveFinger> fingers, LiveOptions options,
                               std::function<sensors::FrameSourceStats(const std::string&)> finger_stats)
    : source_(source), fingers_(std::move(fingers)), options_(options), finger_stats_(std::move(finger_stats)) {
  if (fingers_.empty()) throw std::invalid_argument("LiveHandBridge needs at least one finger");
  for (size_t i = 0; i < fingers_.size(); ++i) {
    const LiveFinger& f = fingers_[i];
    if (!f.profile || !f.pipeline) throw std::invalid_argument("finger '" + f.name + "': no profile or pipeline");
    if (f.tick_period_us <= 0) throw std::invalid_argument("finger '" + f.name + "': tick period must be > 0");
    router_.Claim(int(i), f.name, f.interface, *f.profile);
    sensors::AssemblerOptions a;
    a.tare_scans = f.tare_scans;
    a.interface = f.interface;  // the router already sent only this bus's frames; kept for its counters
    assemblers_.push_back(std::make_unique<sensors::ScanAssembler>(*f.profile, a));
    slots_.push_back(std::make_unique<LatestScanSlot>());
  }
}

sensors::FrameSourceStats LiveHandBridge::StatsOf(size_t finger) const {
  return finger_stats_ ? finger_stats_(fingers_[finger].interface) : source_.Stats();
}

LiveHandResult LiveHandBridge::Run(const std::atomic<bool>& stop) {
  const size_t n = fingers_.size();
  LiveHandResult result;
  result.fingers.resize(n);
  std::mutex error_mutex;
  std::exception_ptr first_error;
  std::atomic<bool> halt{false};  // any thread's error stops every thread
  auto fail = [&](std::exception_ptr e) {
    {
      std::lock_guard<std::mutex> lock(error_mutex);
      if (!first_error) first_error = e;
    }
    halt = true;
  };
  auto stopped = [&] { return stop.load() || halt.load(); };
  auto close_slots = [&] {
    for (auto& slot : slots_) slot->Close();
  };

  // Error frames make no scan: a bus-off on one finger's bus reaches that finger's slot (and
  // its display ticks' BRIDGE_STATUS) when another finger's scan comes or the buses idle, so
  // the receiver refreshes every finger's counters then (n slots, a lock each).
  auto refresh_counters = [&] {
    for (size_t i = 0; i < n; ++i) slots_[i]->SetCounters(assemblers_[i]->counters(), StatsOf(i));
  };
  std::atomic<bool> receiver_done{false};
  sensors::PumpResult pumped;
  std::thread receiver([&] {
    try {
      sensors::PumpOptions pump;
      pump.frame_wait_us = options_.receive_timeout_us;
      pump.wall_clock_utime = WallClockUtime;
      pump.poll_on_timeout = true;  // a scan with a lost frame still goes out after its timeout
      pump.stop = stopped;
      pump.on_idle = [&](int64_t) { refresh_counters(); };
      std::vector<sensors::ScanAssembler*> assemblers;
      for (auto& a : assemblers_) assemblers.push_back(a.get());
      pumped = sensors::PumpRoutedFrames(
          source_, router_, assemblers,
          [&](int index, sensors::Scan& scan, int64_t receive_wall_utime) {
            LatestScanSlot& slot = *slots_[size_t(index)];
            refresh_counters();
            const int64_t origin = options_.scan_utime_is_wall_clock ? scan.utime : receive_wall_utime;
            slot.Put({std::move(scan), origin});
          },
          pump);
      refresh_counters();
    } catch (...) {
      fail(std::current_exception());
    }
    receiver_done = true;
    close_slots();
  });

  std::vector<std::thread> solvers;
  for (size_t i = 0; i < n; ++i) {
    solvers.emplace_back([&, i] {
      LiveOptions own = options_;
      own.tick_period_us = fingers_[i].tick_period_us;
      try {
        RunLiveSolver(*slots_[i], *fingers_[i].pipeline, own, stopped, receiver_done, &result.fingers[i]);
      } catch (...) {
        fail(std::current_exception());
      }
    });
  }
  for (std::thread& t : solvers) t.join();
  result.stopped_by_request = stop.load();
  halt = true;     // the solvers are gone: the receiver stops within one receive timeout
  close_slots();
  receiver.join();
  source_.Close();
  // Zero every display on every way out; a second error must not hide the first.
  for (size_t i = 0; i < n; ++i) {
    try {
      fingers_[i].pipeline->SetScansDroppedUpstream(slots_[i]->dropped_count());
      fingers_[i].pipeline->Shutdown(WallClockUtime());
    } catch (...) {
      fail(std::current_exception());
    }
    result.fingers[i].stopped_by_request = result.stopped_by_request;
    result.fingers[i].scans_received = slots_[i]->put_count();
    result.fingers[i].scans_dropped = slots_[i]->dropped_count();
  }
  result.frames = pumped.frames;
  result.unclaimed_frames = router_.unclaimed();
  if (first_error) std::rethrow_exception(first_error);
  return result;
}

}  // namespace sedbridge::bridge
