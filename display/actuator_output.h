#pragma once
// Where the leader-side display driver writes actuator values: the device end of the chain.
// Backends: CSV lines (stdout, a file or a FIFO a device process reads) and a serial port
// with a documented line protocol (display/README.md, "Display driver"). A lab wires its
// device by reading one of them, or by adding a backend here.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace sedbridge::display {

/// One output frame of the driver (after its own limiter).
struct ActuatorFrame {
  int64_t utime = 0;           ///< driver's clock when emitted [us since the Unix epoch]
  int64_t sequence = 0;        ///< +1 per frame, from 0
  std::vector<double> value;   ///< per actuator [unit], each in [0, max]
  bool stale = false;          ///< watchdog: no valid command within the timeout
  bool fault = false;          ///< last command had NaN/Inf or the wrong size
  bool shutdown = false;       ///< the driver is exiting: all zero
};

class ActuatorOutput {
 public:
  virtual ~ActuatorOutput() = default;
  /// Writes one frame. Returns false on a write error (counted by the caller; the driver
  /// keeps running: a reader may come back).
  virtual bool Write(const ActuatorFrame& frame) = 0;
  virtual std::string Describe() const = 0;
};

/// Builds an output from a spec:
///   "stdout"                      CSV on standard output
///   "csv:PATH"                    CSV into PATH (a regular file is truncated; a FIFO is
///                                 opened for writing, which waits for its reader)
///   "serial:DEVICE[:BAUD]"        line protocol on a serial port (BAUD default 115200)
/// @param[in] actuators  number of values per frame (CSV header)
/// @param[in] unit       display unit, for the CSV header ("kPa", "mm", "mA")
/// Throws std::invalid_argument (bad spec) or std::runtime_error (cannot open).
std::unique_ptr<ActuatorOutput> MakeActuatorOutput(const std::string& spec, std::size_t actuators,
                                                   const std::string& unit);

}  // namespace sedbridge::display
