#include "lcm/lcm_log_writer.h"

#include <cstdio>
#include <lcm/lcm-cpp.hpp>
#include <stdexcept>

namespace sedbridge::lcm_io {

LcmLogWriter::LcmLogWriter(const std::string& path)
    : path_(path), log_(std::make_unique<lcm::LogFile>(path, "w")) {
  if (!log_->good()) throw std::runtime_error("cannot write LCM log '" + path + "'");
}

LcmLogWriter::~LcmLogWriter() = default;

void LcmLogWriter::WriteRaw(const std::string& channel, int64_t timestamp_utime,
                            const void* data, int32_t size) {
  lcm::LogEvent event{};
  event.timestamp = timestamp_utime;
  event.channel = channel;
  event.datalen = size;
  event.data = const_cast<void*>(data);  // LogFile takes a non-const event; it only reads data
  if (log_->writeEvent(&event) != 0)
    throw std::runtime_error("write error in LCM log '" + path_ + "'");
  ++events_;
}

void LcmLogWriter::Flush() { std::fflush(log_->getFilePtr()); }

}  // namespace sedbridge::lcm_io
