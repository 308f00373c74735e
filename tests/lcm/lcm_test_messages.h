#pragma once
// A DISPLAY_COMMAND as the bridge would publish it, and any message's bytes, for the LCM
// stage's tests and the view's.

#include <cstdint>
#include <vector>

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

/// An lcmgen message's encoded bytes (what a log or the bus carries).
template <typename Msg>
std::vector<uint8_t> Encode(const Msg& m) {
  std::vector<uint8_t> b(size_t(m.getEncodedSize()));
  m.encode(b.data(), 0, int(b.size()));
  return b;
}

}  // namespace sedbridge::lcm_io::test_messages
