#pragma once
// Live CAN input from several buses at once (a hand whose fingers sit on can0 and can1): one
// CAN_RAW socket per interface, each bound to its bus with that bus's kernel filters, read by
// one reader that polls them all. Frames keep their interface name (Frame::interface), so a
// FrameRouter sends each to its finger as it does for a `candump -l any` log.
//
// Why a socket per interface and not one CAN_RAW socket bound to "any" (ifindex 0, the
// interface taken from recvfrom's sockaddr_can, as `candump any` does):
//   - kernel filters: an "any" socket's CAN_RAW_FILTER applies to every bus, so the ids of
//     can0's fingers would also pass on can1 (and every bus the host has), waking the reader
//     for traffic no finger wants; bound sockets filter each bus for its own fingers only;
//   - faults stay per bus: SO_RXQ_OVFL drops, read errors and a bus going down (ENETDOWN)
//     are counted per interface, so one bus's trouble is that bus's fingers' (Stats(name));
//   - buses the config does not name (a third, busy bus on the same host) never reach us.
// The cost is one descriptor per bus, polled together in one ppoll.
//
// Tests build it from SocketCanSources on socketpairs (SocketCanSource's descriptor
// constructor), so the reader is tested without AF_CAN.

#include <atomic>
#include <memory>
#include <string>
#include <vector>

#include "sensors/frame_source.h"
#include "sensors/socketcan_source.h"

namespace sedbridge::sensors {

class MultiSocketCanSource final : public FrameSource {
 public:
  /// Reads `buses` (at least one; interface names unique). Throws std::invalid_argument otherwise.
  explicit MultiSocketCanSource(std::vector<std::unique_ptr<SocketCanSource>> buses);
  /// Opens one socket per entry (SocketCanSource(options)); throws as that does, naming the bus.
  static std::unique_ptr<MultiSocketCanSource> Open(const std::vector<SocketCanOptions>& buses);
  ~MultiSocketCanSource() override;
  MultiSocketCanSource(const MultiSocketCanSource&) = delete;
  MultiSocketCanSource& operator=(const MultiSocketCanSource&) = delete;

  /// The next frame of any bus (buses with a frame waiting take turns, so a busy bus cannot
  /// starve another), waiting at most `timeout_us` for one.
  std::optional<Frame> Next(int64_t timeout_us) override;
  /// True once every bus is done (a bus that went down leaves the others running) or Close().
  bool Done() const override;
  /// Thread-safe: wakes a Next() blocked in another thread.
  void Close() override;
  /// Every bus's counters added up (kernel_drops too: each socket counts its own).
  FrameSourceStats Stats() const override;
  /// One bus's counters; all zero for a name not read here.
  FrameSourceStats Stats(const std::string& interface) const;
  /// "socketcan can0+can1".
  std::string Describe() const override;

  /// Sends `frame` on `interface` (start/stop commands). False when no such bus or the send failed.
  bool Send(const std::string& interface, const Frame& frame);
  size_t bus_count() const { return buses_.size(); }

 private:
  std::vector<std::unique_ptr<SocketCanSource>> buses_;
  size_t next_bus_ = 0;  // first bus asked on the next call (round robin)
  int wake_fd_ = -1;     // eventfd written by Close()
  std::atomic<bool> closed_{false};
};

}  // namespace sedbridge::sensors
