#include "lcm/lcm_log_reader.h"

#include <stdexcept>

namespace sedbridge::lcm_io {

LcmLogReader::LcmLogReader(const std::string& path)
    : log_(std::make_unique<lcm::LogFile>(path, "r")) {
  if (!log_->good()) throw std::runtime_error("cannot read LCM log '" + path + "'");
}

LcmLogReader::~LcmLogReader() = default;

const lcm::LogEvent* LcmLogReader::Next() { return log_->readNextEvent(); }

}  // namespace sedbridge::lcm_io
