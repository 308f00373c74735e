#include "display/csv_actuator_output.h"

#include <stdexcept>

namespace sedbridge::display {

CsvActuatorOutput::CsvActuatorOutput(const std::string& path, std::size_t actuators, const std::string& unit)
    : path_(path) {
  if (path.empty()) {
    file_ = stdout;
  } else {
    file_ = std::fopen(path.c_str(), "w");
    if (!file_) throw std::runtime_error("cannot open '" + path + "' for the display output");
    owned_ = true;
  }
  std::fprintf(file_, "utime,sequence,stale,fault,shutdown");
  for (std::size_t i = 0; i < actuators; ++i) std::fprintf(file_, ",a%zu_%s", i, unit.c_str());
  std::fputc('\n', file_);
  std::fflush(file_);
}

CsvActuatorOutput::~CsvActuatorOutput() {
  if (owned_ && file_) std::fclose(file_);
}

bool CsvActuatorOutput::Write(const ActuatorFrame& f) {
  std::fprintf(file_, "%lld,%lld,%d,%d,%d", static_cast<long long>(f.utime), static_cast<long long>(f.sequence),
               f.stale ? 1 : 0, f.fault ? 1 : 0, f.shutdown ? 1 : 0);
  for (double v : f.value) std::fprintf(file_, ",%.4f", v);
  std::fputc('\n', file_);
  // Flushed per frame: the reader is a device, not a log; and a kill must not lose the tail.
  const bool ok = std::fflush(file_) == 0 && !std::ferror(file_);
  std::clearerr(file_);
  return ok;
}

std::string CsvActuatorOutput::Describe() const { return path_.empty() ? "CSV on stdout" : "CSV to " + path_; }

}  // namespace sedbridge::display
