#include "display/command_watchdog.h"

#include <cmath>
#include <stdexcept>

namespace sedbridge::display {

CommandWatchdog::CommandWatchdog(double timeout_s) : timeout_s_(timeout_s) {
  if (!std::isfinite(timeout_s) || timeout_s <= 0)
    throw std::invalid_argument("CommandWatchdog: timeout_s must be finite and > 0");
  timeout_us_ = static_cast<int64_t>(std::llround(timeout_s * 1e6));
}

bool CommandWatchdog::Feed(int64_t input_utime, int64_t now_utime) {
  if (ever_fed_ && input_utime <= last_input_utime_) return false;
  ever_fed_ = true;
  last_input_utime_ = input_utime;
  last_fed_now_utime_ = now_utime;
  return true;
}

bool CommandWatchdog::Stale(int64_t now_utime) const {
  if (!ever_fed_) return true;
  if (now_utime < last_fed_now_utime_) return true;
  return now_utime - last_fed_now_utime_ > timeout_us_;
}

}  // namespace sedbridge::display
