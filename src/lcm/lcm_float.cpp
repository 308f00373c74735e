#include "lcm/lcm_float.h"

#include <limits>

namespace sedbridge::lcm_io {

float ToLcmFloat(double x) {
  constexpr double kMax = std::numeric_limits<float>::max();
  if (x > kMax) return std::numeric_limits<float>::infinity();
  if (x < -kMax) return -std::numeric_limits<float>::infinity();
  return static_cast<float>(x);  // NaN stays NaN
}

}  // namespace sedbridge::lcm_io
