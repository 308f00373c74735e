#include "display/sed_field.h"

#include <algorithm>
#include <cmath>

namespace sedbridge::display {

SedFieldCheck CheckSedField(const SedField& field) {
  SedFieldCheck check;
  const std::size_t n = field.sed_Pa.size();
  check.consistent = field.x_mm.size() == n && field.y_mm.size() == n &&
                     (field.z_mm.empty() || field.z_mm.size() == n);
  for (double s : field.sed_Pa) {
    if (!std::isfinite(s)) ++check.non_finite_sed;
    else if (s < 0) ++check.negative_sed;
  }
  if (!check.consistent) return check;
  for (std::size_t i = 0; i < n; ++i) {
    const bool finite_z = field.z_mm.empty() || std::isfinite(field.z_mm[i]);
    if (!std::isfinite(field.x_mm[i]) || !std::isfinite(field.y_mm[i]) || !finite_z)
      ++check.non_finite_position;
  }
  return check;
}

double MaxFiniteSed(const SedField& field) {
  double m = 0;
  for (double s : field.sed_Pa)
    if (std::isfinite(s)) m = std::max(m, s);
  return m;
}

}  // namespace sedbridge::display
