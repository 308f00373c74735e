#include "display/safety_limiter.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace sedbridge::display {

namespace {

// Upper bound given to a disabled actuator (max_per_actuator 0) [display unit]: the limiter
// needs a positive bound; this one keeps the actuator at zero in any unit.
constexpr double kDisabledActuatorMax = 1e-12;

SafetyLimits Validated(SafetyLimits l) {
  auto fail = [](const std::string& what) {
    throw std::invalid_argument("SafetyLimiter: " + what);
  };
  if (l.max.empty()) fail("no actuators");
  for (double m : l.max)
    if (!std::isfinite(m) || m <= 0) fail("every max must be finite and > 0");
  if (!std::isfinite(l.slew_rate_per_s) || l.slew_rate_per_s <= 0)
    fail("slew_rate_per_s must be finite and > 0");
  if (!std::isfinite(l.watchdog_timeout_s) || l.watchdog_timeout_s <= 0 ||
      l.watchdog_timeout_s > kMaxWatchdogTimeout_s)
    fail("watchdog_timeout_s must be in (0, " + std::to_string(kMaxWatchdogTimeout_s) + "]");
  if (!std::isfinite(l.min_nonzero) || l.min_nonzero < 0) fail("min_nonzero must be finite and >= 0");
  return l;
}

}  // namespace

SafetyLimits SafetyLimits::FromProfile(const DisplayProfile& profile) {
  SafetyLimits l;
  l.max = profile.safety.max_per_actuator;
  // Per-actuator overrides may be 0 ("disabled actuator"); the limiter needs a positive
  // bound, so such an actuator gets a vanishing one and effectively stays at zero.
  for (double& m : l.max) m = std::max(m, kDisabledActuatorMax);
  l.slew_rate_per_s = profile.safety.slew_rate_per_s;
  l.watchdog_timeout_s = profile.safety.watchdog_timeout_s;
  l.min_nonzero = profile.range_min;
  return l;
}

SafetyLimiter::SafetyLimiter(SafetyLimits limits)
    : limits_(Validated(std::move(limits))),
      watchdog_(limits_.watchdog_timeout_s),
      target_(size(), 0.0),
      target_fault_(size(), 0) {
  out_.value.assign(size(), 0.0);
  ramp_.assign(size(), 0.0);
}

const LimitedOutput& SafetyLimiter::Apply(int64_t now_utime, int64_t input_utime,
                                          const std::vector<double>& requested) {
  if (shut_down_) return Emit(now_utime);
  // A repeated or reordered input is not news: it neither re-arms the watchdog nor changes
  // the target — except that its bad entries still zero their actuators (always safe).
  if (!watchdog_.Feed(input_utime, now_utime)) {
    if (requested.size() != size()) {
      std::fill(target_.begin(), target_.end(), 0.0);
      std::fill(target_fault_.begin(), target_fault_.end(), 1);
      target_fault_any_ = true;
    } else {
      for (std::size_t i = 0; i < size(); ++i) {
        if (std::isfinite(requested[i])) continue;
        target_[i] = 0;
        target_fault_[i] = 1;
        target_fault_any_ = true;
      }
    }
    return Emit(now_utime);
  }
  target_clamped_ = false;
  target_fault_any_ = false;
  if (requested.size() != size()) {
    std::fill(target_.begin(), target_.end(), 0.0);
    std::fill(target_fault_.begin(), target_fault_.end(), 1);
    target_fault_any_ = true;
    return Emit(now_utime);
  }
  for (std::size_t i = 0; i < size(); ++i) {
    const double r = requested[i];
    target_fault_[i] = 0;
    if (!std::isfinite(r)) {
      target_[i] = 0;
      target_fault_[i] = 1;
      target_fault_any_ = true;
    } else if (r > limits_.max[i]) {
      target_[i] = limits_.max[i];
      target_clamped_ = true;
    } else if (r < 0) {
      target_[i] = 0;
      target_clamped_ = true;
    } else {
      target_[i] = r;
    }
  }
  return Emit(now_utime);
}

const LimitedOutput& SafetyLimiter::Tick(int64_t now_utime) { return Emit(now_utime); }

const LimitedOutput& SafetyLimiter::Shutdown(int64_t now_utime) {
  shut_down_ = true;
  return Emit(now_utime);
}

const LimitedOutput& SafetyLimiter::Emit(int64_t now_utime) {
  if (shut_down_) {
    std::fill(out_.value.begin(), out_.value.end(), 0.0);
    std::fill(ramp_.begin(), ramp_.end(), 0.0);
    out_.clamped = out_.stale = out_.fault = false;
    out_.shutdown = true;
    emitted_ = true;
    last_emit_utime_ = std::max(last_emit_utime_, now_utime);
    return out_;
  }
  const bool stale = watchdog_.Stale(now_utime);
  // Elapsed time since the previous output; none for the first one (it starts from rest) and
  // none when the clock went backwards. last_emit_utime_ never moves backwards.
  double dt_s = 0;
  if (emitted_ && now_utime > last_emit_utime_) dt_s = (now_utime - last_emit_utime_) * 1e-6;
  if (!emitted_ || now_utime > last_emit_utime_) last_emit_utime_ = now_utime;
  emitted_ = true;
  // Rises use at most kMaxRiseInterval_s: after a pause or between sparse messages the
  // output must not jump up.
  const double rise = limits_.slew_rate_per_s * std::min({dt_s, limits_.watchdog_timeout_s, kMaxRiseInterval_s});
  const double fall = limits_.slew_rate_per_s * dt_s;
  for (std::size_t i = 0; i < size(); ++i) {
    const double prev = ramp_[i];
    double y;
    if (target_fault_[i]) {
      y = 0;  // bad input: off at once, stale or not
    } else {
      const double target = stale ? 0.0 : target_[i];
      y = std::clamp(target, prev - fall, prev + rise);
    }
    ramp_[i] = std::clamp(y, 0.0, limits_.max[i]);
    out_.value[i] = ramp_[i] >= limits_.min_nonzero ? ramp_[i] : 0.0;
  }
  out_.stale = stale;
  out_.clamped = !stale && target_clamped_;
  // Stays raised until a good fresh input replaces the bad one, also through staleness.
  out_.fault = target_fault_any_;
  out_.shutdown = false;
  return out_;
}

}  // namespace sedbridge::display
