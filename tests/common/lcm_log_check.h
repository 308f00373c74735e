#pragma once
// Test helpers for LCM event logs a run left behind: the display commands in it, and whether
// the file ends on a whole record (a process killed mid-write leaves a cut record).

#include <lcm/lcm-cpp.hpp>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "lcm/lcm_log_reader.h"
#include "sedbridge/lcmt_display_command.hpp"

namespace sedbridge::testing {

struct LogCheck {
  std::vector<lcmt_display_command> commands;  ///< every DISPLAY_COMMAND, in file order
  int64_t events = 0;
  int64_t record_bytes = 0;  ///< sum of the records' sizes (28-byte header + channel + data)
  int64_t file_bytes = 0;
  bool whole() const { return events > 0 && record_bytes == file_bytes; }
};

inline LogCheck ReadLog(const std::string& path, const std::string& command_channel = "DISPLAY_COMMAND") {
  LogCheck c;
  c.file_bytes = static_cast<int64_t>(std::filesystem::file_size(path));
  lcm_io::LcmLogReader reader(path);
  while (const lcm::LogEvent* e = reader.Next()) {
    ++c.events;
    c.record_bytes += 4 + 8 + 8 + 4 + 4 + static_cast<int64_t>(e->channel.size()) + e->datalen;
    if (e->channel != command_channel) continue;
    lcmt_display_command m;
    if (lcm_io::LcmLogReader::Decode(*e, &m)) c.commands.push_back(m);
  }
  return c;
}

inline bool AllZero(const lcmt_display_command& m) {
  for (float v : m.value)
    if (v != 0.0f) return false;
  return true;
}

}  // namespace sedbridge::testing
