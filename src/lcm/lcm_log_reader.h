#pragma once
// Reads LCM event logs (from lcm-logger or LcmLogWriter) event by event.

#include <cstdint>
#include <memory>
#include <string>

namespace lcm {
class LogFile;
struct LogEvent;
}

namespace sedbridge::lcm_io {

class LcmLogReader {
 public:
  /// Throws std::runtime_error if `path` cannot be opened as an LCM log.
  explicit LcmLogReader(const std::string& path);
  ~LcmLogReader();
  LcmLogReader(const LcmLogReader&) = delete;
  LcmLogReader& operator=(const LcmLogReader&) = delete;

  /// Next event, or nullptr at the end (or at a truncated/corrupt tail). The event is valid
  /// until the next call.
  const lcm::LogEvent* Next();

  /// Decodes `event` as Msg; false when the bytes are not a Msg (wrong type fingerprint,
  /// truncated, an array count the bytes cannot hold). Use on events of the channel you
  /// expect. Goes through SafeDecode: a log is untrusted input.
  template <typename Msg>
  static bool Decode(const lcm::LogEvent& event, Msg* msg);

 private:
  std::unique_ptr<lcm::LogFile> log_;
};

}  // namespace sedbridge::lcm_io

#include <lcm/lcm-cpp.hpp>

#include "lcm/lcm_safe_decode.h"

namespace sedbridge::lcm_io {

template <typename Msg>
bool LcmLogReader::Decode(const lcm::LogEvent& event, Msg* msg) {
  if (event.datalen < 0) return false;
  return SafeDecode(event.data, static_cast<std::size_t>(event.datalen), msg);
}

}  // namespace sedbridge::lcm_io
