#pragma once
// The display stage in one object: SedField -> mapping -> SafetyLimiter -> DisplayCommand.
// The mapping is the per-site curve (SedToCommandMapping) unless a request source is
// injected (display/command_request_source.h: the bridge's inverse FE renderer); the
// limiter after it is the same either way. This is what the bridge calls; it does no I/O
// (see DisplaySession for LCM output).

#include <cstdint>

#include "display/command_request_source.h"
#include "display/display_command.h"
#include "display/display_profile.h"
#include "display/safety_limiter.h"
#include "display/sed_field.h"
#include "display/sed_to_command_mapping.h"

namespace sedbridge::display {

/// Counters since construction, e.g. for lcmt_bridge_status.
struct DisplayStats {
  int64_t fields = 0;            ///< OnSedField calls
  int64_t fields_rejected = 0;   ///< fields with NaN/Inf or inconsistent lengths
  int64_t fields_negative = 0;   ///< fields with negative SED values (read as 0)
  int64_t commands = 0;          ///< commands emitted
  int64_t commands_clamped = 0;
  int64_t commands_stale = 0;
  int64_t commands_fault = 0;
};

/// Not thread-safe; call from the one thread that owns the display output.
///
///   DisplayController display(LoadDisplayProfile("config/displays/suction_4x4.yaml"));
///   DisplayCommand c = display.OnSedField(field, now_utime);  // after each FE step
///   DisplayCommand c = display.Tick(now_utime);              // at the command rate otherwise
///   DisplayCommand c = display.Shutdown(now_utime);          // all zero, for good
class DisplayController {
 public:
  /// Throws std::invalid_argument when the profile's limits or mapping are invalid.
  /// `requests`: where the requests come from (empty: the profile's curve, `mapping`).
  explicit DisplayController(DisplayProfile profile, CommandRequestSource requests = {});

  /// Maps a fresh SED field and limits the result. `now_utime` [us] is the caller's clock.
  DisplayCommand OnSedField(const SedField& field, int64_t now_utime);
  /// No new field: the limiter holds, or ramps to zero once the watchdog expires.
  DisplayCommand Tick(int64_t now_utime);
  /// Zero now and for every later call.
  DisplayCommand Shutdown(int64_t now_utime);

  const DisplayProfile& profile() const { return profile_; }
  const SedToCommandMapping& mapping() const { return mapping_; }
  const SafetyLimiter& limiter() const { return limiter_; }
  /// True when the requests come from an injected source, not the curve.
  bool has_request_source() const { return bool(requests_); }
  /// Mapping result of the last field (field check, the curve's sampled SED per site, and
  /// the requests the limiter got: the injected source's when there is one).
  const SedToCommandMapping::Result& last_mapping() const { return last_mapping_; }
  const DisplayStats& stats() const { return stats_; }

 private:
  DisplayCommand Make(const LimitedOutput& out, int64_t now_utime);

  DisplayProfile profile_;
  SedToCommandMapping mapping_;
  CommandRequestSource requests_;
  SafetyLimiter limiter_;
  SedToCommandMapping::Result last_mapping_;
  DisplayStats stats_;
  int64_t sequence_ = 0;
  int64_t source_scan_utime_ = 0;
  int64_t source_sed_utime_ = 0;
};

}  // namespace sedbridge::display
