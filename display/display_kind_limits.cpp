#include "display/display_kind_limits.h"

namespace sedbridge::display {

DisplayKindLimits LimitsOf(DisplayKind kind) {
  switch (kind) {
    case DisplayKind::kSuction: return {100.0, 1000.0};      // kPa, kPa/s
    case DisplayKind::kPin: return {5.0, 50.0};              // mm, mm/s
    case DisplayKind::kElectrotactile: return {10.0, 100.0};  // mA, mA/s
  }
  return {0.0, 0.0};  // unreachable: every kind is listed above
}

}  // namespace sedbridge::display
