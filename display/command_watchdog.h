#pragma once
// Detects silence on the input side: no fresh SED field within the timeout.

#include <cstdint>

namespace sedbridge::display {

/// Tracks when fresh input last arrived. Freshness is judged on the receiver's clock
/// (`now_utime`), because the producer's clock may be another machine's; the producer's
/// `input_utime` only rejects repeats and reordering (an old or repeated field does not
/// count as fresh). Pass a monotonic `now_utime` where possible.
class CommandWatchdog {
 public:
  /// @param[in] timeout_s  > 0; otherwise std::invalid_argument
  explicit CommandWatchdog(double timeout_s);

  /// Reports input stamped `input_utime` [us] received at `now_utime` [us]. Returns true and
  /// re-arms the watchdog when it is fresh (newer than every input seen so far).
  bool Feed(int64_t input_utime, int64_t now_utime);

  /// True before the first fresh input, when more than the timeout passed since the last
  /// one, and when the clock went backwards (the elapsed time is then unknown).
  bool Stale(int64_t now_utime) const;

  double timeout_s() const { return timeout_s_; }
  bool ever_fed() const { return ever_fed_; }

 private:
  double timeout_s_;
  int64_t timeout_us_;
  bool ever_fed_ = false;
  int64_t last_input_utime_ = 0;
  int64_t last_fed_now_utime_ = 0;
};

}  // namespace sedbridge::display
