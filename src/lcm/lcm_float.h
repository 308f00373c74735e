#pragma once
// LCM messages carry float: the one narrowing rule every converter uses.

namespace sedbridge::lcm_io {

/// double -> float without undefined behaviour: beyond float range -> +-Inf, NaN stays NaN.
/// Receivers treat message fields as untrusted anyway.
float ToLcmFloat(double x);

}  // namespace sedbridge::lcm_io
