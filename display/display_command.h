#pragma once
// One command for the display, as published on DISPLAY_COMMAND (lcmt_display_command).

#include <cstdint>
#include <string>
#include <vector>

namespace sedbridge::display {

struct DisplayCommand {
  int64_t utime = 0;              ///< emission time [us]
  int64_t sequence = 0;           ///< +1 per command, from 0
  int64_t source_scan_utime = 0;  ///< scan behind the SED field in use [us]; 0 = none
  int64_t source_sed_utime = 0;   ///< SED field in use [us]; 0 = none yet
  std::string display_id;         ///< profile name
  std::string unit;               ///< "kPa", "mm", "mA"
  std::vector<double> value;      ///< per actuator [unit], within [0, max]
  bool clamped = false;
  bool stale = false;
  bool fault = false;
  bool shutdown = false;
};

}  // namespace sedbridge::display
