#pragma once
// A DISPLAY_COMMAND as the bridge would publish it, for the LCM stage's tests.

#include <cstdint>

#include "display/display_command.h"

namespace sedbridge::lcm_io::test_messages {

/// suction_4x4, three values in kPa (0, 1.25, 20), clamped; utime 1000 + seq [us].
inline display::DisplayCommand Command(int64_t seq) {
  display::DisplayCommand c;
  c.utime = 1000 + seq;
  c.sequence = seq;
  c.source_scan_utime = 900;
  c.source_sed_utime = 950;
  c.display_id = "suction_4x4";
  c.unit = "kPa";
  c.value = {0.0, 1.25, 20.0};
  c.clamped = true;
  return c;
}

}  // namespace sedbridge::lcm_io::test_messages
