#pragma once
// Sane upper bounds per display kind, in its unit, for every profile value that bounds what
// reaches a person's finger. A profile outside them is rejected at load time with the limit
// named: a typo (`max: 200` for 20 kPa, `slew_rate_per_s: 1e30`) must not become a command.
// The numbers are deliberately generous device-class limits, not comfort limits; a lab sets
// its comfort limit with `safety.max` below them.

#include "display/display_profile.h"

namespace sedbridge::display {

struct DisplayKindLimits {
  /// Largest `range[1]` (and so `safety.max`, `mapping.saturation`, |calibration offset|) [unit].
  ///   suction 100 kPa: suction cannot exceed ambient pressure (~101 kPa), and skin
  ///     suction devices stay far below it;
  ///   pin 5 mm: beyond a few mm a pin indents past the pad's soft tissue toward bone;
  ///   electrotactile 10 mA: the upper end of electrotactile stimulation currents; more
  ///     risks burns and pain.
  double max_value = 0;
  /// Largest `safety.slew_rate_per_s` [unit/s]: full scale (max_value) in no less than 0.1 s.
  double max_slew_per_s = 0;
};

/// The bounds for `kind` (see DisplayKindLimits for the reasons).
DisplayKindLimits LimitsOf(DisplayKind kind);

}  // namespace sedbridge::display
