#pragma once
// The last stage before a person's skin: clamps, slew-limits and times out actuator commands.
// Nothing in a scene or profile can switch it off; its limits can only be set, not disabled.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "display/command_watchdog.h"
#include "display/display_profile.h"

namespace sedbridge::display {

/// Longest interval one output's rise may use [s]. The slew limit is per unit of time, but a
/// stream with 0.2 s between messages would otherwise jump 0.2 s worth of slew in one step;
/// later outputs rise as if this long had passed (slower than the slew: the safe side).
/// 25 ms: the period of the slowest shipped sensor (40 Hz), and 5 ticks at the default 200 Hz.
inline constexpr double kMaxRiseInterval_s = 0.025;

/// Limits for SafetyLimiter, in the display's unit.
struct SafetyLimits {
  std::vector<double> max;         ///< hard maximum per actuator [unit], each finite and > 0
  double slew_rate_per_s = 0;      ///< largest change per second [unit/s], finite and > 0
  double watchdog_timeout_s = 0;   ///< in (0, kMaxWatchdogTimeout_s] [s]
  /// Smallest nonzero value the device accepts (the profile's range[0]) [unit], >= 0 and
  /// below every max[i] that is not vanishing. Anything the ramp puts below it is sent as 0:
  /// the device cannot render it, and off is the safe reading of "too small to render".
  double min_nonzero = 0;

  static SafetyLimits FromProfile(const DisplayProfile& profile);
};

/// One emitted command after limiting.
struct LimitedOutput {
  std::vector<double> value;  ///< per actuator [unit], always within [0, max[i]]
  bool clamped = false;       ///< a request was above max[i] or below 0 and was clipped
  bool stale = false;         ///< watchdog expired: ramping to / holding zero
  bool fault = false;         ///< the last request had NaN/Inf or the wrong length -> those
                              ///< actuators are 0; cleared by the next good fresh request
  bool shutdown = false;      ///< after Shutdown(): all zero, for good
};

/// Guarantees for every emitted output y_k at time t_k (k > 0, dt = t_k - t_{k-1} >= 0):
///   - 0 <= y_k[i] <= max[i], and y_k[i] == 0 or y_k[i] >= min_nonzero
///   - y_k[i] - y_{k-1}[i] <= slew_rate * min(dt, kMaxRiseInterval_s) + min_nonzero   (rises, always;
///     the min_nonzero term is the one step across the device's dead band [0, min_nonzero))
///   - |y_k[i] - y_{k-1}[i]| <= slew_rate * dt   unless y_k[i] == 0 because of a fault,
///     shutdown or the dead band (dropping to zero at once is the safe direction)
///   - the first output is all zero (it ramps up from rest)
///   - if no fresh input arrives after time t0, y_k == 0 for every
///     t_k >= t0 + timeout + max(max[i]) / slew_rate  (ramp to zero, stale flagged)
///   - after Shutdown() every output is zero.
/// `now_utime` must not decrease between calls; if it does, no rise is allowed for that call.
class SafetyLimiter {
 public:
  /// Throws std::invalid_argument for any limit that is non-finite, <= 0, or a timeout above
  /// kMaxWatchdogTimeout_s.
  explicit SafetyLimiter(SafetyLimits limits);

  /// A fresh request from the mapping (input stamped `input_utime`, e.g. the SED field's utime).
  /// `requested` has one value per actuator in the display unit; NaN/Inf entries (or a wrong
  /// length) become 0 with the fault flag. A repeated or older stamp neither re-arms the
  /// watchdog nor changes the targets, but its NaN/Inf entries still zero their actuators.
  const LimitedOutput& Apply(int64_t now_utime, int64_t input_utime,
                             const std::vector<double>& requested);

  /// No new input: holds the last request while the watchdog is armed, else ramps to zero.
  /// Call at the display's command rate.
  const LimitedOutput& Tick(int64_t now_utime);

  /// Zero now and for every later call; cannot be undone.
  const LimitedOutput& Shutdown(int64_t now_utime);

  const LimitedOutput& last() const { return out_; }
  const SafetyLimits& limits() const { return limits_; }
  std::size_t size() const { return limits_.max.size(); }
  bool is_shut_down() const { return shut_down_; }

 private:
  const LimitedOutput& Emit(int64_t now_utime);

  SafetyLimits limits_;
  CommandWatchdog watchdog_;
  std::vector<double> target_;      // last accepted request, clipped to [0, max]
  std::vector<char> target_fault_;  // per actuator: last request was non-finite
  bool target_clamped_ = false;
  bool target_fault_any_ = false;
  LimitedOutput out_;
  std::vector<double> ramp_;        // slew-limited value before the dead band [unit]
  bool emitted_ = false;
  int64_t last_emit_utime_ = 0;
  bool shut_down_ = false;
};

}  // namespace sedbridge::display
