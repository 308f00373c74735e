#pragma once
// The leader-side display driver's core: the process next to the device. It takes the raw
// bytes of each DISPLAY_COMMAND, checks them (size-safe decode, optional HMAC and replay
// check, right display), and runs its OWN SafetyLimiter from the display profile, so the
// device is protected by limits and a watchdog that do not depend on the bridge being alive
// or honest. Its output is written by Tick() on the driver's own timer: with no valid
// command within the profile's watchdog timeout it ramps to zero at the profile's slew rate.
// No LCM or clock inside (tests drive it): the wire format comes in as a decoder
// (lcm_io::DecodeDisplayCommand); src/app/display_driver_main.cpp is the program around it.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>

#include "display/actuator_output.h"
#include "display/command_authenticator.h"
#include "display/display_command.h"
#include "display/display_profile.h"
#include "display/safety_limiter.h"

namespace sedbridge::display {

/// Decodes one DISPLAY_COMMAND payload (`size` bytes at `data`, any authentication tag
/// already stripped) into `out`; false when the bytes are not a well-formed command. Must not
/// throw and must not allocate more than O(size): the bytes are untrusted.
using DisplayCommandDecoder = std::function<bool(const void* data, std::size_t size, DisplayCommand* out)>;

struct DriverCounters {
  int64_t messages = 0;       ///< DISPLAY_COMMAND messages seen
  int64_t accepted = 0;       ///< passed every check and fed to the limiter
  int64_t malformed = 0;      ///< not a well-formed command (the decoder said no)
  int64_t unsigned_or_forged = 0;  ///< authentication on: no tag or a wrong tag
  int64_t replayed = 0;       ///< authentication on: (utime, sequence) not newer than the last accepted
  int64_t wrong_display = 0;  ///< display_id, unit or actuator count differ from the profile
  int64_t frames = 0;         ///< output frames written
  int64_t output_errors = 0;  ///< frames the output could not write
};

class DisplayDriver {
 public:
  /// @param[in] profile  the device's display profile (its own limits, not the bridge's)
  /// @param[in] output   where frames go (owned)
  /// @param[in] decode   the wire format, e.g. lcm_io::DecodeDisplayCommand (lcm/display_command_message.h);
  ///                     throws std::invalid_argument when empty
  /// @param[in] auth     nullptr = unauthenticated; else every command must carry a valid tag
  ///                     and a (utime, sequence) newer than the last accepted one
  DisplayDriver(const DisplayProfile& profile, std::unique_ptr<ActuatorOutput> output,
                DisplayCommandDecoder decode, std::shared_ptr<const CommandAuthenticator> auth = nullptr);

  /// One DISPLAY_COMMAND as received (`size` bytes at `data`) at the driver's `now_utime`
  /// [us]. Returns true when accepted. Never throws, never writes the output.
  bool OnMessage(const void* data, std::size_t size, int64_t now_utime);

  /// Emits one frame at `now_utime` [us] to the output: call at a steady rate whether or not
  /// messages arrive (the watchdog's ramp to zero happens here).
  const ActuatorFrame& Tick(int64_t now_utime);

  /// All zero with the shutdown flag, written `repeats` times; later ticks stay zero.
  const ActuatorFrame& Shutdown(int64_t now_utime, int repeats = 3);

  const DriverCounters& counters() const { return counters_; }
  const SafetyLimiter& limiter() const { return limiter_; }
  const ActuatorFrame& last_frame() const { return frame_; }
  ActuatorOutput& output() { return *output_; }

 private:
  const ActuatorFrame& Write(const LimitedOutput& out, int64_t now_utime);

  DisplayProfile profile_;
  SafetyLimiter limiter_;
  std::unique_ptr<ActuatorOutput> output_;
  DisplayCommandDecoder decode_;
  std::shared_ptr<const CommandAuthenticator> auth_;
  DriverCounters counters_;
  ActuatorFrame frame_;
  bool have_accepted_ = false;
  int64_t last_utime_ = 0, last_sequence_ = 0;
};

}  // namespace sedbridge::display
