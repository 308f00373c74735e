#pragma once
// ActuatorOutput as CSV lines: a header, then one line per frame, flushed at once.
//   utime,sequence,stale,fault,shutdown,a0_kPa,a1_kPa,...

#include <cstdio>
#include <string>

#include "display/actuator_output.h"

namespace sedbridge::display {

class CsvActuatorOutput : public ActuatorOutput {
 public:
  /// @param[in] path  "" = stdout; else a file (truncated) or FIFO (waits for its reader)
  /// Throws std::runtime_error if `path` cannot be opened.
  CsvActuatorOutput(const std::string& path, std::size_t actuators, const std::string& unit);
  ~CsvActuatorOutput() override;
  bool Write(const ActuatorFrame& frame) override;
  std::string Describe() const override;

 private:
  std::FILE* file_ = nullptr;
  bool owned_ = false;
  std::string path_;
};

}  // namespace sedbridge::display
