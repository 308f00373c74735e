#pragma once
// ActuatorOutput on a serial port (termios, raw 8N1), one ASCII line per frame:
//
//   $D,<sequence>,<flags>,<n>,<v0>,...,<v(n-1)>*<XX>\r\n
//
//   sequence  decimal, +1 per frame (a gap means a lost line)
//   flags     decimal bit set: 1 stale, 2 fault, 4 shutdown
//   n         number of values; each value in the display unit with 3 decimals, in [0, max]
//   XX        two upper-case hex digits: XOR of every byte between '$' and '*' (as NMEA 0183)
//
// A device should apply a line only when its checksum matches and n is its actuator count,
// and go to zero by itself when no valid line arrives within its own timeout: this driver
// writes a line every tick (default 200 Hz) even when nothing changes.

#include <string>

#include "display/actuator_output.h"

namespace sedbridge::display {

/// The line for `frame`, without writing it (tests, other transports).
std::string FormatSerialLine(const ActuatorFrame& frame);

class SerialActuatorOutput : public ActuatorOutput {
 public:
  /// @param[in] device  e.g. "/dev/ttyUSB0"
  /// @param[in] baud    one of 9600, 19200, 38400, 57600, 115200, 230400, 460800, 921600
  /// Throws std::runtime_error (cannot open / configure), std::invalid_argument (baud).
  SerialActuatorOutput(const std::string& device, int baud);
  ~SerialActuatorOutput() override;
  bool Write(const ActuatorFrame& frame) override;
  std::string Describe() const override;

 private:
  int fd_ = -1;
  std::string device_;
  int baud_;
};

}  // namespace sedbridge::display
