#pragma once
// The one wall clock of the code base: what LCM messages, latency figures and live CAN frames
// are stamped with.

#include <cstdint>

namespace sedbridge {

/// Wall-clock time [us since the Unix epoch], LCM's utime. Not monotonic (NTP may step it):
/// measure durations with std::chrono::steady_clock instead.
int64_t WallClockUtime();

}  // namespace sedbridge
