#include "display/display_driver.h"

#include <stdexcept>

namespace sedbridge::display {

DisplayDriver::DisplayDriver(const DisplayProfile& profile, std::unique_ptr<ActuatorOutput> output,
                             DisplayCommandDecoder decode, std::shared_ptr<const CommandAuthenticator> auth)
    : profile_(profile),
      limiter_(SafetyLimits::FromProfile(profile)),
      output_(std::move(output)),
      decode_(std::move(decode)),
      auth_(std::move(auth)) {
  if (!decode_) throw std::invalid_argument("DisplayDriver needs a command decoder");
  frame_.value.assign(profile_.size(), 0.0);
}

bool DisplayDriver::OnMessage(const void* data, std::size_t size, int64_t now_utime) {
  ++counters_.messages;
  std::size_t payload = size;
  if (auth_) {
    const std::optional<std::size_t> n = auth_->Verify(data, size);
    if (!n) {
      ++counters_.unsigned_or_forged;
      return false;
    }
    payload = *n;
  }
  DisplayCommand m;
  if (!decode_(data, payload, &m)) {
    ++counters_.malformed;
    return false;
  }
  if (auth_) {
    // A valid tag on an old message is a replay: (utime, sequence) must move forward.
    const bool newer = !have_accepted_ || m.utime > last_utime_ ||
                       (m.utime == last_utime_ && m.sequence > last_sequence_);
    if (!newer) {
      ++counters_.replayed;
      return false;
    }
  }
  if (m.display_id != profile_.name || m.unit != profile_.unit ||
      m.value.size() != profile_.size()) {
    ++counters_.wrong_display;
    return false;
  }
  have_accepted_ = true;
  last_utime_ = m.utime;
  last_sequence_ = m.sequence;
  ++counters_.accepted;
  // The bridge's own stale/shutdown flags need no special case: their values are already
  // zero, and this limiter ramps down from wherever it is. Freshness for the watchdog is
  // judged on this driver's clock; the bridge's utime only orders messages.
  limiter_.Apply(now_utime, m.utime, m.value);
  return true;
}

const ActuatorFrame& DisplayDriver::Write(const LimitedOutput& out, int64_t now_utime) {
  frame_.utime = now_utime;
  frame_.sequence = counters_.frames;
  frame_.value = out.value;
  frame_.stale = out.stale;
  frame_.fault = out.fault;
  frame_.shutdown = out.shutdown;
  if (!output_->Write(frame_)) ++counters_.output_errors;
  ++counters_.frames;
  return frame_;
}

const ActuatorFrame& DisplayDriver::Tick(int64_t now_utime) { return Write(limiter_.Tick(now_utime), now_utime); }

const ActuatorFrame& DisplayDriver::Shutdown(int64_t now_utime, int repeats) {
  const LimitedOutput& out = limiter_.Shutdown(now_utime);
  for (int i = 0; i < repeats; ++i) Write(out, now_utime);
  return frame_;
}

}  // namespace sedbridge::display
