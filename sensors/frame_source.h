#pragma once
// The one interface every CAN frame source implements: SocketCAN, candump-log playback and
// the simulated follower sensor. The scan assembler and the bridge only see this.

#include <cstdint>
#include <optional>
#include <string>

#include "sensors/can_frame.h"

namespace sedbridge::sensors {

/// Counters of a frame source (all since construction). Error-frame classes follow
/// linux/can/error.h; a log source counts its unparsable lines in `bad_lines`.
struct FrameSourceStats {
  int64_t frames = 0;                 ///< frames handed out by Next() (incl. error frames)
  int64_t error_frames = 0;           ///< error frames seen
  int64_t bus_off = 0;                ///< CAN_ERR_BUSOFF
  int64_t error_passive = 0;          ///< CAN_ERR_CRTL with an error-passive state bit
  int64_t error_warning = 0;          ///< CAN_ERR_CRTL with a warning bit
  int64_t controller_overflow = 0;    ///< CAN_ERR_CRTL_RX/TX_OVERFLOW
  int64_t restarted = 0;              ///< CAN_ERR_RESTARTED
  int64_t other_errors = 0;           ///< any other error class (lost arbitration, bus error, ...)
  int64_t kernel_drops = 0;           ///< frames the kernel dropped (SO_RXQ_OVFL)
  int64_t bad_lines = 0;              ///< log lines that were not a frame
  int64_t read_errors = 0;            ///< failed reads (I/O errors, truncated datagrams)
};

/// Adds the error classes of error frame `f` (f.error must be true) to `stats`.
void CountErrorFrame(const Frame& f, FrameSourceStats* stats);

class FrameSource {
 public:
  virtual ~FrameSource() = default;

  /// Next frame, waiting at most `timeout_us` microseconds (0 = do not wait; a negative
  /// value waits indefinitely). Returns std::nullopt on timeout or at the end (see Done()).
  virtual std::optional<Frame> Next(int64_t timeout_us) = 0;

  /// True once the source can never produce another frame (end of a log, closed socket,
  /// end of a simulation). A live bus is never done until Close().
  virtual bool Done() const = 0;

  /// Stops the source; later Next() calls return std::nullopt. Idempotent.
  virtual void Close() {}

  virtual FrameSourceStats Stats() const = 0;
  /// One line for logs, e.g. "socketcan can0" or "candump log recording.log".
  virtual std::string Describe() const = 0;
};

}  // namespace sedbridge::sensors
